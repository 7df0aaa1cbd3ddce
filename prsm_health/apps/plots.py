"""matplotlib figures: run time traces and spectra with the characteristic frequencies marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from prsm_health.core.channels import UNITS
from prsm_health.core.run import Run
from prsm_health.signals.spectra import amplitude_spectrum


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
    fig.suptitle(_run_title(run), fontsize=10)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


#: Phase colours of a health-check plot (cycled).
PHASE_COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860")
#: Channels of a health-check plot, and the ones shown in other units than SI.
CHECK_CHANNELS = ("screw_speed", "drive_torque", "nut_position", "nut_axial_accel")
_SCALE = {"nut_position": (1e3, "mm")}


def plot_check(run: Run, path: str | Path) -> Path:
    """A health-check recording's measured channels over time with its phases shaded and named
    (the ramps between phases left white), saved as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    present = [c for c in CHECK_CHANNELS if c in run.channels]
    fig, axes = plt.subplots(len(present), 1, figsize=(10, 1.9 * len(present)), sharex=True)
    axes = np.atleast_1d(axes)
    phases = run.check.phases if run.check is not None else ()
    for ax, name in zip(axes, present):
        factor, unit = _SCALE.get(name, (1.0, UNITS[name]))
        ax.plot(run.time, factor * run.channels[name], lw=0.5, color="k")
        ax.set_ylabel(f"{name}\n[{unit}]", fontsize=8)
        ax.grid(alpha=0.3)
        for k, phase in enumerate(phases):
            colour = PHASE_COLOURS[k % len(PHASE_COLOURS)]
            ax.axvspan(phase.start, phase.end, color=colour, alpha=0.18)
    for k, phase in enumerate(phases):
        axes[0].text(
            0.5 * (phase.start + phase.end),
            1.02,
            phase.name,
            transform=axes[0].get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=8,
            color=PHASE_COLOURS[k % len(PHASE_COLOURS)],
        )
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(
        f"health check '{run.check.name if run.check else ''}' — {run.operating.design or ''}, "
        f"{run.scenario.get('instrumentation', '')}, seed {run.labels.get('seed', '')}: "
        "phases shaded (ramps between them unshaded)",
        fontsize=10,
        y=0.995,
    )
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _run_title(run: Run) -> str:
    """Design, speed, load (the operating point) and, of a simulated run, its clearance, motion,
    load profile and seed (its labels) — what a reader needs to place it."""
    op, labels = run.operating, run.labels
    parts = [op.design or ""]
    if "clearance_screw" in labels:
        parts.append(f"clearance {1e6 * labels['clearance_screw']:.0f} µm")
    motion = labels.get("motion", "constant")
    if op.screw_speed is not None:
        parts.append(
            f"speed {op.screw_speed:g} rad/s" + (f" ({motion})" if motion != "constant" else "")
        )
    if op.axial_load is not None:
        load = f"load {op.axial_load:g} N"
        profile = labels.get("load_profile", "constant")
        if profile != "constant":
            load += f" {profile} ±{op.load_amplitude or 0:g} N"
        parts.append(load)
    if "seed" in labels:
        parts.append(f"seed {labels['seed']}")
    return "  ".join(parts)


def plot_diagnosis(result, path: str | Path) -> Path:
    """Per-window clearance estimates with their 90 % intervals and class probabilities, as PNG.

    Each window is drawn over its own span (start to end), the last one included; the
    recording's overall estimate and interval are the dashed line and the band behind them.
    Where a target is not observable (:mod:`prsm_health.diagnostics.not_observable`) its numbers are
    no reading: the clearance estimate is a hollow grey marker in a hatched grey interval, the
    class probabilities are left out (a grey span), each labelled "not observable".

    Parameters
    ----------
    result : Diagnosis
        A recording diagnosis (:func:`prsm_health.diagnostics.diagnosis.diagnose`).
    path : str or Path
    """
    fig = diagnosis_figure(result)
    import matplotlib.pyplot as plt  # after diagnosis_figure chose the Agg backend

    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


#: How a not-observable clearance interval is drawn (grey, hatched: no reading).
_HIDDEN = {"facecolor": "none", "edgecolor": "0.6", "hatch": "///", "lw": 0.0}


