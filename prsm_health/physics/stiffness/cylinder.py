"""Axial deformation and stiffness of an electric cylinder driven by a PRSM (paper 05).

The load path of the cylinder is a series chain of eight compliances; under an axial load F
with the rod extended by x the total axial deformation is

    Δl(F, x) = Δl1 + Δl2 + … + Δl8,        k(F, x) = F / Δl  (secant stiffness),

    bearing        Δl1   preloaded tapered-roller support pair       ∝ F
    contact        Δl2   Hertz point contact roller–screw and –nut   ∝ F^(2/3)
    screw_thread   Δl3   screw thread teeth (Yamamoto)               ∝ F
    nut_thread     Δl4   nut thread teeth (Yamamoto)                 ∝ F
    nut_body       Δl5   nut component as a tube                     ∝ F
    screw_axial    Δl6   screw core in tension/compression           ∝ F·x
    screw_torsion  Δl7   screw twist under the drive torque          ∝ F·x
    belt           Δl8   synchronous belt: polygon effect + stretch  a + b·F

Everything is SI (N, m, Pa, rad). The paper's printed Δl(F, x) mixes units; this module
implements each formula in a consistent unit system and never tunes to the printed
coefficients. The readings that differ from the paper's arithmetic are:

Bearing (Δl1)
    ``F / (29.011 Z^0.9 l1^0.8 sin^1.9 α F_a0^0.1)`` is a catalogue formula in **µm** with F
    and F_a0 in N and l1 in mm. Its constant is Palmgren's line-contact approach
    δ = 3.84e-5·Q^0.9/l^0.8 [mm, N, mm] per raceway, two raceways, linearised about the preload
    of a face-to-face pair: 1/(0.45·2·3.84e-5 mm) = 28 935 mm⁻¹ = 28.9 µm⁻¹ ≈ 29.011. The paper
    evaluates the same digits (2.5038e-4) but reads them as mm, so its 2.5038e-7 m/N is 10³
    too compliant: a preloaded pair deflecting 3.3 µm at its own 6 kN preload (Palmgren)
    cannot have 0.25 µm/N. Here Δl1 = 2.5038e-10 m/N for the paper's bearing.
Contact (Δl2)
    Exact Hertz (:mod:`prsm_health.physics.stiffness.hertz`) with the paper's principal curvatures
    and Q = F/(i sin β cos λ). The normal approach is converted to the axial one by virtual
    work, u = δ/(sin β cos λ) (the axial component of the contact normal is sin β cos λ, see
    :mod:`prsm_health.actuator.design`); the paper writes δ·cos λ/sin β, smaller by cos²λ (0.27 % at
    λ = 3°).
Threads (Δl3, Δl4)
    The γ1…γ5 of the paper are Yamamoto's thread-tooth deflections (bending, shear, root
    inclination by moment, root inclination by shear, radial contraction/expansion) for a
    sharp V thread of flank angle 45° loaded at mid-flank (b/a = 1/2, c/a = 1/4, a = P). In
    Yamamoto's theory the load W is a *line load* [N/m] per unit circumferential length of one
    thread ring and P is the axial spacing of the loaded rings (the thread pitch). As printed,
    F' [N] stands in for W, so every γ has units of m² (F'/E), not m. This module uses
    W = F/(i1·π·d) — the axial load shared by the i1 engaged rings, spread over the pitch
    circumference π·d1 (screw) or π·d2 (nut) — and P = thread pitch. At β = 45° the printed
    γ1, γ2, γ3, γ4 and the screw's γ5 are exactly Yamamoto's with W = F'·sin β; the nut's γ5
    prints 2·F' where Yamamoto gives √2·F' (= 2·W), which is taken as a misprint.
Torsion (Δl7)
    Implemented as printed with p the lead: 8Fp²x/(π³d1⁴ηG) (bore allowed). The printed
    coefficient 7.006e-11 corresponds to p = 6 mm and x in m; see ``validation/paper05.py``.
Belt (Δl8)
    The paper gives neither the tooth geometry (R_r, R_p, c, φ) nor the belt (l8, E3, b, h_s,
    h_t); the default cylinder has ``belt=None`` and Δl8 = 0. The tight-side tension is
    T/r2 + F0 with T the screw torque and r2 the pulley on the screw (the paper writes T/r1,
    which holds only for a 1:1 drive).

References
----------
- Paper 05 (docs/references.md) — the Δl1…Δl8 formulas, the
  parameter table, the printed Δl(F, x), the stiffness table and the influence coefficients.
- A. Palmgren, *Ball and Roller Bearing Engineering*, 1959 (via T. A. Harris, *Rolling
  Bearing Analysis*): line-contact approach δ = 3.84e-5·Q^0.9/l^0.8 [mm, N, mm].
- A. Yamamoto, *The Theory and Computation of Threads Connection*, Yokendo, 1980: thread-tooth
  deflections δ1…δ5 per unit line load.
- K. L. Johnson, *Contact Mechanics*, CUP 1985, §3.6 (via :mod:`.hertz`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from prsm_health.actuator.design import PRSMDesign, preset
from prsm_health.core.errors import ParameterError, require, require_positive, require_range

from .hertz import HertzContact, effective_modulus
from .thread_compliance import yamamoto_terms

#: Component names, in the paper's order Δl1 … Δl8.
COMPONENTS = (
    "bearing",
    "contact",
    "screw_thread",
    "nut_thread",
    "nut_body",
    "screw_axial",
    "screw_torsion",
    "belt",
)

#: Constant of paper 05's bearing formula, in µm with F, F_a0 [N] and l1 [mm].
BEARING_CONSTANT = 29.011

#: Palmgren's line-contact approach per raceway, δ = C·Q^0.9/l^0.8 with δ [mm], Q [N], l [mm].
PALMGREN_LINE_CONTACT = 3.84e-5

#: Thread-tooth shape in Yamamoto's formulas: a sharp V whose root width a equals the pitch,
#: loaded at mid-flank: width at the load point b = a/2, height of the load point above the
#: root c = (a/4)·cot β_Y. These are the ratios paper 05's γ1…γ5 imply (b/a = 1/2, c/a = 1/4 at
#: β_Y = 45°, the only values making γ3 = 0 as printed).
THREAD_ROOT_WIDTH_OVER_PITCH = 1.0
THREAD_LOAD_WIDTH_OVER_ROOT = 0.5


# ============================================================================ parameters
@dataclass(frozen=True)
class SupportBearing:
    """Preloaded pair of tapered roller bearings carrying the screw's axial load.

    Parameters
    ----------
    n_rollers : int
        Rollers per bearing, Z.
    roller_length : float [m]
        Effective roller (line-contact) length l1.
    contact_angle : float [rad]
        Contact angle α under load.
    preload : float [N]
        Axial preload F_a0.

    References
    ----------
    Paper 05, Δl1 formula and parameter table (Z = 16, l1 = 16 mm, α = 45°, F_a0 = 6000 N).
    """

    n_rollers: int = 16
    roller_length: float = 16e-3
    contact_angle: float = math.radians(45.0)
    preload: float = 6000.0

    def __post_init__(self):
        require(
            isinstance(self.n_rollers, int) and self.n_rollers >= 3,
            "bearing.n_rollers",
            self.n_rollers,
            "must be an integer ≥ 3",
        )
        # The formula is a catalogue fit for rollers of a few mm to a few tens of mm; a value
        # above 0.2 m is almost surely a length given in mm.
        require_range("bearing.roller_length [m]", self.roller_length, 1e-4, 0.2)
        require_range(
            "bearing.contact_angle [rad]", self.contact_angle, 0.0, math.pi / 2, inclusive=False
        )
        require_positive("bearing.preload [N]", self.preload)

    @property
    def compliance(self) -> float:
        """Linearised axial compliance of the preloaded pair, Δl1/F [m/N].

        The paper's formula gives µm with F, F_a0 in N and l1 in mm (module docstring).
        """
        l1_mm = self.roller_length * 1e3
        denominator_um = (
            BEARING_CONSTANT
            * self.n_rollers**0.9
            * l1_mm**0.8
            * math.sin(self.contact_angle) ** 1.9
            * self.preload**0.1
        )
        return 1e-6 / denominator_um

    @property
    def preload_loss_load(self) -> float:
        """External axial load [N] at which the unloaded bearing of the pair loses contact.

        With δ ∝ F_a^0.9 per bearing the loaded one reaches twice its preload approach at
        2^(1/0.9)·F_a0; beyond it the linearised Δl1 underestimates the deformation.
        """
        return 2.0 ** (1.0 / 0.9) * self.preload


@dataclass(frozen=True)
class BeltDrive:
    """Synchronous belt between motor (drive pulley) and screw (driven pulley).

    Parameters
    ----------
    drive_pitch_radius : float [m]
        r1, pulley on the motor.
    driven_pitch_radius : float [m]
        r2, pulley on the screw.
    pretension : float [N]
        F0.
    pulley_pitch_radius : float [m]
        R_c of the pulley whose polygon effect is counted.
    tip_arc_centre_radius : float [m]
        R_r, radius of the circle through the tooth-tip arc centres.
    tip_radius : float [m]
        R_p, tooth-tip radius.
    pitch_line_to_root : float [m]
        c, distance from the belt pitch line to the tooth root.
    half_tooth_angle : float [rad]
        φ, half the angle between adjacent tooth centres.
    tight_side_length : float [m]
        l8.
    belt_modulus : float [Pa]
        E3, equivalent elastic modulus of the belt.
    belt_width : float [m]
        b.
    belt_height : float [m]
        h_s.
    tooth_height : float [m]
        h_t (< 2·h_s).

    References
    ----------
    Paper 05, Δx1, Δx2 and Δl8 formulas; r1 = 35 mm, r2 = 17.5 mm, F0 = 30 N in its table,
    the other inputs are not given.
    """

    drive_pitch_radius: float
    driven_pitch_radius: float
    pretension: float
    pulley_pitch_radius: float
    tip_arc_centre_radius: float
    tip_radius: float
    pitch_line_to_root: float
    half_tooth_angle: float
    tight_side_length: float
    belt_modulus: float
    belt_width: float
    belt_height: float
    tooth_height: float

    def __post_init__(self):
        for name in (
            "drive_pitch_radius",
            "driven_pitch_radius",
            "pulley_pitch_radius",
            "tip_arc_centre_radius",
            "tip_radius",
            "tight_side_length",
            "belt_modulus",
            "belt_width",
            "belt_height",
            "tooth_height",
        ):
            require_positive(f"belt.{name}", getattr(self, name))
        require(
            isinstance(self.pretension, (int, float)) and 0.0 <= self.pretension < math.inf,
            "belt.pretension [N]",
            self.pretension,
            "must be a finite number ≥ 0",
        )
        require(
            isinstance(self.pitch_line_to_root, (int, float)) and self.pitch_line_to_root >= 0,
            "belt.pitch_line_to_root [m]",
            self.pitch_line_to_root,
            "must be ≥ 0",
        )
        require_range(
            "belt.half_tooth_angle [rad]", self.half_tooth_angle, 0.0, math.pi / 2, inclusive=False
        )
        require(
            self.tooth_height < 2.0 * self.belt_height,
            "belt.tooth_height [m]",
            self.tooth_height,
            f"must be < 2·belt_height = {2 * self.belt_height:.6g} m (effective section "
            "b·(h_s − h_t/2) must be positive)",
        )

    @property
    def polygon_error(self) -> float:
        """Δx1 = 2[R_c φ − R_r sin φ − (R_p + c) φ] [m] (paper 05)."""
        phi = self.half_tooth_angle
        return 2.0 * (
            self.pulley_pitch_radius * phi
            - self.tip_arc_centre_radius * math.sin(phi)
            - (self.tip_radius + self.pitch_line_to_root) * phi
        )

    @property
    def stretch_compliance(self) -> float:
        """Δx2 per unit tight-side tension, l8/(E3 b (h_s − h_t/2)) [m/N]."""
        section = self.belt_width * (self.belt_height - 0.5 * self.tooth_height)
        return self.tight_side_length / (self.belt_modulus * section)


def _default_design() -> PRSMDesign:
    return preset("paper05")


@dataclass(frozen=True)
class ElectricCylinder:
    """An electric cylinder: support bearings, PRSM, nut component and belt drive.

    Parameters
    ----------
    design : PRSMDesign
        Roller screw geometry and materials. Used: d = roller_diameter, d1 = screw_diameter,
        d2 = nut_diameter, d2' = nut_outer_diameter, β = contact_angle, i = n_rollers,
        i1 = engaged_threads, p = screw_lead, thread pitch, screw bore, materials.
    bearing : SupportBearing
        Screw support bearing pair (Δl1).
    lead_angle : float or None [rad]
        λ used in the contact curvatures and the normal load. Paper 05 prints 3°, while its
        own lead and screw diameter give atan(5/(π·36)) = 2.53°; ``None`` uses the design's
        ``screw_lead_angle``.
    efficiency : float [-]
        Transmission efficiency η in T = F·p/(2π η).
    screw_shear_modulus : float or None [Pa]
        G of the screw; ``None`` takes ``design.screw_material.G`` (85 GPa for paper 05).
    nut_body_length : float or None [m]
        l5, length of the nut component loaded as a tube; ``None`` takes
        ``design.threaded_nut_length`` (0.6 m for paper 05).
    belt : BeltDrive or None
        ``None`` (paper 05 lacks the inputs): Δl8 = 0.
    name : str

    Notes
    -----
    Construction validates every field and solves both Hertz contacts once; all component
    coefficients are then cached.

    References
    ----------
    Paper 05, parameter table and Δl1…Δl8.
    """

    design: PRSMDesign = field(default_factory=_default_design)
    bearing: SupportBearing = field(default_factory=SupportBearing)
    lead_angle: float | None = math.radians(3.0)
    efficiency: float = 0.93
    screw_shear_modulus: float | None = None
    nut_body_length: float | None = None
    belt: BeltDrive | None = None
    name: str = field(default="user", compare=False)
    _coefficients: dict = field(init=False, repr=False, compare=False, default=None)

    def __post_init__(self):
        require(
            isinstance(self.design, PRSMDesign),
            "cylinder.design",
            self.design,
            "must be a PRSMDesign",
        )
        require(
            isinstance(self.bearing, SupportBearing),
            "cylinder.bearing",
            self.bearing,
            "must be a SupportBearing",
        )
        require(
            self.belt is None or isinstance(self.belt, BeltDrive),
            "cylinder.belt",
            self.belt,
            "must be a BeltDrive or None",
        )
        if self.lead_angle is not None:
            require_range(
                "cylinder.lead_angle [rad]",
                self.lead_angle,
                0.0,
                math.radians(30.0),
                inclusive=False,
            )
        require(
            isinstance(self.efficiency, (int, float)) and 0.0 < self.efficiency <= 1.0,
            "cylinder.efficiency",
            self.efficiency,
            "must lie in (0, 1]",
        )
        if self.screw_shear_modulus is not None:
            require_positive("cylinder.screw_shear_modulus [Pa]", self.screw_shear_modulus)
        if self.nut_body_length is not None:
            require_positive("cylinder.nut_body_length [m]", self.nut_body_length)
        object.__setattr__(self, "_coefficients", _compute_coefficients(self))

    @classmethod
    def paper05(cls) -> ElectricCylinder:
        """The cylinder of paper 05's parameter table (belt inputs missing → no belt)."""
        return cls(design=preset("paper05"), name="paper05")

    # ------------------------------------------------------------ resolved parameters
    @property
    def lambda_(self) -> float:
        """Lead angle λ actually used [rad]."""
        return self.design.screw_lead_angle if self.lead_angle is None else self.lead_angle

    @property
    def shear_modulus(self) -> float:
        """Screw shear modulus G actually used [Pa]."""
        if self.screw_shear_modulus is not None:
            return self.screw_shear_modulus
        return self.design.screw_material.G

    @property
    def nut_length(self) -> float:
        """l5 actually used [m]."""
        if self.nut_body_length is not None:
            return self.nut_body_length
        return self.design.threaded_nut_length

    @property
    def coefficients(self) -> dict[str, float]:
        """Coefficient of every component (a copy).

        Keys and units: ``bearing``, ``screw_thread``, ``nut_thread``, ``nut_body`` [m/N];
        ``contact`` [m/N^(2/3)]; ``screw_axial``, ``screw_torsion`` [m/(N·m)] = [1/N];
        ``belt`` [m/N] and ``belt_offset`` [m] (Δl8 = belt_offset + belt·F, both 0 without
        a belt). Also ``contact_screw``, ``contact_nut`` [m/N^(2/3)]: Hertz normal approach
        coefficients c in δ = c·Q^(2/3) of one roller–screw / roller–nut contact.
        """
        return dict(self._coefficients)


