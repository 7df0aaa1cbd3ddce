"""Diagnosis: recording → windows → indicators → estimators → :class:`Diagnosis`.

A **model bundle** (saved by :func:`prsm_health.training.train`) holds the clearance estimator,
the fault classifier, the indicator names they were trained on, the window length of the
training runs, the design and the measured channels of the training runs. :func:`diagnose`
cuts a recording into windows of that length, computes the indicators
(:mod:`prsm_health.features`) of each, and returns a :class:`Diagnosis` for the whole recording
with one per window; :func:`replay` does the same window by window while an MCAP recording
streams. The diagnosis reads the measured channels only, never a
recording's truth signals.

Missing channels: the indicator set is fixed (:data:`prsm_health.features.FEATURES`) and an
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
from pathlib import Path

import numpy as np

from .channels import MEASURED_TOPICS
from .design import PRSMDesign
from .design_files import load_design
from .errors import PRSMHealthError, RecordingError
from .features import extract_features, windows
from .jsonable import finite_or_none
from .run import MIN_SAMPLES, Run

#: Where the shipped default model lives (repository layout: models/ next to the package).
DEFAULT_MODEL = Path(__file__).resolve().parents[1] / "models" / "default.skops"
#: A recording's tail shorter than a window is diagnosed as its own window when it holds at
#: least this fraction of a window (indicators over less are biased: fewer reversals, wider
#: spectral bins), and reported as dropped otherwise.
MIN_TAIL_FRACTION = 0.5


@dataclass
class ModelBundle:
    """A loaded diagnosis model; ``design`` is resolved once, at load."""

    clearance: object | None
    fault: object | None
    feature_names: list[str]
    metadata: dict
    design: PRSMDesign = field(init=False)

    def __post_init__(self):
        self.design = load_design(self.metadata.get("design", "paper01"))

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
        return {"name": self.name, "version": self.version, "design": self.design.name}

    def check_channels(self, run: Run, what: str = "recording") -> None:
        """Refuse a recording that lacks a channel the model was trained with."""
        missing = [c for c in self.channels or () if c not in run.channels]
        if missing:
            raise RecordingError(
                f"{what} lacks channel(s) {', '.join(missing)} that model {self.name!r} was "
                f"trained with ({', '.join(self.channels)}); use a model trained for this "
                "instrumentation"
            )


def load_bundle(
    path: str | Path | None = None, *, allow_version_mismatch: bool = False
) -> ModelBundle:
    """Load a model bundle (default: the shipped model); version checks in persistence.load_model."""
    from .persistence import load_model

    path = Path(path) if path is not None else DEFAULT_MODEL
    if not path.exists():
        hint = " (run tools/train_default_model.py)" if path == DEFAULT_MODEL else ""
        raise PRSMHealthError(f"{path}: no such model file{hint}")
    model, metadata = load_model(path, allow_version_mismatch=allow_version_mismatch)
    if not isinstance(model, dict) or "feature_names" not in model:
        raise PRSMHealthError(f"{path}: not a prsm_health diagnosis bundle")
    return ModelBundle(
        model.get("clearance"), model.get("fault"), list(model["feature_names"]), metadata
    )


@dataclass
class Diagnosis:
    """One diagnosis, of a window or of a whole recording (then with ``windows``).

    Attributes
    ----------
    clearance : dict
        ``estimate``, ``lower``, ``upper`` [m] (90 % interval); None where not computable.
    fault_class : str or None
        The most probable class.
    class_probabilities : dict of class → probability
    indicators : dict of name → value (None where not computable)
    model : dict
        ``name``, ``version``, ``design`` of the model bundle.
    window : dict or None
        ``index``, ``start``, ``end`` [s] of a window diagnosis.
    windows : list of Diagnosis
        Per-window diagnoses of a recording diagnosis.
    warnings : list of str
        Sentences a person can act on (e.g. a dropped tail).
    """

    clearance: dict
    fault_class: str | None
    class_probabilities: dict
    indicators: dict
    model: dict
    window: dict | None = None
    windows: list[Diagnosis] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def to_json(self) -> dict:
        """The Diagnosis contract as plain JSON values."""
        out = {
            "clearance": dict(self.clearance),
            "fault_class": self.fault_class,
            "class_probabilities": dict(self.class_probabilities),
            "indicators": dict(self.indicators),
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

    return pd.DataFrame(
        [[r.get(n, np.nan) for n in names] for r in rows], columns=names, dtype=float
    )


def diagnose_indicators(rows: list[dict], bundle: ModelBundle) -> list[Diagnosis]:
    """One :class:`Diagnosis` per row of indicators (one row per window)."""
    from threadpoolctl import threadpool_limits

    x = _matrix(rows, bundle.feature_names)
    # A few rows per call: OpenMP threads in the boosted trees only add spin-wait latency, and
    # under load (the service, parallel replays) oversubscribe the cores.
    with threadpool_limits(limits=1, user_api="openmp"):
        return _predict(rows, x, bundle)


def _predict(rows: list[dict], x, bundle: ModelBundle) -> list[Diagnosis]:
    n = len(rows)
    estimate = lower = upper = np.full(n, np.nan)
    if bundle.clearance is not None:
        estimate = np.asarray(bundle.clearance.predict(x), float)
        lower, upper = (np.asarray(a, float) for a in bundle.clearance.predict_interval(x))
        # Regime gate: without a load or motion reversal the clearance is not observable
        # (steady preload keeps each roller on one flank, docs/validation.md), so the interval
        # is the whole range the model was trained on, whatever the regression says.
        gate = bundle.metadata.get("observability_feature")
        span = bundle.metadata.get("clearance_range")
        if gate in x.columns and span:
            hidden = ~np.isfinite(x[gate].to_numpy(float))
            lower = np.where(hidden, span[0], lower)
            upper = np.where(hidden, span[1], upper)
    classes, proba = [], np.zeros((n, 0))
    if bundle.fault is not None:
        classes = [str(c) for c in bundle.fault.classes_]
        proba = np.asarray(bundle.fault.predict_proba(x), float)
    out = []
    for i, row in enumerate(rows):
        probabilities = {c: float(p) for c, p in zip(classes, proba[i])}
        out.append(
            Diagnosis(
                clearance={
                    "estimate": finite_or_none(estimate[i]),
                    "lower": finite_or_none(lower[i]),
                    "upper": finite_or_none(upper[i]),
                },
                fault_class=max(probabilities, key=probabilities.get) if probabilities else None,
                class_probabilities=probabilities,
                indicators={k: finite_or_none(v) for k, v in row.items()},
                model=bundle.reference(),
            )
        )
    return out


def aggregate(diagnoses: list[Diagnosis], bundle: ModelBundle) -> Diagnosis:
    """One diagnosis for a recording: medians of the window estimates and bounds, mean class
    probabilities, median indicators; the windows attached."""

    def median(values):
        values = [v for v in values if v is not None]
        return float(np.median(values)) if values else None

    probs: dict[str, float] = {}
    for d in diagnoses:
        for c, p in d.class_probabilities.items():
            probs[c] = probs.get(c, 0.0) + p / len(diagnoses)
    names = diagnoses[0].indicators.keys()
    return Diagnosis(
        clearance={
            k: median([d.clearance[k] for d in diagnoses]) for k in ("estimate", "lower", "upper")
        },
        fault_class=max(probs, key=probs.get) if probs else None,
        class_probabilities=probs,
        indicators={n: median([d.indicators[n] for d in diagnoses]) for n in names},
        model=bundle.reference(),
        windows=list(diagnoses),
    )


def diagnose_window(run: Run, bundle: ModelBundle) -> Diagnosis:
    """Diagnosis of one window (a :class:`Run` of about the model's window length)."""
    bundle.check_channels(run, "window")
    return diagnose_indicators([extract_features(run, bundle.design)], bundle)[0]


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
    bundle = bundle or load_bundle()
    run = run.without_truth().validate()
    bundle.check_channels(run)
    parts, notes = split_windows(run, window or bundle.window)
    rows = [extract_features(part, bundle.design) for part in parts]
    per_window = diagnose_indicators(rows, bundle)
    for k, (part, d) in enumerate(zip(parts, per_window)):
        d.window = {"index": k, "start": float(part.time[0]), "end": float(part.time[-1])}
    result = aggregate(per_window, bundle)
    result.warnings.extend(notes)
    return result


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
    from .mcap import DiagnosisWriter, iter_windows, window_statistics

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
