"""Gear tooth damage in the potential-energy mesh stiffness: a root crack or a flank pit on one
tooth of the ring gear or of one roller's gear.

The damage changes the sections of the tooth's cantilever (:mod:`.gear_mesh`), so the bending,
shear and axial energies of that tooth — and, for a pit, the Hertzian contact line — while it
carries load:

Root crack (Tian 2004, §3; Wu, Zuo & Parey 2008, case "crack not crossing the centreline")
    A straight crack from the root on the loaded side, of length q at angle ν to the root
    surface, leaves h_q = h_r − q·sin ν of the root half-thickness h_r on that side. Sections
    keep their full thickness 2h_x where h_x ≤ h_q, else only h_x + h_q (the material beyond the
    line from the crack tip parallel to the centreline carries no stress):
    A_x = (h_x + min(h_x, h_q))·w, I_x = (h_x + min(h_x, h_q))³·w/12. The shift of the neutral
    axis, the Hertzian and the fillet-foundation terms are left unchanged, as in both papers.
Flank pit (Chaari, Baccar, Abbes & Haddar 2008; Liang, Zuo & Hoseini 2015)
    A pit of depth d over a share f of the face width and a radial band of the flank: while
    the contact lies on the band, the Hertzian contact line is (1 − f) of the face width; the
    sections within the band lose the pit's material, A_x = 2h_x·w − f·w·d,
    I_x = w(2h_x)³/12 − f·w·(d³/12 + d·(h_x − d/2)²) (parallel axes about the centreline; the
    neutral-axis shift is neglected).

:func:`damaged_sections` and :func:`contact_share` take a fault record as plain data (its
``kind`` and sizes, :mod:`prsm_health.actuator.faults`) and the tooth's geometry
(:class:`~prsm_health.physics.stiffness.gear_mesh.ToothGeometry`);
:func:`~prsm_health.physics.stiffness.damaged_mesh.damaged_mesh` puts one damaged tooth into
the mesh cycle.

References
----------
- X. Tian, "Dynamic simulation for system response of gearbox including localized gear
  faults", MSc thesis, University of Alberta, 2004, §3.
- S. Wu, M.J. Zuo, A. Parey, "Simulation of spur gear dynamics and estimation of fault growth",
  J. Sound Vib. 317 (2008) 608–624.
- F. Chaari, W. Baccar, M.S. Abbes, M. Haddar, "Effect of spalling or tooth breakage on
  gearmesh stiffness and dynamic response of a one-stage spur gear transmission", Eur. J.
  Mech. A/Solids 27 (2008) 691–705.
- X. Liang, M.J. Zuo, M.R. Hoseini, "Vibration signal modeling of a planetary gear set for
  tooth crack detection", Eng. Fail. Anal. 48 (2015) 185–200.
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.core.errors import require


def root_half_thickness(tooth) -> float:
    """Half thickness of a tooth at its root [m] (fillet root of an external tooth, root circle
    of a ring tooth)."""
    if tooth.internal:
        return float(tooth.involute(tooth.t_root)[1])
    return float(np.max(tooth._fillet_sections()[1]))


def crack_section(tooth, h, w, depth: float, angle: float):
    """(area [m²], second moment [m⁴]) of sections of half thickness ``h`` and width ``w`` of a
    tooth with a root crack (module docstring)."""
    h_q = root_half_thickness(tooth) - depth * math.sin(angle)
    thickness = h + np.minimum(h, h_q)
    return thickness * w, w * thickness**3 / 12.0


def _zeta_of_radius(tooth, r: float) -> float:
    """Distance from the root along the centreline of the flank point at radius r [m]."""
    t = math.sqrt(max((r / tooth.rb) ** 2 - 1.0, 0.0))
    y = float(tooth.involute(t)[0])
    return tooth.y_root - y if tooth.internal else y - tooth.y_root


def pit_band(tooth, offset: float, length: float) -> tuple[float, float]:
    """Radii [m] of a pit band of radial ``length`` centred ``offset`` from the pitch circle
    (towards the tip of an external tooth, the tip of a ring tooth too)."""
    centre = tooth.rp - offset if tooth.internal else tooth.rp + offset
    return centre - 0.5 * length, centre + 0.5 * length


def pit_section(tooth, zeta, h, w, band, width_share: float, depth: float):
    """(area, second moment) of sections with a flank pit on the radial ``band`` (module
    docstring)."""
    z1, z2 = sorted((_zeta_of_radius(tooth, band[0]), _zeta_of_radius(tooth, band[1])))
    inside = (zeta >= z1) & (zeta <= z2)
    area = 2.0 * h * w
    inertia = w * (2.0 * h) ** 3 / 12.0
    strip = width_share * w * depth
    area = np.where(inside, area - strip, area)
    inertia = np.where(
        inside,
        inertia - width_share * w * (depth**3 / 12.0 + depth * (h - depth / 2) ** 2),
        inertia,
    )
    return area, inertia


def pit_contact_share(radius, band, width_share: float):
    """Share of the face width left to the Hertzian contact at flank radii ``radius``."""
    r = np.asarray(radius, dtype=float)
    return np.where((r >= band[0]) & (r <= band[1]), 1.0 - width_share, 1.0)


def damaged_sections(damage, tooth, zeta, h, w):
    """(area [m²], second moment [m⁴]) of the tooth's sections with ``damage`` (a
    ``tooth_crack`` or ``tooth_pit`` record: kind, depth, angle, width, length, offset)."""
    if damage.kind == "tooth_crack":
        limit = root_half_thickness(tooth) / math.sin(damage.angle)
        require(
            damage.depth < limit,
            "faults.depth",
            damage.depth,
            f"must stay below {limit:.4g} m on this gear (a deeper crack crosses the tooth "
            "centreline, outside the model)",
        )
        return crack_section(tooth, h, w, damage.depth, damage.angle)
    band = pit_band(tooth, damage.offset, damage.length)
    return pit_section(tooth, zeta, h, w, band, damage.width, damage.depth)


def contact_share(damage, tooth, radius):
    """Share of the face width left to the Hertzian contact at flank radii ``radius`` [-]: a
    crack leaves the flank whole; a pit of non-zero depth takes its width share on its band."""
    if damage.kind == "tooth_crack":
        return 1.0
    width = damage.width if damage.depth > 0 else 0.0  # no depth, no pit
    return pit_contact_share(radius, pit_band(tooth, damage.offset, damage.length), width)