# ============================================================================ coefficients
def yamamoto_thread_terms(
    youngs_modulus: float,
    poisson_ratio: float,
    flank_angle: float,
    pitch: float,
    diameter: float,
    radial_factor: float,
) -> tuple[float, float, float, float, float]:
    """Yamamoto's axial thread-tooth deflections per unit line load, δ_j / W.

    Parameters
    ----------
    youngs_modulus : float [Pa]
    poisson_ratio : float [-]
    flank_angle : float [rad]
        β_Y, angle of the flank from the radial plane (= π/2 − the design's contact angle).
    pitch : float [m]
        Axial spacing P of the loaded thread rings.
    diameter : float [m]
        Diameter on which the load acts (screw d1 / nut d2).
    radial_factor : float [-]
        Lamé factor of the radial term: 1 − ν for a solid screw, (d² + d_b²)/(d² − d_b²) − ν
        for a hollow one, (d2'² + d2²)/(d2'² − d2²) + ν for the nut.

    Returns
    -------
    (δ1, δ2, δ3, δ4, δ5) : tuple of float [m/(N/m)] = [m²/N]
        Bending, shear, root inclination (moment), root inclination (shear), radial
        contraction/expansion, each per unit line load W [N/m] along the thread ring.

    Notes
    -----
    Tooth shape: sharp V with root width a = P, load at mid-flank (b = a/2, c = (a/4)·cot β_Y).
    At β_Y = 45° these are paper 05's γ1…γ5 with F' replaced by the line load; δ1 is then
    slightly negative (the radial load component's moment outweighs the axial one), as it is
    in the paper's γ1 (4 ln 2 − 3 < 0).

    The formulas are :func:`prsm_health.physics.stiffness.thread_compliance.yamamoto_terms` (the one
    implementation, shared with the PRSM thread model) evaluated for this tooth and divided
    by E.

    References
    ----------
    Yamamoto (1980); paper 05, γ1S…γ5S and γ1N…γ5N.
    """
    a = THREAD_ROOT_WIDTH_OVER_PITCH * pitch
    b = THREAD_LOAD_WIDTH_OVER_ROOT * a
    c = 0.25 * a * (1.0 / math.tan(flank_angle))
    terms = yamamoto_terms(pitch, a, b, c, flank_angle, poisson_ratio, radial_factor, diameter)
    return tuple(t / youngs_modulus for t in terms)


