"""A health check at a glance: one matplotlib panel per role a check is read for — the phase it
was read in, what it shows there and its verdict — saved as PNG (``prsm-health diagnose
CHECK --plot``).

The numbers in the titles and notes are the diagnosis's (:func:`check_verdicts
<prsm_health.diagnostics.check_verdicts.check_verdicts>`); the curves are the phase's samples
and the library's views of them (Welch PSD, the lost-motion lag, the synchronous averages of
:mod:`prsm_health.signals.check_averages`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.diagnostics.check_verdicts import CLEARANCE_ROLE, check_verdicts
from prsm_health.diagnostics.not_observable import not_observable_text
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.signals.check_averages import high_load_averages
from prsm_health.signals.check_indicators import CENTROID_BAND, CENTROID_SEGMENT, SNR_PERIODS
from prsm_health.signals.features import run_design
from prsm_health.signals.spectra import welch_psd

#: What each role's panel is called.
ROLE_TITLES = {
    "no_load": "no-load stroke",
    "torque_pair": "torque at two speeds",
    "reversal": "slow reversal (lost motion)",
    "high_load": "high-load stroke",
}
#: Readings shown in each panel's note (the rest are in the JSON).
SHOWN_READINGS = {
    "no_load": ("check_noload_centroid", "check_noload_rms"),
    "torque_pair": ("check_torque_low", "check_torque_high", "check_torque_ratio"),
    "reversal": ("check_reversal_lost_motion", "check_reversal_lost_motion_step"),
    "high_load": ("check_highload_kurtosis", "check_highload_rms"),
}
#: Readings shown in µm rather than m.
_MICRO = {"m": (1e6, "µm")}


def panel_title(verdict: dict, diagnosis: dict | None = None) -> str:
    """``<role>: phase '<name>' — read`` (or ``not read`` and why), and on a second line the
    targets the phase shows: the clearance interval (the reversal) and its classes'
    probabilities — "not observable" instead where ``diagnosis`` (its JSON) says the model
    could not see them (:mod:`prsm_health.diagnostics.not_observable`)."""
    head = ROLE_TITLES[verdict["role"]]
    if verdict["phase"] is None:
        return f"{head}: not read — the check has no {verdict['condition']}"
    state = "read" if verdict["read"] else "not read (see the warnings)"
    lines = [f"{head}: phase '{verdict['phase']}' — {state}"]
    targets = []
    c = verdict["clearance"]
    diagnosis = diagnosis or {}
    hidden = not_observable_text(diagnosis, "clearance")
    if verdict["role"] == CLEARANCE_ROLE and hidden:
        targets.append(f"clearance {hidden}")
    elif c is not None and c.get("estimate") is not None:
        targets.append(
            f"clearance {1e6 * c['estimate']:.1f} µm [{1e6 * c['lower']:.1f}, "
            f"{1e6 * c['upper']:.1f}]"
        )
    hidden = not_observable_text(diagnosis, "fault")
    if hidden and verdict["classes"]:
        targets.append(f"{', '.join(verdict['classes'])}: {hidden}")
    else:
        targets += [f"P({k}) {p:.2f}" for k, p in verdict["classes"].items()]
    if targets:
        lines.append(", ".join(targets))
    return "\n".join(lines)


def reading_text(reading: dict) -> str:
    """``name = value unit`` (and ``z = …`` against the baseline), or ``not read``."""
    name = reading["name"].removeprefix("check_")
    if reading["value"] is None:
        return f"{name}: not read"
    factor, unit = _MICRO.get(reading["unit"], (1.0, reading["unit"]))
    text = f"{name} = {factor * reading['value']:.4g} {unit if unit != '-' else ''}".rstrip()
    if reading["z"] is not None:
        text += f" (z {reading['z']:+.1f})"
    return text


def plot_check_result(
    run: Run, diagnosis, path: str | Path, *, design=None, reference: Run | None = None
) -> Path:
    """:func:`check_figure` saved as PNG at ``path``."""
    import matplotlib.pyplot as plt

    fig = check_figure(run, diagnosis, design=design, reference=reference)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def check_figure(run: Run, diagnosis, *, design=None, reference: Run | None = None):
    """The check phase by phase with each phase's reading and verdict: a matplotlib figure,
    one panel per role (:data:`ROLE_TITLES`), each titled by :func:`panel_title`.

    Parameters
    ----------
    run : Run
        The check recording (its phases: ``run.check``, ``check_phase``).
    diagnosis : Diagnosis
        Its diagnosis (``check_phases`` set), against the unit's baseline or alone.
    design : PRSMDesign or None
        The design read (the model bundle's); None: the run's own.
    reference : Run or None
        A check recording of the same unit to draw the high-load averages against (a baseline
        recording); None: the averages alone (the baseline's z-scores are in the notes when
        the diagnosis has them).

    Raises
    ------
    PRSMHealthError
        A diagnosis that is no check's.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    result = diagnosis.to_json()
    verdicts = check_verdicts(result)
    if verdicts is None:
        raise PRSMHealthError("the diagnosis is no health check's (no check phases)")
    design = run_design(run) if design is None else design
    phases = run.phases()
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    for ax, verdict in zip(axes.flat, verdicts):
        role = verdict["role"]
        ax.set_title(panel_title(verdict, result), fontsize=9, loc="left")
        names = (verdict["phase"] or "").split(" / ")
        if verdict["phase"] is None or any(n not in phases for n in names):
            ax.text(0.5, 0.5, "not read", ha="center", va="center", transform=ax.transAxes)
            ax.set_axis_off()
            continue
        if role == "no_load":
            _no_load(ax, phases[names[0]], result["indicators"])
        elif role == "torque_pair":
            _torque_pair(ax, phases[names[0]], phases[names[1]], result["indicators"])
        elif role == "reversal":
            _reversal(ax, phases, names[0], design, result.get("measured_clearance"))
        else:
            reference_phase = None if reference is None else reference.phases().get(names[0])
            _high_load(ax, phases[names[0]], design, run, result["indicators"], reference_phase)
        shown = [r for r in verdict["readings"] if r["name"] in SHOWN_READINGS[role]]
        ax.text(
            0.99,
            0.02,
            "\n".join(reading_text(r) for r in shown),
            transform=ax.transAxes,
            ha="right",
            va="bottom",
            fontsize=7.5,
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "0.7"},
        )
        ax.grid(alpha=0.3)
    fig.suptitle(_suptitle(run, result), fontsize=10)
    fig.tight_layout()
    return fig


