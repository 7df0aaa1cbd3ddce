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
    labels = run.labels
    fig.suptitle(
        f"{labels.get('design', '')}  clearance {1e6 * labels.get('clearance_screw', 0):.0f} µm  "
        f"speed {labels.get('screw_speed', 0):g} rad/s  load {labels.get('axial_load', 0):g} N  seed {labels.get('seed', '')}",
        fontsize=10,
    )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