def contact_pair(cyl: ElectricCylinder) -> tuple[HertzContact, HertzContact]:
    """The roller–screw (S) and roller–nut (N) Hertz contacts of one roller.

    Principal curvatures [1/m] of paper 05: ρ_S11 = ρ_S12 = ρ_N11 = ρ_N12 = 2cos β/d,
    ρ_S21 = 2cos β/(d1 cos λ), ρ_N21 = −2cos β/(d2 cos λ) (concave nut), ρ_S22 = ρ_N22 = 0.
    The roller's two curvatures are equal, so the angle between principal planes is moot.

    References
    ----------
    Paper 05, principal curvatures at S and N; Johnson (1985) §3.6.
    """
    d = cyl.design
    beta, lam = d.contact_angle, cyl.lambda_
    roller = 2.0 * math.cos(beta) / d.roller_diameter
    screw = 2.0 * math.cos(beta) / (d.screw_diameter * math.cos(lam))
    nut = -2.0 * math.cos(beta) / (d.nut_diameter * math.cos(lam))
    e_s = effective_modulus(
        d.roller_material.youngs_modulus,
        d.roller_material.poisson_ratio,
        d.screw_material.youngs_modulus,
        d.screw_material.poisson_ratio,
    )
    e_n = effective_modulus(
        d.roller_material.youngs_modulus,
        d.roller_material.poisson_ratio,
        d.nut_material.youngs_modulus,
        d.nut_material.poisson_ratio,
    )
    return (
        HertzContact.from_curvatures((roller, roller), (screw, 0.0), e_s),
        HertzContact.from_curvatures((roller, roller), (nut, 0.0), e_n),
    )