def diagnosis_figure(result):
    """The matplotlib figure of :func:`plot_diagnosis`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from prsm_health.diagnostics.not_observable import (
        NOT_OBSERVABLE,
        not_observable_text,
        observable,
    )

    def um(value):
        return np.nan if value is None else 1e6 * value

    wins = result.windows or [result]
    spans = [(w.window["start"], w.window["end"]) if w.window else (0.0, 1.0) for w in wins]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    overall = result.clearance
    t0, t1 = spans[0][0], spans[-1][1]
    if observable(result, "clearance"):
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
    labelled = set()
    for (a, b), w in zip(spans, wins):
        c = w.clearance
        seen = observable(w, "clearance")
        if seen:
            a1.fill_between(
                [a, b],
                um(c["lower"]),
                um(c["upper"]),
                color="tab:blue",
                alpha=0.3,
                label=None if "seen" in labelled else "window: 90 % interval",
            )
            a1.hlines(
                um(c["estimate"]),
                a,
                b,
                colors="tab:blue",
                lw=2,
                label=None if "seen" in labelled else "window: estimate",
            )
            labelled.add("seen")
            continue
        a1.fill_between(
            [a, b],
            um(c["lower"]),
            um(c["upper"]),
            **_HIDDEN,
            label=None if "hidden" in labelled else f"window {NOT_OBSERVABLE}: interval",
        )
        a1.plot(
            [(a + b) / 2],
            [um(c["estimate"])],
            "o",
            mfc="none",
            mec="0.5",
            label=None if "hidden" in labelled else f"window {NOT_OBSERVABLE}: estimate",
        )
        labelled.add("hidden")
    if "seen" not in labelled:
        box = {"facecolor": "white", "edgecolor": "none"}
        a1.text(
            0.5,
            0.5,
            f"clearance {NOT_OBSERVABLE}",
            transform=a1.transAxes,
            ha="center",
            va="center",
            color="0.4",
            bbox=box,
        )
    a1.set_ylabel("clearance [µm]")
    a1.legend(fontsize=8, loc="best")
    told = [(span, w) for span, w in zip(spans, wins) if observable(w, "fault")]
    for i, cls in enumerate(result.class_probabilities):
        for k, ((a, b), w) in enumerate(told):
            probability = w.class_probabilities.get(cls, 0.0)
            a2.hlines(probability, a, b, lw=2, colors=f"C{i}", label=cls if k == 0 else None)
    hidden = [(a, b) for (a, b), w in zip(spans, wins) if not observable(w, "fault")]
    if not result.class_probabilities:  # no fault model: nothing hidden
        hidden = []
    for k, (a, b) in enumerate(hidden):
        label = f"class {NOT_OBSERVABLE} (no probabilities)" if k == 0 else None
        a2.axvspan(a, b, color="0.85", alpha=0.6, lw=0, label=label)
    if hidden and len(hidden) == len(wins):
        a2.text(
            0.5,
            0.5,
            f"class {NOT_OBSERVABLE}",
            transform=a2.transAxes,
            ha="center",
            va="center",
            color="0.4",
        )
    a2.set_ylabel("class probability [-]")
    a2.set_xlabel("recording time [s] (one segment per window)")
    a2.set_ylim(-0.02, 1.02)
    if a2.get_legend_handles_labels()[0]:
        a2.legend(fontsize=8, loc="best")
    a2.set_xlim(t0, t1 if t1 > t0 else t0 + 1.0)
    clearance = not_observable_text(result, "clearance") or (
        f"{um(overall['estimate']):.1f} µm [{um(overall['lower']):.1f}, {um(overall['upper']):.1f}]"
    )
    fig.suptitle(
        f"{result.fault_class}  clearance {clearance}  {len(wins)} window(s)  "
        f"model {result.model['name']}",
        fontsize=10,
    )
    return fig


def plot_evaluation(report: dict, records, directory: str | Path) -> list[Path]:
    """Figures of :func:`prsm_health.training.evaluation.evaluate_model` as PNGs in ``directory``:

    - ``clearance.png``: predicted vs true clearance with the 90 % intervals (grey where the
      diagnosis called the clearance not observable);
    - ``calibration.png``: reliability of the class probabilities (top probability in bins vs
      the share of those runs whose class was right), runs given a class only;
    - ``confusion.png``: the confusion matrix, ``cannot_tell`` as its own column.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    if "clearance" in report:
        fig, ax = plt.subplots(figsize=(6, 6))
        y = 1e6 * records["clearance"].to_numpy(float)
        est = 1e6 * records["estimate"].to_numpy(float)
        lo, hi = 1e6 * records["lower"].to_numpy(float), 1e6 * records["upper"].to_numpy(float)
        seen = records["clearance_observable"].to_numpy(bool)
        for mask, colour, label in ((seen, "tab:blue", "observable"), (~seen, "0.6", "not")):
            if mask.any():
                ax.errorbar(
                    y[mask],
                    est[mask],
                    yerr=[est[mask] - lo[mask], hi[mask] - est[mask]],
                    fmt="o",
                    ms=3,
                    color=colour,
                    ecolor=colour,
                    alpha=0.5,
                    label=f"{label} (90 % interval)",
                )
        top = float(np.nanmax(np.concatenate([y, hi]))) if len(y) else 1.0
        ax.plot([0, top], [0, top], "k--", lw=1, label="ideal")
        c = report["clearance"]
        ax.set_title(
            f"MAE {_um_text(c['mae'])} µm, coverage {_fraction_text(c['coverage'])} (n = {c['n']})"
        )
        ax.set_xlabel("true clearance [µm]")
        ax.set_ylabel("estimated clearance [µm]")
        ax.legend(loc="upper left")
        written.append(_save(fig, out / "clearance.png"))
    if "fault" in report:
        told = records[records["predicted_class"] != "cannot_tell"]
        fig, ax = plt.subplots(figsize=(6, 5))
        edges = np.linspace(0.0, 1.0, 11)
        right = (told["predicted_class"] == told["fault_class"]).to_numpy(float)
        conf = told["top_probability"].to_numpy(float)
        which = np.clip(np.digitize(conf, edges[1:-1]), 0, 9)
        centres = [conf[which == b].mean() for b in range(10) if np.any(which == b)]
        shares = [right[which == b].mean() for b in range(10) if np.any(which == b)]
        ax.plot([0, 1], [0, 1], "k--", lw=1, label="perfectly calibrated")
        ax.plot(centres, shares, "o-", label="model")
        ax.set_xlabel("top class probability")
        ax.set_ylabel("share correct")
        ax.set_title(f"class calibration ({len(told)} runs given a class)")
        ax.legend(loc="upper left")
        written.append(_save(fig, out / "calibration.png"))
        cm = report["fault"]["confusion"]
        matrix = np.asarray(cm["matrix"], float)
        fig, ax = plt.subplots(
            figsize=(1.0 + 0.8 * len(cm["predicted"]), 1.0 + 0.7 * len(cm["true"]))
        )
        ax.imshow(matrix, cmap="Blues")
        for i in range(matrix.shape[0]):
            for j in range(matrix.shape[1]):
                ax.text(j, i, int(matrix[i, j]), ha="center", va="center", fontsize=8)
        ax.set_xticks(range(len(cm["predicted"])), cm["predicted"], rotation=45, ha="right")
        ax.set_yticks(range(len(cm["true"])), cm["true"])
        ax.set_xlabel("predicted")
        ax.set_ylabel("true")
        f = report["fault"]
        ax.set_title(
            f"macro-F1 {f['macro_f1_all']:.2f} (given a class: {_fraction_text(f['macro_f1_named'])})"
        )
        written.append(_save(fig, out / "confusion.png"))
    return written