def _suptitle(run: Run, result: dict) -> str:
    p = result["class_probabilities"].get(result["fault_class"])
    named = f"{result['fault_class']}" + (f" ({p:.2f})" if p is not None else "")
    against = "alone"
    baseline = (result.get("asset") or {}).get("baseline")
    if baseline and baseline.get("distance") is not None:
        against = f"against its baseline (distance {baseline['distance']:.2f})"
    elif baseline:
        against = f"baseline {baseline['recordings']} of {baseline['needed']} (not yet scored)"
    name = run.check.name if run.check is not None else ""
    return (
        f"health check '{name}' — {named}, read {against}; model {result['model']['name']} "
        f"{result['model']['version']}"
    )


def _no_load(ax, phase: Run, indicators: dict) -> None:
    x = np.asarray(phase.channels["nut_axial_accel"], float)
    if len(x) >= CENTROID_SEGMENT:
        f, p = welch_psd(
            x - x.mean(), phase.sample_rate, CENTROID_SEGMENT, 3 * CENTROID_SEGMENT // 4
        )
        inside = (f >= CENTROID_BAND[0]) & (f <= CENTROID_BAND[1])
        ax.semilogy(f[inside], p[inside], lw=0.8, color="k")
    centroid = indicators.get("check_noload_centroid")
    if centroid is not None:
        ax.axvline(centroid, color="tab:red", ls="--", lw=1, label="spectral centroid")
        ax.legend(fontsize=7, loc="upper right")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("nut axial acceleration PSD [(m/s²)²/Hz]", fontsize=8)