def _compute_coefficients(cyl: ElectricCylinder) -> dict[str, float]:
    d = cyl.design
    beta, lam = d.contact_angle, cyl.lambda_
    i, i1 = d.n_rollers, d.engaged_threads
    d1, d2, d2o, bore = (
        d.screw_diameter,
        d.nut_diameter,
        d.nut_outer_diameter,
        d.screw_bore_diameter,
    )
    lead = d.screw_lead
    sm, nm = d.screw_material, d.nut_material

    # Δl2: Q = F/(i sinβ cosλ) per roller, δ = c·Q^(2/3) at S and N in series, axial u =
    # δ/(sinβ cosλ) by virtual work (F·u = i·Q·δ).
    screw_contact, nut_contact = contact_pair(cyl)
    c_s, c_n = screw_contact.compliance_coefficient, nut_contact.compliance_coefficient
    projection = math.sin(beta) * math.cos(lam)
    contact = (c_s + c_n) * (1.0 / (i * projection)) ** (2.0 / 3.0) / projection

    # Δl3, Δl4: Yamamoto per unit line load, W = F/(i1·π·d) on each of the i1 loaded rings.
    flank = 0.5 * math.pi - beta
    screw_radial = (d1**2 + bore**2) / (d1**2 - bore**2) - sm.poisson_ratio
    nut_radial = (d2o**2 + d2**2) / (d2o**2 - d2**2) + nm.poisson_ratio
    screw_terms = yamamoto_thread_terms(
        sm.youngs_modulus, sm.poisson_ratio, flank, d.pitch, d1, screw_radial
    )
    nut_terms = yamamoto_thread_terms(
        nm.youngs_modulus, nm.poisson_ratio, flank, d.pitch, d2, nut_radial
    )
    screw_thread = sum(screw_terms) / (i1 * math.pi * d1)
    nut_thread = sum(nut_terms) / (i1 * math.pi * d2)

    nut_body = cyl.nut_length / (nm.youngs_modulus * math.pi * (d2o**2 - d2**2) / 4.0)
    screw_axial = 1.0 / (sm.youngs_modulus * math.pi * (d1**2 - bore**2) / 4.0)
    # Δl7 = θ·x·p/(2π), θ = T/(G J), T = F p/(2π η), J = π(d1⁴ − d_b⁴)/32.
    polar = math.pi * (d1**4 - bore**4) / 32.0
    screw_torsion = lead**2 / (4.0 * math.pi**2 * cyl.efficiency * cyl.shear_modulus * polar)

    belt, belt_offset = 0.0, 0.0
    if cyl.belt is not None:
        bd = cyl.belt
        # Belt travel → screw rotation Δx/(2π r2) → nut travel ×p. Tension = screw torque / r2.
        to_axial = lead / (2.0 * math.pi * bd.driven_pitch_radius)
        tension_per_load = lead / (2.0 * math.pi * cyl.efficiency * bd.driven_pitch_radius)
        belt = to_axial * bd.stretch_compliance * tension_per_load
        belt_offset = to_axial * (bd.polygon_error + bd.stretch_compliance * bd.pretension)

    return {
        "bearing": cyl.bearing.compliance,
        "contact": contact,
        "screw_thread": screw_thread,
        "nut_thread": nut_thread,
        "nut_body": nut_body,
        "screw_axial": screw_axial,
        "screw_torsion": screw_torsion,
        "belt": belt,
        "belt_offset": belt_offset,
        "contact_screw": c_s,
        "contact_nut": c_n,
    }


