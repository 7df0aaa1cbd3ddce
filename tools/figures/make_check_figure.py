"""A recording of the built-in health check, its phases shaded and named.

Paper-01 design (or ``--design``), default drive train and health, flight-ema instrumentation,
Hertzian flanks, seed 3: the built-in ``health-check`` (prsm_health.actuator.health_check) as
the actuator runs it, loads resolved against the design's ratings. Plots the measured screw
speed, drive torque, nut position and nut axial acceleration over the whole check with each
phase shaded and named (the ramps between phases left white), and prints the energy book
(drive − output − dissipated, relative to the energy through the actuator). Writes
docs/figures/health-check.png.

    python tools/figures/make_check_figure.py [--design paper01] [--out FILE]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from prsm_health import OperatingProfile, Scenario, SimulationOptions
from prsm_health.apps.plots import plot_check

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures" / "health-check.png"


def simulate_check(design: str):
    scenario = Scenario(
        design=design,
        profile=OperatingProfile(check="health-check"),
        instrumentation="flight-ema",
        options=SimulationOptions(contact_law="hertz"),
        seed=3,
    )
    return scenario.simulate(progress=True)


def energy_residual(energy: dict) -> float:
    """(drive − output − dissipated) over the energy through the actuator, (|drive| + |load|)/2
    (output = −load work, the energy book's sign; the high-load stroke back-drives the motor,
    so the net drive energy alone can be small)."""
    through = 0.5 * (abs(energy["drive"]) + abs(energy["load"]))
    return (energy["drive"] + energy["load"] - energy["dissipated"]) / through


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--design", default="paper01")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    run = simulate_check(args.design)
    e = run.energy
    print(
        f"energy: drive {e['drive']:.4g} J, output {-e['load']:.4g} J, dissipated "
        f"{e['dissipated']:.4g} J; (drive − output − dissipated)/(energy through) = "
        f"{100 * energy_residual(e):+.3f} %"
    )
    for p in run.check.phases:
        print(f"phase {p.index} {p.name!r}: {p.start:.3f}–{p.end:.3f} s")
    print("wrote", plot_check(run, args.out))


if __name__ == "__main__":
    main()
