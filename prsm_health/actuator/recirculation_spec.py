"""The recirculating geometry a design gives (paper 03's carrier, cam ring and assembly
dimensions): data only, each field optional.

A recirculating design (``variant = "recirculating"``) may carry a ``[recirculation]`` table;
every field it leaves out takes paper 03's rule for it, computed from the design's threads
(:meth:`prsm_health.physics.recirculating.RecirculatingGeometry.for_design`, which also checks
the whole geometry against eqs. (13)–(22)). The standard variant has none.

References
----------
Paper 03, eqs. (13)–(22) (carrier and cam ring), (34)–(35) (assembly offset), §2.2–2.3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from prsm_health.core.errors import require

#: Unit and meaning of each field (the design file's comments, docs/formats.md).
RECIRCULATION_FIELDS = {
    "carrier_outer_diameter": ("m", "carrier outer diameter D_B (eq. 15)"),
    "carrier_inner_diameter": ("m", "carrier bore d_b"),
    "groove_length": ("m", "carrier groove length l_b (eq. 17)"),
    "groove_end_radius": ("m", "carrier groove end radius R_b (eq. 18)"),
    "roller_half_length_1": ("m", "roller length s1 on one side of its contact plane"),
    "roller_half_length_2": ("m", "roller length s2 on the other side"),
    "cam_inner_diameter": ("m", "cam ring bore d_t"),
    "platform_inner_diameter": ("m", "cam-ring platform bore d_t1 (eq. 20)"),
    "platform_outer_radius": ("m", "cam-ring platform outer radius R_t1 (eq. 21)"),
    "cam_step_thickness": ("m", "cam ring end-step thickness z_t1"),
    "carrier_arc_angle": ("rad", "central angle φ_b of one carrier groove"),
    "platform_arc_angle": ("rad", "central angle φ_t1 of the platform (eq. 22)"),
    "axial_offset": ("m", "assembly offset m of the first roller (eq. 34)"),
}


@dataclass(frozen=True)
class RecirculationSpec:
    """Paper 03's carrier, cam-ring and assembly dimensions as a design gives them [m, rad];
    None: paper 03's rule from the threads (the fields of
    :class:`~prsm_health.physics.recirculating.RecirculatingGeometry`)."""

    carrier_outer_diameter: float | None = None
    carrier_inner_diameter: float | None = None
    groove_length: float | None = None
    groove_end_radius: float | None = None
    roller_half_length_1: float | None = None
    roller_half_length_2: float | None = None
    cam_inner_diameter: float | None = None
    platform_inner_diameter: float | None = None
    platform_outer_radius: float | None = None
    cam_step_thickness: float | None = None
    carrier_arc_angle: float | None = None
    platform_arc_angle: float | None = None
    axial_offset: float | None = None

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            low = 0.0 if f.name == "axial_offset" else None
            ok = isinstance(value, (int, float)) and math.isfinite(value)
            ok = ok and (value >= 0 if low is not None else value > 0)
            require(
                ok,
                f"design.recirculation.{f.name}",
                value,
                f"must be a finite number {'≥' if low is not None else '>'} 0 "
                f"[{RECIRCULATION_FIELDS[f.name][0]}]",
            )

    def given(self) -> dict[str, float]:
        """The fields the design sets (the rest follow paper 03's rules)."""
        return {
            f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None
        }