# ============================================================================ inputs
def _as_load(load) -> np.ndarray:
    arr = np.asarray(load, dtype=float)
    bad = ~np.isfinite(arr) | (arr < 0)
    if np.any(bad):
        raise ParameterError("load [N]", float(arr[bad].flat[0]), "must be finite and ≥ 0")
    return arr


def _as_extension(extension) -> np.ndarray:
    arr = np.asarray(extension, dtype=float)
    bad = ~np.isfinite(arr) | (arr < 0)
    if np.any(bad):
        raise ParameterError("extension [m]", float(arr[bad].flat[0]), "must be finite and ≥ 0")
    return arr


def _load_extension(load, extension) -> tuple[np.ndarray, np.ndarray]:
    return tuple(np.broadcast_arrays(_as_load(load), _as_extension(extension)))


# ============================================================================ components
def bearing(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl1, support bearing pair [m].

    Parameters
    ----------
    cyl : ElectricCylinder
    load : array_like [N]
        Axial load F ≥ 0. Linearised about the preload: valid below
        ``cyl.bearing.preload_loss_load``.

    References
    ----------
    Paper 05, Δl1 (read in µm, see module docstring); Palmgren line contact.
    """
    return cyl._coefficients["bearing"] * _as_load(load)


def contact(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl2, Hertz contact of the rollers with screw and nut [m], ∝ F^(2/3).

    References
    ----------
    Paper 05, Q and Δl2 = (δ_S + δ_N)·(axial projection); Johnson (1985).
    """
    f = _as_load(load)
    return cyl._coefficients["contact"] * np.cbrt(f) ** 2


def screw_thread(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl3, screw thread teeth [m] (Yamamoto, load spread over π·d1).

    References
    ----------
    Paper 05, γ1S…γ5S; Yamamoto (1980).
    """
    return cyl._coefficients["screw_thread"] * _as_load(load)


def nut_thread(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl4, nut thread teeth [m] (Yamamoto, load spread over π·d2).

    References
    ----------
    Paper 05, γ1N…γ5N; Yamamoto (1980).
    """
    return cyl._coefficients["nut_thread"] * _as_load(load)


def nut_body(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl5 = F l5 / (E2 π (d2'² − d2²)/4), nut component as a tube [m].

    References
    ----------
    Paper 05, Δl5.
    """
    return cyl._coefficients["nut_body"] * _as_load(load)


def screw_axial(cyl: ElectricCylinder, load, extension) -> np.ndarray:
    """Δl6 = F x / (E1 π d1²/4), screw core over the extension x [m].

    Parameters
    ----------
    cyl : ElectricCylinder
    load : array_like [N]
    extension : array_like [m]
        Screw length x between support bearing and nut; broadcast with ``load``.

    References
    ----------
    Paper 05, Δl6.
    """
    f, x = _load_extension(load, extension)
    return cyl._coefficients["screw_axial"] * f * x


def screw_torsion(cyl: ElectricCylinder, load, extension) -> np.ndarray:
    """Δl7 = 8 F p² x / (π³ d1⁴ η G), screw twist under the drive torque [m].

    References
    ----------
    Paper 05, θ, T and Δl7 (p = lead).
    """
    f, x = _load_extension(load, extension)
    return cyl._coefficients["screw_torsion"] * f * x


def belt(cyl: ElectricCylinder, load) -> np.ndarray:
    """Δl8 = (Δx1 + Δx2)·p/(2π r2), belt polygon effect and stretch [m]; 0 without a belt.

    References
    ----------
    Paper 05, Δx1, Δx2, Δl8 (tension T/r2 + F0, see module docstring).
    """
    f = _as_load(load)
    k = cyl._coefficients
    return k["belt_offset"] + k["belt"] * f


# ============================================================================ totals
def deformation_components(cyl: ElectricCylinder, load, extension) -> dict[str, np.ndarray]:
    """Every component Δl1…Δl8 [m], keyed by :data:`COMPONENTS`.

    Parameters
    ----------
    cyl : ElectricCylinder
    load : array_like [N]
        Axial load F ≥ 0.
    extension : array_like [m]
        Extension x ≥ 0; broadcast with ``load``.

    Returns
    -------
    dict of str → ndarray [m]
        Arrays of the broadcast shape.

    References
    ----------
    Paper 05, Δl = Δl1 + … + Δl8.
    """
    f, x = _load_extension(load, extension)
    k = cyl._coefficients
    return {
        "bearing": k["bearing"] * f,
        "contact": k["contact"] * np.cbrt(f) ** 2,
        "screw_thread": k["screw_thread"] * f,
        "nut_thread": k["nut_thread"] * f,
        "nut_body": k["nut_body"] * f,
        "screw_axial": k["screw_axial"] * f * x,
        "screw_torsion": k["screw_torsion"] * f * x,
        "belt": k["belt_offset"] + k["belt"] * f,
    }


def total_deformation(cyl: ElectricCylinder, load, extension) -> np.ndarray:
    """Δl(F, x) [m], the sum of the eight components.

    References
    ----------
    Paper 05, Δl(F, x).
    """
    return sum(deformation_components(cyl, load, extension).values())


def _secant(load: np.ndarray, total: np.ndarray) -> np.ndarray:
    # F/Δl → 0 as F → 0: Hertz makes Δl ~ F^(2/3), and a belt offset keeps Δl > 0.
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(load > 0, load / np.where(total > 0, total, np.inf), 0.0)


def stiffness(cyl: ElectricCylinder, load, extension) -> np.ndarray:
    """Secant axial stiffness k = F/Δl [N/m]; 0 at F = 0.

    References
    ----------
    Paper 05, k = F/Δl.
    """
    f, x = _load_extension(load, extension)
    return _secant(f, total_deformation(cyl, f, x))


@dataclass(frozen=True)
class InfluenceCoefficients:
    """Partial derivatives of each component, keyed by :data:`COMPONENTS`.

    Attributes
    ----------
    load : dict of str → ndarray [m/N]
        ∂Δl_i/∂F (the contact term is infinite at F = 0).
    extension : dict of str → ndarray [m/m]
        ∂Δl_i/∂x.
    """

    load: dict
    extension: dict


def influence_coefficients(cyl: ElectricCylinder, load, extension) -> InfluenceCoefficients:
    """Analytic ∂Δl_i/∂F and ∂Δl_i/∂x of every component.

    Parameters
    ----------
    cyl : ElectricCylinder
    load : array_like [N]
    extension : array_like [m]

    Returns
    -------
    InfluenceCoefficients

    References
    ----------
    Paper 05, influence-coefficient vectors at x = 300 mm, F = 5000 N.
    """
    f, x = _load_extension(load, extension)
    k = cyl._coefficients
    ones = np.ones_like(f)
    zeros = np.zeros_like(f)
    with np.errstate(divide="ignore"):
        d_contact = np.where(
            f > 0, (2.0 / 3.0) * k["contact"] / np.cbrt(np.where(f > 0, f, 1.0)), np.inf
        )
    d_load = {
        "bearing": k["bearing"] * ones,
        "contact": d_contact,
        "screw_thread": k["screw_thread"] * ones,
        "nut_thread": k["nut_thread"] * ones,
        "nut_body": k["nut_body"] * ones,
        "screw_axial": k["screw_axial"] * x,
        "screw_torsion": k["screw_torsion"] * x,
        "belt": k["belt"] * ones,
    }
    d_ext = {name: zeros.copy() for name in COMPONENTS}
    d_ext["screw_axial"] = k["screw_axial"] * f
    d_ext["screw_torsion"] = k["screw_torsion"] * f
    return InfluenceCoefficients(load=d_load, extension=d_ext)


@dataclass(frozen=True)
class CylinderDeformation:
    """Deformation of the cylinder at given load(s) and extension(s).

    Attributes
    ----------
    load : ndarray [N]
    extension : ndarray [m]
    components : dict of str → ndarray [m]
        Δl1…Δl8 keyed by :data:`COMPONENTS`.
    total : ndarray [m]
        Δl.
    stiffness : ndarray [N/m]
        Secant F/Δl (0 at F = 0).
    """

    load: np.ndarray
    extension: np.ndarray
    components: dict
    total: np.ndarray
    stiffness: np.ndarray

    def as_dict(self) -> dict:
        """Plain-Python (JSON-ready) version, SI units."""

        def plain(a):
            a = np.asarray(a)
            return a.item() if a.ndim == 0 else a.tolist()

        return {
            "load": plain(self.load),
            "extension": plain(self.extension),
            "components": {k: plain(v) for k, v in self.components.items()},
            "total": plain(self.total),
            "stiffness": plain(self.stiffness),
        }


def cylinder_deformation(cyl: ElectricCylinder, load, extension) -> CylinderDeformation:
    """Components, total deformation and secant stiffness in one call.

    Parameters
    ----------
    cyl : ElectricCylinder
    load : array_like [N]
    extension : array_like [m]

    Returns
    -------
    CylinderDeformation

    References
    ----------
    Paper 05, Δl(F, x) and k = F/Δl.
    """
    f, x = _load_extension(load, extension)
    components = deformation_components(cyl, f, x)
    total = sum(components.values())
    return CylinderDeformation(
        load=f, extension=x, components=components, total=total, stiffness=_secant(f, total)
    )