def _um_text(value) -> str:
    return "–" if value is None else f"{1e6 * value:.2f}"


def _fraction_text(value) -> str:
    return "–" if value is None else f"{value:.2f}"


def _save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_fleet_lives(lives, path: str | Path, *, test_units=(), snapshots: int = 0) -> Path:
    """Wear trajectories of a fleet (:func:`prsm_health.physics.life.fleet_lives`): mean thread
    half-clearance, screw and nut sides, and lubricant degradation over operating hours, with
    the failure threshold and the snapshot ages; saved as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_b, ax_s, ax_d) = plt.subplots(1, 3, figsize=(15, 4.2))
    test_units = set(test_units)
    for unit in lives:
        ages = np.linspace(0.0, unit.failure_age, 200)
        screw, nut = unit.clearances(ages)
        color = "tab:red" if unit.unit_id in test_units else "tab:blue"
        ax_b.plot(ages, unit.clearance(ages) * 1e6, color=color, lw=0.9, alpha=0.8)
        if snapshots:
            at = unit.snapshot_ages(snapshots)
            ax_b.plot(at, unit.clearance(at) * 1e6, ".", color=color, ms=2.5)
        ax_s.plot(ages, screw * 1e6, color="tab:purple", lw=0.7, alpha=0.6)
        ax_s.plot(ages, nut * 1e6, color="tab:green", lw=0.7, alpha=0.6)
        ax_d.plot(ages, unit.degradation(ages), color=color, lw=0.8, alpha=0.7)
        if unit.failure_mode == "spall":  # failed by its spall before the wear limit
            ax_b.plot(unit.failure_age, float(unit.clearance(unit.failure_age)) * 1e6, "kx")
    threshold = lives[0].failure_clearance * 1e6
    ax_b.axhline(threshold, color="k", ls="--", lw=0.8)
    ax_b.set_title(
        f"installed clearance (blue: train, red: test units; failure at {threshold:g} µm)",
        fontsize=9,
    )
    ax_s.set_title("thread half-clearances: screw side (purple), nut side (green)", fontsize=9)
    ax_d.set_title("lubricant degradation (additives used up at 1)", fontsize=9)
    for ax, label in ((ax_b, "µm"), (ax_s, "µm"), (ax_d, "-")):
        ax.set_xlabel("age [operating hours]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return _save(fig, Path(path))


#: How each RUL method's median is drawn: (marker/line, colour, marker size, line width, label).
_RUL_STYLES = {
    "degradation": ("o-", "tab:blue", 2.5, 1, "degradation (90 % interval)"),
    "similarity": ("s--", "tab:orange", 2, 0.8, "similarity"),
    "physics": ("^-.", "tab:green", 2, 0.8, "physics (progpy)"),
}


def plot_prognostics(histories, predictions, model, directory, *, alpha: float = 0.2) -> list[Path]:
    """Figures of a prognostics evaluation (tools/release/train_prognostics_model.py): each held-out
    unit's predicted RUL against its true RUL with the α cone, and its diagnosed health
    indicator against the true clearance; saved as PNG in ``directory``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(directory)
    units = sorted(int(u) for u in predictions["unit_id"].unique())
    cols = min(3, len(units))
    rows = -(-len(units) // cols)
    written = []

    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.4 * rows), squeeze=False)
    for ax, unit in zip(axes.flat, units):
        mine = predictions[predictions["unit_id"] == unit]
        deg = mine[mine["method"] == "degradation"]
        ax.plot(deg["age_hours"], deg["true_rul"], "k-", lw=1, label="true RUL")
        ax.fill_between(
            deg["age_hours"],
            (1 - alpha) * deg["true_rul"],
            (1 + alpha) * deg["true_rul"],
            color="0.85",
            label=f"±{alpha:g}·true (α cone)",
        )
        ax.fill_between(
            deg["age_hours"], deg["lower"], deg["upper"], color="tab:blue", alpha=0.25, lw=0
        )
        for method, (style, color, ms, lw, label) in _RUL_STYLES.items():
            part = mine[mine["method"] == method]
            if not part.empty:  # physics: models fitted on a fleet dataset only
                ax.plot(
                    part["age_hours"], part["estimate"], style, color=color, ms=ms, lw=lw,
                    label=label,
                )  # fmt: skip
        life = float(deg["age_hours"].max() + deg["true_rul"].min())
        ax.axvline(0.5 * life, color="0.5", ls=":", lw=0.8)
        ax.set_title(f"unit {unit} (life {life:.0f} h)", fontsize=9)
        ax.set_xlabel("age [h]")
        ax.set_ylabel("RUL [h]")
        ax.set_ylim(0, 1.6 * float(deg["true_rul"].max()))
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=6.5, loc="upper right")
    for ax in list(axes.flat)[len(units) :]:
        ax.axis("off")
    written.append(_save(fig, out / "prognostics_rul.png"))

    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.2 * rows), squeeze=False)
    for ax, unit in zip(axes.flat, units):
        h = histories[histories["unit_id"] == unit]
        ax.errorbar(
            h["age_hours"],
            h["clearance"] * 1e6,
            yerr=[
                (h["clearance"] - h["clearance_lower"]) * 1e6,
                (h["clearance_upper"] - h["clearance"]) * 1e6,
            ],
            fmt=".",
            ms=3,
            lw=0.6,
            color="tab:blue",
            label="diagnosed (90 % interval)",
        )
        ax.plot(h["age_hours"], h["clearance_mean_true"] * 1e6, "k-", lw=1, label="true (mean)")
        ax.axhline(
            model.threshold * 1e6,
            color="tab:red",
            ls="--",
            lw=0.8,
            label="model threshold (diagnosed)",
        )
        ax.set_title(f"unit {unit}", fontsize=9)
        ax.set_xlabel("age [h]")
        ax.set_ylabel("clearance [µm]")
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=6.5, loc="upper left")
    for ax in list(axes.flat)[len(units) :]:
        ax.axis("off")
    written.append(_save(fig, out / "prognostics_indicator.png"))
    return written
