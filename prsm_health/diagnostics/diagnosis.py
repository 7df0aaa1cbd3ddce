"""Diagnosis: recording → windows → indicators → estimators → :class:`Diagnosis`.

A **model bundle** (saved by :func:`prsm_health.diagnostics.training.train`) holds the clearance estimator,
the fault classifier, the indicator names they were trained on, the window length of the
training runs, the design and the measured channels of the training runs. :func:`diagnose`
cuts a recording into windows of that length, computes the indicators
(:mod:`prsm_health.signals.features`) of each, and returns a :class:`Diagnosis` for the whole recording
with one per window; :func:`replay` does the same window by window while an MCAP recording
streams. The diagnosis reads the measured channels only, never a
recording's truth signals.

Missing channels: the indicator set is fixed (:data:`prsm_health.signals.features.FEATURES`) and an
indicator whose channel a window lacks is NaN. A model was trained on the runs' channels: a
recording that lacks one of them is refused (:class:`RecordingError` naming the channels),
because the model never learnt to do without it; a channel the model was trained without is
harmless (its indicators were NaN in training, the model never uses them). Bundles saved before
the channel list was recorded are not checked.

``Diagnosis.to_json()`` is the Diagnosis contract (docs/formats.md)::

    {"clearance": {"estimate": m, "lower": m, "upper": m}, "fault_class": str,
     "class_probabilities": {class: p}, "indicators": {name: value},
     "model": {name, version, design}, "warnings": [str], "window"|"windows": …}
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.design_files import load_design
from prsm_health.core.channels import MEASURED_TOPICS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import finite_or_none
from prsm_health.core.run import MIN_SAMPLES, Run
from prsm_health.signals.features import (
    FEATURES,
    NO_DESIGN,
    extract_features_batch,
    indicator_groups,
    windows,
)

#: Where the shipped default model lives (repository layout: models/ next to the package).
DEFAULT_MODEL = Path(__file__).resolve().parents[2] / "models" / "default.skops"
#: A recording's tail shorter than a window is diagnosed as its own window when it holds at
#: least this fraction of a window (indicators over less are biased: fewer reversals, wider
#: spectral bins), and reported as dropped otherwise.
MIN_TAIL_FRACTION = 0.5
#: The class of a window whose class the model cannot see (clearance hidden, channels missing,
#: indicators unlike the training set).
CANNOT_TELL = "cannot_tell"
#: Out-of-distribution score above which a window is unlike the training set. The score is 1 at
#: the 99th percentile of the training windows' own scores; 1.5 leaves room for the held-out
#: windows of the same recipe (models/MODEL_CARD.md: the share of them above it).
OOD_LIMIT = 1.5
#: A class is named when its calibrated probability reaches this: more probable than all the
#: others together, so the named class is right more often than not (calibration figure of the
#: model card); below it the answer is ``cannot_tell`` with the candidates in a warning.
NAME_PROBABILITY = 0.5
#: How the class-set part of a fault-class warning begins.
_SET_NOTE = "not ruled out at "
#: Words for the operating indicators in warnings.
REGIME_WORDS = {
    "speed_mean": "speed",
    "load_mean": "mean load",
    "load_range": "load swing",
    "drive_torque_mean": "mean drive torque (load)",
}


@dataclass
class ModelBundle:
    """A loaded diagnosis model; ``design`` is resolved once, at load."""

    clearance: object | None
    fault: object | None
    feature_names: list[str]
    metadata: dict
    guard: object | None = None
    design: PRSMDesign | None = field(init=False)

    def __post_init__(self):
        # None: a model trained on an imported rig that is not a PRSM (no design)
        design = self.metadata.get("design", "paper01")
        self.design = None if design is None else load_design(design)

    @property
    def design_name(self) -> str:
        return self.design.name if self.design is not None else NO_DESIGN

    def indicators(self, run: Run) -> dict:
        """The indicators of one window, as this model was trained to read them."""
        return self.indicators_batch([run])[0]

    def indicators_batch(self, runs: list[Run]) -> list[dict]:
        """:meth:`indicators` of several windows, computed together (equal to one by one)."""
        design = self.design or NO_DESIGN
        return extract_features_batch(runs, design, lead=self.metadata.get("lead"))

    @property
    def name(self) -> str:
        return self.metadata.get("name", "unnamed")

    @property
    def version(self) -> str:
        return str(
            self.metadata.get("model_version", self.metadata.get("prsm_health_version", "?"))
        )

    @property
    def window(self) -> float:
        """Window length the model was trained on [s]."""
        return float(self.metadata.get("window", 0.4))

    @property
    def channels(self) -> tuple[str, ...] | None:
        """Measured channels of the training runs; None for a bundle that predates the record."""
        channels = self.metadata.get("channels")
        return None if channels is None else tuple(channels)

    def reference(self) -> dict:
        """The ``model`` entry of a diagnosis."""
        return {"name": self.name, "version": self.version, "design": self.design_name}

    def missing_channels(self, channels) -> list[str]:
        """The channels the model was trained with that a recording lacks."""
        return [c for c in self.channels or () if c not in channels]

    @property
    def regime(self) -> dict[str, list[float]]:
        """Indicator → [min, max] of the operating indicators over the training windows."""
        return dict(self.metadata.get("regime", {}))


def load_bundle(
    path: str | Path | None = None, *, allow_version_mismatch: bool = False
) -> ModelBundle:
    """Load a model bundle (default: the shipped model); version checks in persistence.load_model."""
    from .model_files import load_model

    path = Path(path) if path is not None else DEFAULT_MODEL
    if not path.exists():
        hint = " (run tools/release/train_default_model.py)" if path == DEFAULT_MODEL else ""
        raise PRSMHealthError(f"{path}: no such model file{hint}")
    model, metadata = load_model(path, allow_version_mismatch=allow_version_mismatch)
    if not isinstance(model, dict) or "feature_names" not in model:
        raise PRSMHealthError(f"{path}: not a prsm_health diagnosis bundle")
    return ModelBundle(
        model.get("clearance"),
        model.get("fault"),
        list(model["feature_names"]),
        metadata,
        model.get("guard"),
    )


@dataclass
class Diagnosis:
    """One diagnosis, of a window or of a whole recording (then with ``windows``).

    Attributes
    ----------
    clearance : dict
        ``estimate``, ``lower``, ``upper`` [m] (90 % interval); None where not computable.
    fault_class : str or None
        The most probable class, when the window shows the fault (``observability``) and its
        probability reaches :data:`NAME_PROBABILITY`; else ``cannot_tell``.
    class_probabilities : dict of class → probability
    class_set : list of str
        The classes the evidence cannot rule out (the model's conformal class set, 90 % by
        default: :meth:`prsm_health.diagnostics.estimators.FaultClassifier.predict_set`); every class where
        the fault is not observable.
    indicators : dict of name → value (None where not computable)
    model : dict
        ``name``, ``version``, ``design`` of the model bundle.
    window : dict or None
        ``index``, ``start``, ``end`` [s] of a window diagnosis.
    windows : list of Diagnosis
        Per-window diagnoses of a recording diagnosis.
    warnings : list of str
        Sentences a person can act on: why a target is not observable, a missing channel, a
        recording outside the trained range, a dropped tail.
    observability : dict
        ``clearance`` and ``fault``: whether the window lets the model see them (bool), or the
        fraction of windows that did for a recording.
    ood_score : float or None
        Out-of-distribution score of the indicators (:class:`DistributionGuard`: 1 = the
        training windows' 99th percentile; above :data:`OOD_LIMIT` the window is unlike the
        training set); a recording's is the median of its windows'.
    indicator_groups : dict
        Indicator group → ``"computed"`` or why not (missing channels, window).
    """

    clearance: dict
    fault_class: str | None
    class_probabilities: dict
    indicators: dict
    model: dict
    window: dict | None = None
    windows: list[Diagnosis] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    observability: dict = field(default_factory=dict)
    ood_score: float | None = None
    indicator_groups: dict = field(default_factory=dict)
    class_set: list[str] = field(default_factory=list)

    def to_json(self) -> dict:
        """The Diagnosis contract as plain JSON values."""
        out = {
            "clearance": dict(self.clearance),
            "fault_class": self.fault_class,
            "class_probabilities": dict(self.class_probabilities),
            "class_set": list(self.class_set),
            "observability": dict(self.observability),
            "ood_score": self.ood_score,
            "indicators": dict(self.indicators),
            "indicator_groups": dict(self.indicator_groups),
            "model": dict(self.model),
            "warnings": list(self.warnings),
        }
        if self.window is not None:
            out["window"] = dict(self.window)
        if self.windows:
            out["windows"] = [w.to_json() for w in self.windows]
        return out


def _matrix(rows: list[dict], names: list[str]):
    import pandas as pd

    values = np.array([[r.get(n, np.nan) for n in names] for r in rows], dtype=float)
    columns = _columns(tuple(names))
    return pd.DataFrame(values.reshape(len(rows), len(names)), columns=columns, copy=False)


@lru_cache(maxsize=8)
def _columns(names: tuple[str, ...]):
    import pandas as pd

    # an object index, made once: pandas' default (Arrow strings) costs ≈ 0.3 ms per frame
    # to build, and each estimator's column check iterates it again
    return pd.Index(names, dtype=object)


@lru_cache(maxsize=1)
def _threadpools():
    # made once: each threadpool_limits() call rescans the process's libraries (≈ 5 ms)
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def diagnose_indicators(
    rows: list[dict], bundle: ModelBundle, channels: list | None = None, design: str | None = None
) -> list[Diagnosis]:
    """One :class:`Diagnosis` per row of indicators (one row per window).

    ``channels``: the measured channels of each row's window (default: the model's, i.e. none
    missing); ``design``: the recording's design label, if it has one.
    """
    x = _matrix(rows, bundle.feature_names)
    channels = channels or [bundle.channels or ()] * len(rows)
    # A few rows per call: OpenMP threads in the boosted trees only add spin-wait latency, and
    # under load (the service, parallel replays) oversubscribe the cores.
    with _threadpools().limit(limits=1, user_api="openmp"):
        return _predict(rows, x, bundle, channels, design)


def _window_gates(row: dict, channels, bundle: ModelBundle, ood: float, design) -> tuple:
    """(clearance observable, fault observable, warnings) of one window."""
    notes = []
    missing = bundle.missing_channels(channels)
    if missing:
        notes.append(
            f"channel(s) {', '.join(missing)} missing: model {bundle.name!r} was trained with "
            f"them ({', '.join(bundle.channels)}); their indicators are NaN"
        )
    reversal = row.get("reversal")
    reverses = reversal is not None and np.isfinite(reversal) and reversal > 0
    gate = bundle.metadata.get("observability_feature")
    gate_ok = gate not in bundle.feature_names or np.isfinite(row.get(gate, np.nan))
    clearance_ok = bool(reverses and gate_ok and not missing)
    if bundle.clearance is not None and not clearance_ok:
        if not reverses:
            notes.append(
                "no load or motion reversal in this window: clearance is not observable (the "
                "rollers stay on one flank); the interval is the whole trained range"
            )
        elif missing:
            notes.append("clearance is not observable without the missing channel(s)")
        else:
            notes.append(f"indicator {gate} not computable: clearance is not observable")
    for name, (lo, hi) in bundle.regime.items():
        value = row.get(name)
        if value is not None and np.isfinite(value):
            slack = 0.05 * max(hi - lo, abs(hi), abs(lo))  # the range of a few hundred windows
            if not lo - slack <= value <= hi + slack:
                notes.append(
                    f"recording outside the trained {REGIME_WORDS.get(name, name)} range: "
                    f"{value:.4g} vs {lo:.4g} … {hi:.4g} {FEATURES[name]}"
                )
    if design is not None and design != bundle.design_name:
        notes.append(
            f"recording of design {design!r}, model trained on {bundle.design_name!r}: its "
            "indicators mean something else"
        )
    ood_high = np.isfinite(ood) and ood > OOD_LIMIT
    if ood_high:
        notes.append(
            f"indicators unlike the training windows (out-of-distribution score {ood:.2g} > "
            f"{OOD_LIMIT:g}): another design, instrumentation or operating regime? No class, "
            "and the clearance interval is the whole trained range"
        )
    fault_ok = bool(clearance_ok and not ood_high and not missing)
    if bundle.fault is not None and not fault_ok:
        notes.append(
            "fault class: cannot tell — wear classes differ by clearance, which this window "
            "does not show"
            if not clearance_ok
            else "fault class: cannot tell"
        )
    return clearance_ok, fault_ok, notes


def _predict(rows, x, bundle: ModelBundle, channels, design) -> list[Diagnosis]:
    n = len(rows)
    estimate = lower = upper = np.full(n, np.nan)
    guard = bundle.guard
    ood = np.asarray(guard.score(x), float) if guard is not None else np.full(n, np.nan)
    gates = [_window_gates(r, c, bundle, o, design) for r, c, o in zip(rows, channels, ood)]
    if bundle.clearance is not None:
        estimate = np.asarray(bundle.clearance.predict(x), float)
        lower, upper = (np.asarray(a, float) for a in bundle.clearance.predict_interval(x))
        # Where the clearance is not observable (no reversal: steady load keeps each roller on
        # one flank, docs/validation.md) or the window is unlike the training set, the interval
        # is the whole range the model was trained on, whatever the regression says.
        span = bundle.metadata.get("clearance_range")
        if span:
            hidden = np.array([not g[0] or o > OOD_LIMIT for g, o in zip(gates, ood)])
            lower = np.where(hidden, span[0], lower)
            upper = np.where(hidden, span[1], upper)
    classes, proba = [], np.zeros((n, 0))
    if bundle.fault is not None:
        classes = [str(c) for c in bundle.fault.classes_]
        proba = np.asarray(bundle.fault.predict_proba(x), float)
    out = []
    for i, row in enumerate(rows):
        clearance_ok, fault_ok, notes = gates[i]
        probabilities = {c: float(p) for c, p in zip(classes, proba[i])}
        fault_class, class_set = _fault_answer(probabilities, fault_ok, bundle, notes)
        out.append(
            Diagnosis(
                clearance={
                    "estimate": finite_or_none(estimate[i]),
                    "lower": finite_or_none(lower[i]),
                    "upper": finite_or_none(upper[i]),
                },
                fault_class=fault_class,
                class_probabilities=probabilities,
                class_set=class_set,
                indicators={k: finite_or_none(v) for k, v in row.items()},
                model=bundle.reference(),
                warnings=notes,
                observability={"clearance": clearance_ok, "fault": fault_ok},
                ood_score=finite_or_none(ood[i]),
                indicator_groups=indicator_groups(row, channels[i]),
            )
        )
    return out


def _fault_answer(probabilities: dict, observable: bool, bundle: ModelBundle, notes: list):
    """(fault class, class set) of class probabilities, and a warning when the set holds more
    than the named class or no class is named.

    The class is named when the fault is observable and its probability reaches
    :data:`NAME_PROBABILITY`; otherwise ``cannot_tell``. The class set (the model's conformal
    set) lists what the evidence cannot rule out: where the instrumentation cannot tell
    classes apart, their held-out probabilities overlap and the set holds them all."""
    from .estimators import class_sets  # scikit-learn only when a model is used

    if not probabilities:
        return None, []
    names = list(probabilities)
    if not observable:
        return CANNOT_TELL, names
    best = max(probabilities, key=probabilities.get)
    thresholds = getattr(bundle.fault, "set_thresholds_", None)
    members = [best]  # a bundle saved before class sets: its most probable class
    if thresholds is not None:
        chosen = class_sets([list(probabilities.values())], thresholds)[0]
        members = sorted(
            (c for c, keep in zip(names, chosen) if keep), key=probabilities.get, reverse=True
        )
    named = probabilities[best] >= NAME_PROBABILITY
    if named and members == [best]:
        return best, members
    others = [c for c in members if c != best] if named else members
    ruled_out = [c for c in names if c not in members]
    head = (
        f"fault class {best} (P = {probabilities[best]:.2f})"
        if named
        else f"fault class: cannot tell — no class reaches P = {NAME_PROBABILITY:g} (most "
        f"probable {best}, {probabilities[best]:.2f})"
    )
    notes.append(
        f"{head}; {_SET_NOTE}{100 * _set_coverage(bundle):.0f} %: {', '.join(others)}"
        + (f"; ruled out: {', '.join(ruled_out)}" if ruled_out else "")
    )
    return (best if named else CANNOT_TELL), members


def _set_coverage(bundle: ModelBundle) -> float:
    return float(getattr(bundle.fault, "set_coverage", 0.9))


def aggregate(diagnoses: list[Diagnosis], bundle: ModelBundle) -> Diagnosis:
    """One diagnosis for a recording: medians of the estimates and bounds of the windows where
    the clearance is observable (else of all), mean class probabilities of the windows where
    the class is (else ``cannot_tell``), median indicators and OOD score, each warning once
    (with the number of windows it concerns); the windows attached."""

    def median(values):
        values = [v for v in values if v is not None]
        return float(np.median(values)) if values else None

    seen = [d for d in diagnoses if d.observability.get("clearance")] or diagnoses
    told = [d for d in diagnoses if d.observability.get("fault")]
    probs: dict[str, float] = {}
    for d in told or diagnoses:
        for c, p in d.class_probabilities.items():
            probs[c] = probs.get(c, 0.0) + p / len(told or diagnoses)
    counts: dict[str, int] = {}
    for d in diagnoses:
        for note in d.warnings:
            if _SET_NOTE not in note:  # restated below for the mean probabilities
                counts[note] = counts.get(note, 0) + 1
    notes = [
        note if k == len(diagnoses) else f"{note} (in {k} of {len(diagnoses)} windows)"
        for note, k in counts.items()
    ]
    fault_class, class_set = _fault_answer(probs, bool(told), bundle, notes)
    names = diagnoses[0].indicators.keys()
    groups = {
        g: next(
            (d.indicator_groups[g] for d in diagnoses if d.indicator_groups.get(g) == "computed"), r
        )
        for g, r in diagnoses[0].indicator_groups.items()
    }
    return Diagnosis(
        clearance={
            k: median([d.clearance[k] for d in seen]) for k in ("estimate", "lower", "upper")
        },
        fault_class=fault_class,
        class_probabilities=probs,
        class_set=class_set,
        indicators={n: median([d.indicators[n] for d in diagnoses]) for n in names},
        model=bundle.reference(),
        windows=list(diagnoses),
        warnings=notes,
        observability={
            k: float(np.mean([bool(d.observability.get(k)) for d in diagnoses]))
            for k in ("clearance", "fault")
        },
        ood_score=median([d.ood_score for d in diagnoses]),
        indicator_groups=groups,
    )


def diagnose_window(run: Run, bundle: ModelBundle) -> Diagnosis:
    """Diagnosis of one window (a :class:`Run` of about the model's window length)."""
    row = bundle.indicators(run)
    return diagnose_indicators([row], bundle, [tuple(run.channels)], run.labels.get("design"))[0]


def split_windows(run: Run, length: float) -> tuple[list[Run], list[str]]:
    """Windows of ``length`` seconds covering the recording, and warnings about what is not.

    A recording shorter than one window (but ≥ the indicators' minimum) is one window; a tail
    of at least :data:`MIN_TAIL_FRACTION` of a window is a last, shorter window; a shorter tail
    is dropped with a warning.
    """
    n = int(round(length * run.sample_rate))
    if len(run) < n:
        return [run], [
            f"recording ({run.duration:.3g} s) is shorter than the model's window ({length:g} s): "
            "diagnosed as one short window"
        ]
    parts = list(windows(run, length))
    tail = len(run) - n * len(parts)
    notes = []
    if tail >= max(MIN_SAMPLES, MIN_TAIL_FRACTION * n):
        parts.append(run.slice(len(run) - tail, len(run)))
        notes.append(f"last window is {tail / run.sample_rate:.3g} s, shorter than {length:g} s")
    elif tail > 0:
        notes.append(
            f"last {tail / run.sample_rate:.3g} s not diagnosed: shorter than half a window "
            f"({length:g} s)"
        )
    return parts, notes


def diagnose(
    run: Run, bundle: ModelBundle | None = None, *, window: float | None = None
) -> Diagnosis:
    """Diagnose a recording: a :class:`Diagnosis` of the whole, with one per window.

    Parameters
    ----------
    run : Run
    bundle : ModelBundle, default the shipped model
    window : float or None [s]
        Window length; default the model's training window (see :func:`split_windows`).
    """
    return diagnose_runs([run], bundle, window=window)[0]


def diagnose_runs(
    runs: list[Run], bundle: ModelBundle | None = None, *, window: float | None = None
) -> list[Diagnosis]:
    """Diagnose several recordings in one batch (every window's indicators in one call):
    one :class:`Diagnosis` per run, each as :func:`diagnose` gives it."""
    bundle = bundle or load_bundle()
    runs = [run.without_truth().validate() for run in runs]
    split = [split_windows(run, window or bundle.window) for run in runs]
    rows = bundle.indicators_batch([part for parts, _ in split for part in parts])
    channels = [tuple(run.channels) for run, (parts, _) in zip(runs, split) for _ in parts]
    designs = [run.labels.get("design") for run, (parts, _) in zip(runs, split) for _ in parts]
    per_window = []
    for design in dict.fromkeys(designs):  # one call per design (usually one)
        at = [i for i, d in enumerate(designs) if d == design]
        found = diagnose_indicators(
            [rows[i] for i in at], bundle, [channels[i] for i in at], design
        )
        per_window.extend(zip(at, found))
    per_window = [d for _, d in sorted(per_window, key=lambda pair: pair[0])]
    results, start = [], 0
    for parts, notes in split:
        mine = per_window[start : start + len(parts)]
        start += len(parts)
        for k, (part, d) in enumerate(zip(parts, mine)):
            d.window = {"index": k, "start": float(part.time[0]), "end": float(part.time[-1])}
        result = aggregate(mine, bundle)
        result.warnings.extend(notes)
        results.append(result)
    return results


@dataclass
class ReplayStep:
    """One window of a replay: its span and its diagnosis (or plain statistics without a model)."""

    index: int
    start: float
    end: float
    diagnosis: Diagnosis | None = None
    statistics: dict | None = None

    def to_json(self) -> dict:
        out = {"index": self.index, "start": self.start, "end": self.end}
        if self.diagnosis is not None:
            out["diagnosis"] = self.diagnosis.to_json()
        if self.statistics is not None:
            out["statistics"] = self.statistics
        return out


def replay(
    path: str | Path,
    bundle: ModelBundle | None,
    *,
    window: float | None = None,
    rate: float | None = None,
    out: str | Path | None = None,
) -> Iterator[ReplayStep]:
    """Stream an MCAP recording window by window through the diagnosis.

    Parameters
    ----------
    path : MCAP recording
    bundle : ModelBundle or None
        None: window statistics only (no model).
    window : float or None [s]
        Default: the model's window, 1 s without a model.
    rate : float or None
        Real-time factor of the replay; None as fast as possible.
    out : path or None
        Write a copy of the recording with a ``/prsm/diagnosis`` message per window (needs a
        model); written atomically when the replay completes, discarded if it fails.
    """
    from prsm_health.io.mcap import DiagnosisWriter, iter_windows, window_statistics

    length = window or (bundle.window if bundle else 1.0)
    writer = DiagnosisWriter(path, out) if (out and bundle) else None
    stream = iter_windows(path, length, rate=rate, topics=MEASURED_TOPICS)
    try:
        for w in stream:
            step = ReplayStep(w.index, w.start, w.end)
            if bundle is not None:
                step.diagnosis = diagnose_window(
                    Run(w.time, w.channels, w.sample_rate, w.labels), bundle
                )
                if writer is not None:
                    writer.add(w.end_ns, step.diagnosis.to_json())
            else:
                step.statistics = window_statistics(w)
            yield step
    except BaseException:
        if writer is not None:
            writer.abort()
        raise
    finally:
        stream.close()
    if writer is not None:
        writer.close()
