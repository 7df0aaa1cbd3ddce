"""Recirculating PRSM (paper 03): threadless-area design rules, carrier/cam-ring checks,
kinematics with roller resets, and the cam-ring/roller reset force as a signal.

A recirculating PRSM has grooved rollers (no helix, no gears). Relative to the nut each roller
drifts back by one lead per carrier revolution (eq. 31); in the nut's threadless area the
convex platform of a cam ring lifts it over one screw thread and pushes it forward by that
lead again ("reset"). Each roller resets once per carrier revolution, so the mechanism has
N reset events per carrier revolution, at N·f_c (:func:`~prsm_health.physics.kinematics.
characteristic_frequencies`, ``roller_reset``).

Modules (each documents its readings of the paper):

- :mod:`.geometry` — threadless area (eqs. 5–12), carrier/cam-ring design rules
  (eqs. 13–22, :func:`check_recirculating`), assembly offsets (eqs. 34–37).
- :mod:`.travel` — speeds, reset events and nut/roller displacements (eqs. 23–33).
- :mod:`.impact` — ADAMS IMPACT contact (eq. 38), the single-reset pulse and the sampled
  reset force series.

Every public name is re-exported here; import from ``prsm_health.physics.recirculating``.

References
----------
Paper 03 (docs/references.md) — eqs. (1)–(22) design, (23)–(33) motion, (34)–(37) assembly,
(38) and §4.1 contact parameters, §4.2–4.3 results.
"""

from __future__ import annotations

from .geometry import (
    ANGLE_TOLERANCE,
    FIT_TOLERANCE,
    TWO_PI,
    RecirculatingGeometry,
    ThreadlessArea,
    arc_de,
    cam_ring_spacing,
    check_recirculating,
    eq13_roller_limit,
    groove_length,
    lift_radius,
    orbital_angle,
    platform_contact_offset,
    radial_lift,
    reset_stroke,
    roller_arc_radius,
    roller_axial_offsets,
    roller_spacing,
    threadless_angle,
    threadless_area,
    threadless_radius,
    with_explicit_geometry,
)
from .impact import (
    PAPER03_CONTACT,
    ImpactContact,
    ResetForceSeries,
    ResetPulse,
    impact_force,
    reset_force_series,
    reset_pulse,
)
from .travel import (
    RecirculatingMotion,
    ResetEvents,
    carrier_speed,
    motion,
    nut_speed,
    reset_events,
    roller_speed,
)

__all__ = [
    "ANGLE_TOLERANCE",
    "FIT_TOLERANCE",
    "PAPER03_CONTACT",
    "TWO_PI",
    "ImpactContact",
    "RecirculatingGeometry",
    "RecirculatingMotion",
    "ResetEvents",
    "ResetForceSeries",
    "ResetPulse",
    "ThreadlessArea",
    "arc_de",
    "cam_ring_spacing",
    "carrier_speed",
    "check_recirculating",
    "eq13_roller_limit",
    "groove_length",
    "impact_force",
    "lift_radius",
    "motion",
    "nut_speed",
    "orbital_angle",
    "platform_contact_offset",
    "radial_lift",
    "reset_events",
    "reset_force_series",
    "reset_pulse",
    "reset_stroke",
    "roller_arc_radius",
    "roller_axial_offsets",
    "roller_speed",
    "roller_spacing",
    "threadless_angle",
    "threadless_area",
    "threadless_radius",
    "with_explicit_geometry",
]
