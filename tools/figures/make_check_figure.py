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

import numpy as np

from prsm_health import OperatingProfile, Scenario, SimulationOptions
from prsm_health.core.channels import UNITS

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures" / "health-check.png"
CHANNELS = ("screw_speed", "drive_torque", "nut_position", "nut_axial_accel")
SCALE = {"nut_position": (1e3, "mm")}  # shown in mm, the others in SI
COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860")


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


def figure(run, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    present = [c for c in CHANNELS if c in run.channels]
    fig, axes = plt.subplots(len(present), 1, figsize=(10, 1.9 * len(present)), sharex=True)
    axes = np.atleast_1d(axes)
    for ax, name in zip(axes, present):
        factor, unit = SCALE.get(name, (1.0, UNITS[name]))
        ax.plot(run.time, factor * run.channels[name], lw=0.5, color="k")
        ax.set_ylabel(f"{name}\n[{unit}]", fontsize=8)
        ax.grid(alpha=0.3)
        for k, phase in enumerate(run.check["phases"]):
            ax.axvspan(phase["start"], phase["end"], color=COLOURS[k % len(COLOURS)], alpha=0.18)
    top = axes[0]
    for k, phase in enumerate(run.check["phases"]):
        top.text(
            0.5 * (phase["start"] + phase["end"]),
            1.02,
            phase["name"],
            transform=top.get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=8,
            color=COLOURS[k % len(COLOURS)],
        )
    axes[-1].set_xlabel("time [s]")
    labels = run.labels
    fig.suptitle(
        f"health check '{run.check['name']}' — {labels.get('design')}, "
        f"{run.scenario.get('instrumentation')}: phases shaded (ramps between them unshaded)",
        fontsize=10,
        y=0.995,
    )
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


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
    for p in run.check["phases"]:
        print(f"phase {p['index']} {p['name']!r}: {p['start']:.3f}–{p['end']:.3f} s")
    print("wrote", figure(run, args.out))


if __name__ == "__main__":
    main()
