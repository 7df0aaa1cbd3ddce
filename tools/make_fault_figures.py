"""Figures of docs/faults.md: each fault's signature as the flight-ema instrumentation records it.

Preload loss: the nut's lost motion through load reversals as the preload goes.

Localised faults (spalls, gear tooth damage): the paper-01 design with the default drive train,
100 rad/s, 300 N, 1 s, seed 4, measured by `flight-ema`; the nut axial accelerometer over 60 ms
(faulty over healthy, same seed) and its envelope spectrum (2–8 kHz band,
`prsm_health.spectra.envelope_spectrum`) with the predicted defect frequency and its harmonics
marked. Prints, per fault, the line at the defect frequency over the local median of the
envelope spectrum (the statistic tests/dynamics/test_spalls.py checks). Writes
docs/figures/fault-<name>.png.

    python tools/make_fault_figures.py [NAME ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from prsm_health import (
    HealthState,
    OperatingProfile,
    defect_frequencies,
    extract_features,
    preset,
    simulate,
)
from prsm_health.faults import fault_from_dict
from prsm_health.spectra import envelope_spectrum

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures"
DESIGN = "paper01"
SPEED = 100.0  # rad/s
PROFILE = OperatingProfile(duration=1.0, speed=SPEED, load=300.0)
SEED = 4
BAND = (2000.0, 8000.0)  # Hz: above the structural modes, below the accelerometer's limit
CHANNEL = "nut_axial_accel"

#: name → (fault table, defect frequency it should show, title)
LOCALISED = {
    "screw-spall": ({"kind": "spall", "location": "screw"}, "screw_flank", "screw flank spall"),
    "nut-spall": ({"kind": "spall", "location": "nut"}, "nut_flank", "nut flank spall"),
    "roller-spall": ({"kind": "spall", "location": "roller"}, "roller_flank", "roller flank spall"),
}


def line_ratio(f: np.ndarray, p: np.ndarray, f0: float) -> float:
    """The largest of the 3 bins around f0 over the median of ±40 % around it."""
    k = int(np.argmin(np.abs(f - f0)))
    return float(p[k - 1 : k + 2].max() / np.median(p[(f > 0.6 * f0) & (f < 1.4 * f0)]))


def severity_text(fault) -> str:
    value = getattr(fault, fault.severity_field)
    return f"{value * 1e6:g} µm" if fault.severity_field == "depth" else f"{value:g}"


def localised_figure(name: str, healthy_run) -> tuple[Path, float]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table, location, title = LOCALISED[name]
    fault = fault_from_dict(table)
    run = simulate(DESIGN, HealthState(faults=(fault,)), PROFILE, "flight-ema", SEED)
    f0 = defect_frequencies(preset(DESIGN), SPEED)[location]
    fig, (ax_t, ax_e) = plt.subplots(2, 1, figsize=(9, 6))
    shown = (run.time >= 0.5) & (run.time < 0.56)
    t_ms = 1e3 * run.time[shown]
    ax_t.plot(t_ms, healthy_run[CHANNEL][shown], color="0.6", lw=0.8, label="healthy")
    ax_t.plot(t_ms, run[CHANNEL][shown], color="C3", lw=0.8, label=title)
    ax_t.set(xlabel="time [ms]", ylabel="nut axial acceleration [m/s²]")
    ax_t.legend(loc="upper right", fontsize=8)
    ratio = float("nan")
    for r, color, label in ((healthy_run, "0.6", "healthy"), (run, "C3", title)):
        f, p = envelope_spectrum(r[CHANNEL], r.sample_rate, BAND)
        keep = f <= 5 * f0
        ax_e.semilogy(f[keep], p[keep], color=color, lw=0.9, label=label)
        if r is run:
            ratio = line_ratio(f, p, f0)
    for k in (1, 2, 3, 4):
        ax_e.axvline(k * f0, color="k", ls="--", lw=0.6, alpha=0.6)
    ax_e.text(f0, ax_e.get_ylim()[1], f" {location}\n {f0:.1f} Hz", va="top", fontsize=8)
    ax_e.set(
        xlabel="frequency [Hz]",
        ylabel=f"envelope PSD {BAND[0] / 1e3:g}–{BAND[1] / 1e3:g} kHz [(m/s²)²/Hz]",
    )
    ax_e.legend(loc="upper right", fontsize=8)
    fig.suptitle(
        f"{title}, default severity ({fault.severity_field} {severity_text(fault)}): flight-ema, "
        f"{SPEED:g} rad/s, {PROFILE.load:g} N — line/median {ratio:.1f}×",
        fontsize=10,
    )
    fig.tight_layout()
    path = OUT / f"fault-{name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path, ratio


REVERSING = OperatingProfile(
    duration=0.3,
    speed=SPEED,
    load=0.0,
    load_profile="reversing",
    load_amplitude=300.0,
    load_frequency=10.0,
    accel_time=0.002,
)


def preload_figure() -> Path:
    """The lost-motion indicator through ±300 N load reversals for a nut with 5 µm of worn
    clearance and 10 µm of installed preload, as the preload is lost, read by flight-ema's
    sensors (LVDT, resolver) and by ideal ones."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fractions = np.linspace(0.0, 1.0, 6)
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for instrumentation, color in (("flight-ema", "C3"), ("ideal", "0.4")):
        values = []
        for fraction in fractions:
            faults = ({"kind": "preload_loss", "fraction": float(fraction)},) if fraction else ()
            health = HealthState.uniform(5e-6, preload=10e-6, faults=faults)
            run = simulate(DESIGN, health, REVERSING, instrumentation, SEED)
            values.append(extract_features(run)["lost_motion"])
        ax.plot(100 * fractions, 1e6 * np.array(values), "o-", color=color, label=instrumentation)
        print(f"  lost motion, {instrumentation}: " + ", ".join(f"{1e6 * v:.1f}" for v in values))
        if not np.all(np.isfinite(values)):
            ax.text(0, 1e6 * np.nanmin(values), f"{instrumentation}: no reversal detected\n"
                    "(the drive torque stays one-signed)", fontsize=7, color=color, va="top")  # fmt: skip
    ax.axvline(50, color="k", ls=":", lw=0.8)
    ax.text(51, ax.get_ylim()[0], " interference gone", va="bottom", fontsize=8)
    ax.set(
        xlabel="preload lost [%]",
        ylabel="lost motion [µm]",
        title="Preload loss (b = 5 µm, 10 µm installed), ±300 N reversals",
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = OUT / "fault-preload-loss.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(names: list[str]) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    names = names or [*LOCALISED, "preload-loss"]
    healthy = simulate(DESIGN, HealthState(), PROFILE, "flight-ema", SEED)
    for name in names:
        if name == "preload-loss":
            print(f"{name:14s} {preload_figure().relative_to(OUT.parents[1])}")
            continue
        path, ratio = localised_figure(name, healthy)
        print(f"{name:14s} line/median {ratio:6.1f}×  {path.relative_to(OUT.parents[1])}")


if __name__ == "__main__":
    main(sys.argv[1:])
