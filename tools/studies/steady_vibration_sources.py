"""Steady nut vibration of the paper-01 design and where it comes from (docs/validation.md).

Paper-01 design, 100 rad/s, steady 100 N, default drive train, 0.3 s per run of which the
last two thirds are analysed, seeds 1–3; each geometric error switched on alone, off alone, and
the lead-error grade varied. Prints Markdown tables of the nut axial, tangential and radial
acceleration RMS (truth, before any sensor) and the peak of the axial one.

    python tools/studies/steady_vibration_sources.py
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from prsm_health import (
    HealthState,
    ManufacturingVariation,
    OperatingProfile,
    SimulationOptions,
    simulate,
)

SEEDS = (1, 2, 3)
FULL = ManufacturingVariation()
NONE = ManufacturingVariation.ideal()
GROUPS = {
    "lead error (v_300p, v_2πp)": ("lead_error_cumulative", "lead_error_periodic"),
    "flank waviness": ("flank_waviness",),
    "screw and roller runout": ("screw_runout", "roller_runout"),
    "gear pitch, profile and transmission error": (
        "gear_pitch_error",
        "gear_profile_error",
        "transmission_error",
    ),
    "roller scatter (pitch, pocket, mesh stiffness)": (
        "pitch_error",
        "position_error",
        "eccentricity",
        "mesh_stiffness_spread",
    ),
}


def level(variation: ManufacturingVariation) -> tuple[float, float, float, float]:
    """Mean over seeds of axial RMS, axial peak, tangential RMS, radial-x RMS [m/s²]."""
    out = []
    for seed in SEEDS:
        r = simulate(
            "paper01",
            HealthState(),
            OperatingProfile(duration=0.3, speed=100.0, load=100.0),
            "ideal",
            seed,
            options=SimulationOptions(variation=variation),
        )
        steady = slice(len(r) // 3, None)
        ax = r.truth["nut_axial_accel"][steady]
        out.append(
            (
                np.std(ax),
                np.max(np.abs(ax - ax.mean())),
                np.std(r.truth["nut_tangential_accel"][steady]),
                np.std(r.truth["nut_radial_x_accel"][steady]),
            )
        )
    return tuple(float(v) for v in np.mean(out, axis=0))


def _row(name: str, values) -> str:
    return f"| {name} | " + " | ".join(f"{v:.3g}" for v in values) + " |"


def main() -> None:
    head = (
        "| errors | axial RMS | axial peak | tangential RMS | radial x RMS |\n|---|---|---|---|---|"
    )
    print(head)
    print(_row("all (default: ISO 3408-3 grade 5)", level(FULL)))
    print(_row("none", level(NONE)))
    for name, keys in GROUPS.items():
        print(_row(f"only {name}", level(replace(NONE, **{k: getattr(FULL, k) for k in keys}))))
    for name, keys in GROUPS.items():
        print(_row(f"all but {name}", level(replace(FULL, **{k: 0.0 for k in keys}))))
    print()
    print(
        "| lead grade | axial RMS | axial peak | tangential RMS | radial x RMS |\n|---|---|---|---|---|"
    )
    for grade in (1, 3, 5, 7):
        print(_row(str(grade), level(ManufacturingVariation.grade(grade))))


if __name__ == "__main__":
    main()
