"""One figure per built-in instrumentation profile: a reversing-load recording as it records it.

Paper-01 design, default drive train, b = 20 µm, 100 rad/s, a ±300 N load reversing at 10 Hz
(2 ms edges), seed 5. Each fitted channel over 40 ms around the first load reversal: the
profile's measurement in colour over the true signal it reads in grey. Writes
docs/figures/profile-<name>.png.

    python tools/figures/make_profile_figures.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.core.channels import UNITS
from prsm_health.simulation.instrumentation import list_profiles, load_instrumentation

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures"
PROFILE = OperatingProfile(
    duration=0.3,
    speed=100.0,
    load=0.0,
    load_profile="reversing",
    load_amplitude=300.0,
    load_frequency=10.0,
    accel_time=0.002,
)
#: The truth signal each measured channel reads (contract: docs/formats.md).
READS = {"screw_angle": "motor_angle", "screw_speed": "motor_speed", "drive_torque": "motor_torque"}
WINDOW = (0.035, 0.075)  # s: the first reversal is at 0.05 s


def figure(name: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = simulate(
        "paper01",
        HealthState.uniform(20e-6),
        PROFILE,
        name,
        5,
        options=SimulationOptions(contact_law="hertz"),
    )
    shown = (run.time >= WINDOW[0]) & (run.time <= WINDOW[1])
    t_ms = 1e3 * run.time[shown]
    names = list(run.channels)
    fig, axes = plt.subplots(len(names), 1, figsize=(9, 1.6 * len(names)), sharex=True)
    axes = np.atleast_1d(axes)
    for ax, channel in zip(axes, names):
        truth = run.truth[READS.get(channel, channel)][shown]
        measured = run.channels[channel][shown]
        if channel in ("screw_angle", "nut_position"):  # show the deviation from a straight line
            trend = np.polyval(np.polyfit(t_ms, truth, 1), t_ms)
            truth, measured = truth - trend, measured - trend
            label = f"{channel} − trend\n[{UNITS[channel]}]"
        else:
            label = f"{channel}\n[{UNITS[channel]}]"
        ax.plot(t_ms, truth, color="0.6", lw=1.2, label="truth")
        ax.plot(t_ms, measured, color="tab:blue", lw=0.7, label=name)
        ax.set_ylabel(label, fontsize=7)
        ax.tick_params(labelsize=7)
    axes[0].legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("time [ms]")
    description = load_instrumentation(name).description
    fig.suptitle(f"{name}: {description}\nb = 20 µm, ±300 N load reversing at 10 Hz", fontsize=9)
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"profile-{name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main() -> None:
    for name in list_profiles():
        print(figure(name))


if __name__ == "__main__":
    main()
