"""matplotlib figures: run time traces and spectra with the characteristic frequencies marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .channels import UNITS
from .run import Run
from .spectra import amplitude_spectrum


def plot_run(
    run: Run, path: str | Path, mesh_frequency: float | None = None, harmonics: int = 5
) -> Path:
    """Time traces and spectra of a run's nut accelerations and torques, saved as PNG.

    Parameters
    ----------
    run : Run
    path : str or Path
    mesh_frequency : float or None [Hz]
        Marked with its harmonics on the spectra.
    harmonics : int
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    channels = ["nut_axial_accel", "nut_tangential_accel", "nut_radial_x_accel", "drive_torque"]
    channels = [c for c in channels if c in run.channels]
    fig, axes = plt.subplots(len(channels), 2, figsize=(12, 2.4 * len(channels)), squeeze=False)
    for row, name in enumerate(channels):
        x = run.channels[name]
        ax_t, ax_f = axes[row]
        ax_t.plot(run.time, x, lw=0.6)
        ax_t.set_ylabel(f"{name}\n[{UNITS[name]}]", fontsize=8)
        ax_f.set_ylabel(f"amplitude\n[{UNITS[name]}]", fontsize=8)
        f, a = amplitude_spectrum(x, run.sample_rate)
        ax_f.semilogy(f[1:], np.maximum(a[1:], 1e-12), lw=0.6)
        top = min(run.sample_rate / 2, 8 * (mesh_frequency or 500.0))
        ax_f.set_xlim(0, top)
        if mesh_frequency:
            for k in range(1, harmonics + 1):
                if k * mesh_frequency < top:
                    ax_f.axvline(k * mesh_frequency, color="tab:red", lw=0.8, ls="--", alpha=0.7)
            ax_f.text(
                mesh_frequency,
                ax_f.get_ylim()[1],
                f" f_mesh {mesh_frequency:.1f} Hz",
                color="tab:red",
                fontsize=7,
                va="top",
            )
    axes[-1][0].set_xlabel("time [s]")
    axes[-1][1].set_xlabel("frequency [Hz] (dashed: gear mesh harmonics)")
    fig.suptitle(_run_title(run.labels), fontsize=10)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _run_title(labels: dict) -> str:
    """Design, clearance, speed, load with its profile, seed — what a reader needs to place it."""
    load = f"load {labels.get('axial_load', 0):g} N"
    profile = labels.get("load_profile", "constant")
    if profile != "constant":
        load += f" {profile} ±{labels.get('load_amplitude', 0):g} N"
    motion = labels.get("motion", "constant")
    return (
        f"{labels.get('design', '')}  clearance {1e6 * labels.get('clearance_screw', 0):.0f} µm  "
        f"speed {labels.get('screw_speed', 0):g} rad/s"
        + (f" ({motion})" if motion != "constant" else "")
        + f"  {load}  seed {labels.get('seed', '')}"
    )


def plot_diagnosis(result, path: str | Path) -> Path:
    """Per-window clearance estimates with their 90 % intervals and class probabilities, as PNG.

    Each window is drawn over its own span (start to end), the last one included; the
    recording's overall estimate and interval are the dashed line and the band behind them.

    Parameters
    ----------
    result : Diagnosis
        A recording diagnosis (:func:`prsm_health.diagnosis.diagnose`).
    path : str or Path
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def um(value):
        return np.nan if value is None else 1e6 * value

    wins = result.windows or [result]
    spans = [(w.window["start"], w.window["end"]) if w.window else (0.0, 1.0) for w in wins]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    overall = result.clearance
    t0, t1 = spans[0][0], spans[-1][1]
    a1.axhspan(
        um(overall["lower"]),
        um(overall["upper"]),
        color="tab:gray",
        alpha=0.15,
        label="recording: 90 % interval",
    )
    a1.hlines(
        um(overall["estimate"]),
        t0,
        t1,
        colors="tab:gray",
        linestyles="--",
        label="recording: estimate",
    )
    for k, ((a, b), w) in enumerate(zip(spans, wins)):
        c = w.clearance
        a1.fill_between(
            [a, b],
            um(c["lower"]),
            um(c["upper"]),
            color="tab:blue",
            alpha=0.3,
            label="window: 90 % interval" if k == 0 else None,
        )
        a1.hlines(
            um(c["estimate"]),
            a,
            b,
            colors="tab:blue",
            lw=2,
            label="window: estimate" if k == 0 else None,
        )
    a1.set_ylabel("clearance [µm]")
    a1.legend(fontsize=8, loc="best")
    for i, cls in enumerate(result.class_probabilities):
        for k, ((a, b), w) in enumerate(zip(spans, wins)):
            probability = w.class_probabilities.get(cls, 0.0)
            a2.hlines(probability, a, b, lw=2, colors=f"C{i}", label=cls if k == 0 else None)
    a2.set_ylabel("class probability [-]")
    a2.set_xlabel("recording time [s] (one segment per window)")
    a2.set_ylim(-0.02, 1.02)
    a2.legend(fontsize=8, loc="best")
    a2.set_xlim(t0, t1 if t1 > t0 else t0 + 1.0)
    fig.suptitle(
        f"{result.fault_class}  clearance {um(overall['estimate']):.1f} µm "
        f"[{um(overall['lower']):.1f}, {um(overall['upper']):.1f}]  "
        f"{len(wins)} window(s)  model {result.model['name']}",
        fontsize=10,
    )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