def _torque_pair(ax, slow: Run, fast: Run, indicators: dict) -> None:
    pairs = ((slow, "check_torque_low", "tab:blue"), (fast, "check_torque_high", "tab:orange"))
    for part, key, colour in pairs:
        torque = np.asarray(part.channels["drive_torque"], float)
        t = part.time - part.time[0]
        ax.plot(t, torque, lw=0.5, color=colour, alpha=0.7)
        level = indicators.get(key)
        if level is not None:
            sign = 1.0 if np.mean(torque) >= 0 else -1.0
            ax.axhline(sign * level, color=colour, ls="--", lw=1.2, label=f"{key[6:]}: mean |τ|")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_xlabel("time from the phase start [s]")
    ax.set_ylabel("drive torque [N·m]")


def _reversal(ax, phases: dict, name: str, design, measured: dict | None) -> None:
    # the nut's lag behind the screw's kinematic travel: its two branches (one per flank side)
    # stand apart by the lost motion; each reversal the clearance was measured from, its loop
    read = [(r["phase"], r["load"]) for r in (measured or {}).get("reversals", [])]
    for (phase_name, load), colour in zip(read or [(name, None)], ("k", "tab:orange", "tab:blue")):
        phase = phases[phase_name]
        travel = speed_ratios(design).nut * np.asarray(phase.channels["screw_angle"], float)
        lag = np.asarray(phase.channels["nut_position"], float) - travel
        lag -= np.median(lag)
        label = phase_name if load is None else f"{phase_name} (±{load:.0f} N)"
        ax.plot(1e3 * (travel - travel[0]), 1e6 * lag, lw=0.6, color=colour, label=label)
    if measured is not None:
        how = "commissioned" if measured["commissioned"] else "not commissioned"
        learnt = measured.get("learnt") or {}
        text = f"clearance measured by lost motion ({how})"
        if learnt.get("estimate") is not None:
            agree = "agrees" if measured["agree"] else "DISAGREES"
            text += f"; learnt {1e6 * learnt['estimate']:.1f} µm ({agree})"
        ax.legend(fontsize=7, loc="upper left", title=text, title_fontsize=7)
    ax.set_xlabel("screw angle × lead (kinematic nut travel) [mm]")
    ax.set_ylabel("nut position − screw angle × lead [µm]", fontsize=8)


def _high_load(ax, phase: Run, design, run: Run, indicators: dict, reference: Run | None) -> None:
    ratio = run.operating.gear_ratio
    ratio = float(ratio) if isinstance(ratio, (int, float)) and ratio > 0 else 1.0
    try:
        averages = high_load_averages(phase, design, ratio)
    except PRSMHealthError as exc:
        ax.text(0.5, 0.5, f"no angle domain: {exc}", ha="center", va="center", fontsize=8,
                transform=ax.transAxes, wrap=True)  # fmt: skip
        return
    ref = None
    if reference is not None:
        try:
            ref = high_load_averages(reference, design, ratio)
        except PRSMHealthError:  # its phase has no angle domain: the averages alone
            ref = None
    finite = [a.average for a in averages.values() if a.n_periods >= 2]
    step = 5.0 * max((float(np.std(a)) for a in finite), default=1.0) or 1.0
    for k, name in enumerate(SNR_PERIODS):
        offset = -k * step
        average = averages[name]
        snr = indicators.get(f"check_highload_snr_{name}")
        label = f"{name}: SNR {snr:.3f}" if snr is not None else f"{name}: not read"
        if average.n_periods >= 2:  # one period has no SNR: nothing repeats yet
            grid = np.linspace(0.0, 1.0, average.average.shape[-1], endpoint=False)
            if ref is not None and ref[name].n_periods >= 2:
                r = ref[name].average
                ax.plot(np.linspace(0.0, 1.0, len(r), endpoint=False), offset + r, color="0.6",
                        lw=1.2, label="reference (baseline)" if k == 0 else None)  # fmt: skip
            ax.plot(grid, offset + average.average, lw=0.8, color=f"C{k}")
        label += f" ({average.n_periods} period(s))"
        ax.text(0.01, offset + 0.4 * step, label, fontsize=7, va="center", color=f"C{k}",
                transform=ax.get_yaxis_transform(),
                bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none"})  # fmt: skip
    if ref is not None:
        ax.legend(fontsize=7, loc="lower left")
    ax.set_yticks([])
    ax.set_xlabel("angle in the period [share of the period]")
    ax.set_ylabel("synchronous average, impact band (offset per period)", fontsize=8)
