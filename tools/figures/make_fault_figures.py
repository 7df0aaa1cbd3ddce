"""Figures of docs/faults.md: each fault's signature as the flight-ema instrumentation records it.

Lubrication: the Stribeck curve of the thread contact and the drive torque flight-ema measures
as the screw speeds up, new and degraded.

Preload loss: the nut's lost motion through load reversals as the preload goes.

Localised faults (spalls, gear tooth damage): the paper-01 design with the default drive train,
100 rad/s, 3000 N, 1 s, seed 4, measured by `flight-ema`; the nut axial accelerometer over 60 ms
(faulty over healthy, same seed), its spectrum and its envelope spectrum (2–8 kHz band,
`prsm_health.signals.spectra.envelope_spectrum`) with the predicted defect frequency and its harmonics
marked. Prints, per fault, the line at the defect frequency over the local median of each
spectrum (the statistic tests/dynamics/test_spalls.py checks). Writes
docs/figures/fault-<name>.png.

    python tools/figures/make_fault_figures.py [NAME ...]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from prsm_health import (
    HealthState,
    OperatingProfile,
    SimulationOptions,
    defect_frequencies,
    extract_features,
    preset,
    simulate,
)
from prsm_health.actuator.faults import fault_from_dict
from prsm_health.physics.lubrication import DEFAULT_LUBRICANT, stribeck_curve
from prsm_health.signals.spectra import envelope_spectrum

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures"
DESIGN = "paper01"
SPEED = 100.0  # rad/s
PROFILE = OperatingProfile(duration=1.0, speed=SPEED, load=3000.0)
#: A screw spall 25 mm ahead of the nut's start: its rollers reach it after ≈ 0.06 s and leave it
#: ≈ 0.14 s later; the spectra of that run are taken over that interval only.
PASSING = OperatingProfile(duration=0.4, speed=SPEED, load=3000.0)
SEED = 4
BAND = (2000.0, 8000.0)  # Hz: above the structural modes, below the accelerometer's limit
CHANNEL = "nut_axial_accel"

#: name → (fault table, defect frequency it should show, title, profile)
LOCALISED = {
    "screw-spall": (
        {"kind": "spall", "location": "screw", "length": 6e-3, "position": 0.025},
        "screw_flank",
        "screw flank spall, 6 mm, 25 mm ahead",
        PASSING,
    ),
    "nut-spall": (
        {"kind": "spall", "location": "nut", "length": 6e-3},
        "nut_flank",
        "nut flank spall, 6 mm",
        PROFILE,
    ),
    "roller-spall": (
        {"kind": "spall", "location": "roller"},
        "roller_flank",
        "roller flank spall",
        PROFILE,
    ),
    "ring-tooth-crack": (
        {"kind": "tooth_crack", "location": "ring_gear"},
        "ring_gear_tooth",
        "ring gear tooth crack",
        PROFILE,
    ),
    "roller-tooth-crack": (
        {"kind": "tooth_crack", "location": "roller_gear"},
        "roller_gear_tooth",
        "roller gear tooth crack",
        PROFILE,
    ),
    "ring-tooth-pit": (
        {"kind": "tooth_pit", "location": "ring_gear"},
        "ring_gear_tooth",
        "ring gear tooth pit",
        PROFILE,
    ),
}


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, name: str) -> Path:
    fig.tight_layout()
    path = OUT / f"fault-{name}.png"
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return path


def line_ratio(f: np.ndarray, p: np.ndarray, f0: float) -> float:
    """The largest of the 3 bins around f0 over the median of ±40 % around it."""
    k = int(np.argmin(np.abs(f - f0)))
    return float(p[k - 1 : k + 2].max() / np.median(p[(f > 0.6 * f0) & (f < 1.4 * f0)]))


def severity_text(fault) -> str:
    value = getattr(fault, fault.severity_field)
    if fault.severity_field == "length":
        return f"{value * 1e3:.3g} mm"
    return f"{value * 1e6:.4g} µm" if fault.severity_field == "depth" else f"{value:g}"


def localised_figure(name: str, healthy: dict) -> tuple[Path, float, float]:
    plt = pyplot()
    from scipy import signal

    table, location, title, profile = LOCALISED[name]
    fault = fault_from_dict(table)
    if profile not in healthy:
        healthy[profile] = simulate(DESIGN, HealthState(), profile, "flight-ema", SEED)
    healthy_run = healthy[profile]
    run = simulate(DESIGN, HealthState(faults=(fault,)), profile, "flight-ema", SEED)
    f0 = defect_frequencies(preset(DESIGN), SPEED)[location]
    fig, (ax_t, ax_d, ax_e) = plt.subplots(3, 1, figsize=(9, 8.5))
    window = slice(None)
    if fault.kind == "spall" and fault.location == "screw":
        # while the rollers' threads span the spall (nut travel counted from its start)
        travel = np.abs(run.truth["nut_position"] - run.truth["nut_position"][0])
        offset = abs(fault.position)
        half = 0.5 * preset(DESIGN).engaged_threads * preset(DESIGN).pitch
        inside = np.flatnonzero(np.abs(travel - offset) < half)
        window = slice(inside[0], inside[-1] + 1)
    mid = run.time[window][len(run.time[window]) // 2]
    shown = (run.time >= mid - 0.03) & (run.time < mid + 0.03)
    t_ms = 1e3 * run.time[shown]
    ax_t.plot(t_ms, healthy_run[CHANNEL][shown], color="0.6", lw=0.8, label="healthy")
    ax_t.plot(t_ms, run[CHANNEL][shown], color="C3", lw=0.8, label=title)
    ax_t.set(xlabel="time [ms]", ylabel="nut axial acceleration [m/s²]")
    ax_t.legend(loc="upper right", fontsize=8)
    ratios = {}
    for r, color, label in ((healthy_run, "0.6", "healthy"), (run, "C3", title)):
        x = r[CHANNEL][window]
        nperseg = min(8192, len(x))
        spectra = {
            "direct": signal.welch(x - x.mean(), fs=r.sample_rate, nperseg=nperseg),
            "envelope": envelope_spectrum(x, r.sample_rate, BAND, nperseg=nperseg),
        }
        for (kind, (f, p)), ax in zip(spectra.items(), (ax_d, ax_e)):
            keep = f <= 5 * f0
            ax.semilogy(f[keep], p[keep], color=color, lw=0.9, label=label)
            if r is run:
                ratios[kind] = line_ratio(f, p, f0)
    for ax in (ax_d, ax_e):
        for k in (1, 2, 3, 4):
            ax.axvline(k * f0, color="k", ls="--", lw=0.6, alpha=0.6)
        ax.text(f0, ax.get_ylim()[1], f" {location}\n {f0:.1f} Hz", va="top", fontsize=8)
        ax.legend(loc="upper right", fontsize=8)
    ax_d.set(xlabel="frequency [Hz]", ylabel="PSD [(m/s²)²/Hz]")
    ax_e.set(
        xlabel="frequency [Hz]",
        ylabel=f"envelope PSD {BAND[0] / 1e3:g}–{BAND[1] / 1e3:g} kHz",
    )
    during = "" if window == slice(None) else ", spectra while the nut spans it"
    fig.suptitle(
        f"{title} ({fault.severity_field} {severity_text(fault)}): flight-ema, {SPEED:g} rad/s, "
        f"{profile.load:g} N{during}\nline/median: direct {ratios['direct']:.1f}×, "
        f"envelope {ratios['envelope']:.1f}×",
        fontsize=10,
    )
    return save(fig, name), ratios["direct"], ratios["envelope"]


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
    plt = pyplot()

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
    return save(fig, "preload-loss")


def lubrication_figure() -> Path:
    """Left: the screw–roller contact's Coulomb coefficient vs entrainment speed (the Stribeck
    curve of :mod:`prsm_health.physics.lubrication`) at three temperatures and for a degraded and a
    starved lubricant. Right: the mean drive torque flight-ema measures at 300 N vs screw speed,
    new and degraded lubricant, and with paper 02's constant coefficient."""
    plt = pyplot()

    design = preset(DESIGN)
    speeds = np.geomspace(1e-4, 5.0, 300)
    fig, (ax_mu, ax_t) = plt.subplots(1, 2, figsize=(11, 4))
    cases = [
        ("new, 20 °C", {"temperature": 293.15}, "C0", "-"),
        ("new, 40 °C", {"temperature": 313.15}, "C1", "-"),
        ("new, 80 °C", {"temperature": 353.15}, "C3", "-"),
        ("degraded 0.5, 40 °C", {"degradation": 0.5}, "C1", "--"),
        ("starved 0.5, 40 °C", {"starvation": 0.5}, "C1", ":"),
    ]
    for label, kw, color, style in cases:
        curve = stribeck_curve(design, DEFAULT_LUBRICANT, speeds, axial_load=300.0, **kw)
        ax_mu.semilogx(speeds, curve.coefficient, color=color, ls=style, label=label)
    ax_mu.set(
        xlabel="entrainment speed [m/s]",
        ylabel="Coulomb coefficient μ [-]",
        title=f"Stribeck curve, screw–roller contact ({DEFAULT_LUBRICANT}, 300 N)",
    )
    ax_mu.legend(fontsize=8)
    screw_speeds = [10.0, 30.0, 100.0, 300.0]
    for label, health, options, color in (
        ("new lubricant", HealthState(), None, "C1"),
        ("degraded 0.5", HealthState(lubricant_degradation=0.5), None, "C3"),
        ("constant μ = 0.1 (paper 02)", HealthState(), SimulationOptions(lubrication="constant"),
         "0.5"),
    ):  # fmt: skip
        torque = []
        for w in screw_speeds:
            profile = OperatingProfile(duration=0.1, speed=w, load=300.0)
            run = simulate(DESIGN, health, profile, "flight-ema", SEED, options=options)
            torque.append(float(np.mean(run["drive_torque"])))
        ax_t.semilogx(screw_speeds, torque, "o-", color=color, label=label)
        print(f"  drive torque, {label}: " + ", ".join(f"{t:.3f}" for t in torque) + " N·m")
    ax_t.set(
        xlabel="screw speed [rad/s]",
        ylabel="mean drive torque [N·m] (flight-ema)",
        title="Measured drive torque at 300 N",
    )
    ax_t.legend(fontsize=8)
    return save(fig, "lubrication")


def main(argv: list[str] | None = None) -> None:
    every = [*LOCALISED, "preload-loss", "lubrication"]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"figures (default all): {every}")
    names = parser.parse_args(argv).names or every
    unknown = sorted(set(names) - set(every))
    if unknown:
        parser.error(f"unknown figure(s) {unknown}: choose from {every}")
    OUT.mkdir(parents=True, exist_ok=True)
    healthy: dict = {}
    for name in names:
        if name in ("preload-loss", "lubrication"):
            maker = preload_figure if name == "preload-loss" else lubrication_figure
            print(f"{name:18s} {maker().relative_to(OUT.parents[1])}")
            continue
        path, direct, envelope = localised_figure(name, healthy)
        print(
            f"{name:18s} line/median direct {direct:5.1f}×, envelope {envelope:5.1f}×  "
            f"{path.relative_to(OUT.parents[1])}"
        )


if __name__ == "__main__":
    main()
