"""Diagnosis: recording → windows → indicators → estimators → :class:`Diagnosis`.

A **model bundle** (saved by :func:`prsm_health.training.train.train`) holds the clearance estimator,
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

``Diagnosis.to_json()`` is the Diagnosis contract (docs/formats.md), declared once with its
typed parts in :mod:`prsm_health.diagnostics.contract`::

    {"clearance": {"estimate": m, "lower": m, "upper": m}, "fault_class": str,
     "class_probabilities": {class: p}, "class_set": [class], "observability": {target: …},
     "ood_score": float, "indicators": {name: value}, "indicator_groups": {group: str},
     "model": {name, version, design, instrumentation}, "warnings": [str],
     "window"|"windows": …}
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.design_files import (
    design_fingerprint,
    labelled_same_design,
    load_design,
)
from prsm_health.core.channels import MEASURED_TOPICS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import finite_or_none
from prsm_health.core.operating_point import NO_DESIGN, OperatingPoint
from prsm_health.core.run import Run
from prsm_health.signals.features import FEATURES, extract_features_batch
from prsm_health.signals.indicator_table import indicator_groups

from .answer import NAME_PROBABILITY, SET_NOTE, ambiguous, fault_answer, not_observable  # noqa: F401 (NAME_PROBABILITY: public here)
from .contract import (  # OOD_LIMIT: public here too, where it was defined before
    CANNOT_TELL,
    OOD_LIMIT,
    ClearanceInterval,
    Diagnosis,
    ModelReference,
    Observability,
    WindowSpan,
)

#: Where the shipped default model lives (repository layout: models/ next to the package).
DEFAULT_MODEL = Path(__file__).resolve().parents[2] / "models" / "default.skops"
#: A recording's tail shorter than a window is diagnosed as its own window when it holds at
#: least this fraction of a window (indicators over less are biased: fewer reversals, wider
#: spectral bins), and reported as dropped otherwise.
MIN_TAIL_FRACTION = 0.5
#: How the warning of windows unlike the training set begins.
_OOD_NOTE = "indicators unlike the training windows"
#: A clearance interval at least this share of the trained range wide says nothing: the
#: clearance is not observable in that window (the shipped model's held-out intervals are
#: 10 µm wide on average, a quarter of its 40 µm range: models/default.metrics.json).
WHOLE_RANGE_SHARE = 0.9
#: Each operating indicator a model records the range of: its words in warnings, and the
#: recipe's sweep key that covers it (what to sweep for a recording outside the range).
REGIME = {
    "speed_mean": ("speed", "speed"),
    "load_mean": ("mean load", "load"),
    "load_range": ("load swing", "load_amplitude"),
    "drive_torque_mean": ("mean drive torque (load)", "load"),
}


@dataclass
class ModelBundle:
    """A loaded diagnosis model; ``design`` is resolved once, at load."""

    clearance: object | None
    fault: object | None
    feature_names: list[str]
    metadata: dict
    guard: object | None = None
    check: dict | None = None
    #: The indicators the fault classifier reads, when not ``feature_names`` (a shipped plain
    #: baseline reads the channel statistics: training.fault_candidates).
    fault_features: list[str] | None = None
    design: PRSMDesign | None = field(init=False)

    def __post_init__(self):
        # None: a model trained on an imported rig that is not a PRSM (no design)
        design = self.metadata.get("design", "paper01")
        self.design = None if design is None else load_design(design)

    @property
    def check_only(self) -> bool:
        """A bundle with a health-check part and no window model (``prsm-health train`` on
        checks alone): it reads health-check recordings only."""
        return self.check is not None and self.clearance is None and self.fault is None

    @cached_property  # the chain's sensor delays: once per loaded model
    def clearance_gauge(self):
        """The health check's clearance gauge for this model's actuator
        (:func:`~prsm_health.diagnostics.clearance_gauge.gauge_for`); None without a design."""
        from .clearance_gauge import gauge_for

        return gauge_for(self.design, self.metadata, self.check)

    @property
    def design_name(self) -> str:
        return self.design.name if self.design is not None else NO_DESIGN

    @cached_property  # a hash of the whole design: once per loaded model, not per recording
    def design_fingerprint(self) -> str | None:
        """The identity of the design the model was trained on (None: a rig without one)."""
        return None if self.design is None else design_fingerprint(self.design)

    def refuses(self, operating: OperatingPoint) -> str | None:
        """Why this model cannot diagnose a recording of this operating point — another
        design — or None. The design itself decides (its fingerprint) where the recording
        carries it; a recording known only by its design's name is compared by name; one that
        names no design, or a model trained on a rig without one, is taken as it comes."""
        if self.design is None:
            return None
        fingerprint, name = operating.design_fingerprint, operating.design
        if name == NO_DESIGN:
            name = None
        if labelled_same_design(name, fingerprint, self.design.name, self.design_fingerprint) in (
            True,
            None,
        ):
            return None
        shown = name if fingerprint is None else f"{name} ({fingerprint})"
        return (
            f"recording of design {shown!r}, model {self.name!r} was trained on design "
            f"{self.design.name!r} ({self.design_fingerprint}): its indicators mean something "
            "else; diagnose it with a model trained for its design (prsm-health train)"
        )

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
        """The ``model`` entry of a diagnosis, as JSON (:meth:`model_reference`)."""
        return self.model_reference().to_json()

    def model_reference(self) -> ModelReference:
        """The ``model`` entry of a diagnosis."""
        return ModelReference(
            self.name, self.version, self.design_name, self.metadata.get("instrumentation")
        )

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
    check = model.get("check")
    if check is None and check_part_path(path).exists():
        check, _ = load_model(check_part_path(path), allow_version_mismatch=allow_version_mismatch)
    return ModelBundle(
        model.get("clearance"),
        model.get("fault"),
        list(model["feature_names"]),
        metadata,
        model.get("guard"),
        check,
        model.get("fault_features"),
    )


def check_part_path(path: str | Path) -> Path:
    """Where a bundle's check part lives: ``<name>.check.skops`` beside ``<name>.skops`` (a
    file of its own, so neither file of the shipped model grows past 5 MiB)."""
    path = Path(path)
    return path.with_name(f"{path.stem}.check{path.suffix}")


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
    rows: list[dict],
    bundle: ModelBundle,
    channels: list | None = None,
    design: str | None = None,
    rates: list | None = None,
) -> list[Diagnosis]:
    """One :class:`Diagnosis` per row of indicators (one row per window).

    ``channels``: the measured channels of each row's window (default: the model's, i.e. none
    missing); ``design``: the recording's design name, if it has one; ``rates``: each
    window's sample rate [Hz] (default unknown), for the groups a rate leaves out.
    """
    x = _matrix(rows, bundle.feature_names)
    channels = channels or [bundle.channels or ()] * len(rows)
    rates = rates or [None] * len(rows)
    # A few rows per call: OpenMP threads in the boosted trees only add spin-wait latency, and
    # under load (the service, parallel replays) oversubscribe the cores.
    with _threadpools().limit(limits=1, user_api="openmp"):
        return _predict(rows, x, bundle, channels, design, rates)


def _window_gates(
    row: dict, channels, bundle: ModelBundle, ood: float, design, interval_share: float
) -> tuple:
    """(clearance observable, fault observable, warnings, missing conditions) of one window.

    ``interval_share``: the share of the trained range the regression's clearance interval
    covers (NaN without a clearance model or a recorded range)."""
    notes, conditions = [], []
    missing = bundle.missing_channels(channels)
    conditions += [f"channel {name}" for name in missing]
    if missing:
        notes.append(
            f"channel(s) {', '.join(missing)} missing: model {bundle.name!r} was trained with "
            f"them ({', '.join(bundle.channels)}); their indicators are NaN"
        )
    reversal = row.get("reversal")
    reverses = reversal is not None and np.isfinite(reversal) and reversal > 0
    gate = bundle.metadata.get("observability_feature")
    gate_ok = gate not in bundle.feature_names or np.isfinite(row.get(gate, np.nan))
    ood_high = bool(np.isfinite(ood) and ood > OOD_LIMIT)
    shown = bool(reverses and gate_ok and not missing)
    # An interval as wide as the trained range says nothing about the clearance: the window
    # does not show it, whatever the gates above say (observability must not claim it does).
    wide = bool(np.isfinite(interval_share) and interval_share >= WHOLE_RANGE_SHARE)
    clearance_ok = shown and not ood_high and not wide
    if not reverses:
        conditions.append("a load or motion reversal")
    elif not (gate_ok or missing):
        conditions.append(f"a window where {gate} is computable")
    if ood_high:
        conditions.append("indicators like the training recordings (design, instrumentation, duty)")
    if bundle.clearance is not None and not shown:
        if not reverses:
            notes.append(
                "no load or motion reversal in this window: clearance is not observable (the "
                "rollers stay on one flank); the interval is the whole trained range"
            )
        elif missing:
            notes.append("clearance is not observable without the missing channel(s)")
        else:
            notes.append(f"indicator {gate} not computable: clearance is not observable")
    elif bundle.clearance is not None and wide and not ood_high:
        notes.append(
            f"the clearance interval covers {100 * WHOLE_RANGE_SHARE:.0f} % or more of the "
            "trained range: clearance is not observable in this window (its indicators do not "
            "narrow it); the interval is the whole trained range"
        )
    outside = False
    for name, (lo, hi) in bundle.regime.items():
        value = row.get(name)
        if value is not None and np.isfinite(value):
            if lo >= 0.0 > value or hi <= 0.0 < value:
                # a factor trained on one sign only: the mechanism runs the same the other way
                # round (its mirror image), so the magnitude is what must be in range
                value = -value
            slack = 0.05 * max(hi - lo, abs(hi), abs(lo))  # the range of a few hundred windows
            if not lo - slack <= value <= hi + slack:
                # between the trained levels the guard interpolates; beyond them the model
                # would extrapolate, confidently wrong at worst: it says so and does not tell
                outside = True
                (word, sweep), unit = REGIME.get(name, (name, name)), FEATURES[name]
                notes.append(
                    f"recording outside the trained {word} range: {value:.4g} vs {lo:.4g} … "
                    f"{hi:.4g} {unit} — the model does not extrapolate: record within it, or "
                    f"train on a recipe whose [sweep] {sweep} covers "
                    f"{value:.3g} {unit}"
                )
                conditions.append(f"a {word} within the trained {lo:.3g} … {hi:.3g} {unit}")
    clearance_ok = clearance_ok and not outside
    if design is not None and design != bundle.design_name:
        notes.append(
            f"recording of design {design!r}, model trained on {bundle.design_name!r}: its "
            "indicators mean something else"
        )
    if ood_high:
        notes.append(_ood_note([ood]))
    fault_ok = clearance_ok  # the wear classes differ by clearance
    if bundle.fault is not None and not fault_ok:
        notes.append(
            "fault class: cannot tell"
            if ood_high or outside
            else "fault class: cannot tell — wear classes differ by clearance, which this window "
            "does not show"
        )
    if wide and not conditions:
        conditions.append("a load reversal the clearance shows in (its interval spans the range)")
    return clearance_ok, fault_ok, notes, conditions


def _undecided(fault_class, class_set, observable: bool, conditions: list, bundle):
    """Why a diagnosis cannot tell (None when it names a class)."""
    if fault_class != CANNOT_TELL:
        return None
    has_check = getattr(bundle, "check", None) is not None
    if not observable:
        return not_observable(list(dict.fromkeys(conditions)), has_check=has_check)
    return ambiguous(class_set, baseline=False, check=False)


def _ood_note(scores: list[float]) -> str:
    """The warning of windows unlike the training set, with their scores (each above
    :data:`OOD_LIMIT`), rounded."""
    low, high = _above_limit(min(scores)), _above_limit(max(scores))
    shown = low if low == high else f"{low} … {high}"
    return (
        f"{_OOD_NOTE} (out-of-distribution score {shown} > {OOD_LIMIT:g}): another design, "
        "instrumentation or operating regime? No class, and the clearance interval is the "
        "whole trained range"
    )


def _above_limit(score: float) -> str:
    """``score`` (> :data:`OOD_LIMIT`) rounded to the fewest digits (two at least) that still
    read above the limit: 1.52 is "1.52", never "1.5"."""
    for digits in (2, 3, 4, 5):
        text = f"{score:.{digits}g}"
        if float(text) > OOD_LIMIT:
            return text
    return f"{score:.6g}"


def ood_verdict(diagnosis: Diagnosis) -> str:
    """The OOD score of a diagnosis in words, true for a window and for a recording (whose
    score is the median of its windows', some of which may lie above the limit while the
    median does not): e.g. "0.61 ≤ 1.5: like the training set", "9.4 > 1.5: unlike the
    training set", "0.61 ≤ 1.5 (median of 5 windows; 1 above: unlike the training set)"."""
    score = diagnosis.ood_score
    if score is None:
        return "not computed (the model has no out-of-distribution guard)"
    windows = [w.ood_score for w in diagnosis.windows if w.ood_score is not None]
    above = sum(s > OOD_LIMIT for s in windows)
    if score > OOD_LIMIT:
        text = f"{_above_limit(score)} > {OOD_LIMIT:g}: unlike the training set"
    else:
        text = f"{score:.2g} ≤ {OOD_LIMIT:g}: like the training set"
    if len(windows) > 1 and 0 < above < len(windows):
        text += f" (median of {len(windows)} windows; {above} above {OOD_LIMIT:g})"
    return text


def _predict(rows, x, bundle: ModelBundle, channels, design, rates) -> list[Diagnosis]:
    n = len(rows)
    estimate = lower = upper = share = np.full(n, np.nan)
    guard = bundle.guard
    ood = np.asarray(guard.score(x), float) if guard is not None else np.full(n, np.nan)
    span = bundle.metadata.get("clearance_range")
    if bundle.clearance is not None:
        estimate = np.asarray(bundle.clearance.predict(x), float)
        lower, upper = (np.asarray(a, float) for a in bundle.clearance.predict_interval(x))
        if span and span[1] > span[0]:
            # the part of the trained range the interval covers (a wide interval that reaches
            # past one end still tells the clearance lies near that end)
            covered = np.minimum(upper, span[1]) - np.maximum(lower, span[0])
            share = np.clip(covered, 0.0, None) / (span[1] - span[0])
    gates = [
        _window_gates(r, c, bundle, o, design, s) for r, c, o, s in zip(rows, channels, ood, share)
    ]
    if bundle.clearance is not None and span:
        # Where the clearance is not observable (no reversal: steady load keeps each roller on
        # one flank, docs/validation.md; the window unlike the training set; an interval that
        # says nothing) the interval is the whole range the model was trained on, whatever the
        # regression says.
        hidden = np.array([not g[0] for g in gates])
        lower = np.where(hidden, span[0], lower)
        upper = np.where(hidden, span[1], upper)
    classes, proba = [], np.zeros((n, 0))
    if bundle.fault is not None:
        classes = [str(c) for c in bundle.fault.classes_]
        reads = x if bundle.fault_features is None else _matrix(rows, bundle.fault_features)
        proba = np.asarray(bundle.fault.predict_proba(reads), float)
    model = bundle.model_reference()
    out = []
    for i, row in enumerate(rows):
        clearance_ok, fault_ok, notes, conditions = gates[i]
        probabilities = {c: float(p) for c, p in zip(classes, proba[i])}
        fault_class, class_set = fault_answer(probabilities, fault_ok, bundle.fault, notes)
        out.append(
            Diagnosis(
                clearance=ClearanceInterval(
                    finite_or_none(estimate[i]),
                    finite_or_none(lower[i]),
                    finite_or_none(upper[i]),
                ),
                fault_class=fault_class,
                class_probabilities=probabilities,
                class_set=class_set,
                indicators={k: finite_or_none(v) for k, v in row.items()},
                model=model,
                warnings=notes,
                observability=Observability(clearance_ok, fault_ok),
                ood_score=finite_or_none(ood[i]),
                indicator_groups=indicator_groups(row, channels[i], rates[i]),
                undecided=_undecided(fault_class, class_set, fault_ok, conditions, bundle),
            )
        )
    return out


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
            if note.startswith(_OOD_NOTE):  # one note with the range of the windows' scores
                note = _OOD_NOTE
            if SET_NOTE not in note:  # restated below for the mean probabilities
                counts[note] = counts.get(note, 0) + 1
    flagged = [
        d.ood_score for d in diagnoses if d.ood_score is not None and d.ood_score > OOD_LIMIT
    ]
    notes = [
        (_ood_note(flagged) if note == _OOD_NOTE else note)
        + ("" if k == len(diagnoses) else f" (in {k} of {len(diagnoses)} windows)")
        for note, k in counts.items()
    ]
    fault_class, class_set = fault_answer(probs, bool(told), bundle.fault, notes)
    conditions = [m for d in diagnoses if d.undecided is not None for m in d.undecided.missing]
    names = diagnoses[0].indicators.keys()
    groups = {
        g: next(
            (d.indicator_groups[g] for d in diagnoses if d.indicator_groups.get(g) == "computed"), r
        )
        for g, r in diagnoses[0].indicator_groups.items()
    }
    return Diagnosis(
        clearance=ClearanceInterval(
            *(median([d.clearance[k] for d in seen]) for k in ("estimate", "lower", "upper"))
        ),
        fault_class=fault_class,
        class_probabilities=probs,
        class_set=class_set,
        indicators=_median_indicators(diagnoses, list(names)),
        model=bundle.model_reference(),
        windows=list(diagnoses),
        warnings=notes,
        observability=Observability(
            **{
                target: float(np.mean([bool(d.observability[target]) for d in diagnoses]))
                for target in Observability.TARGETS
            }
        ),
        ood_score=median([d.ood_score for d in diagnoses]),
        indicator_groups=groups,
        undecided=_undecided(fault_class, class_set, bool(told), conditions, bundle),
    )


def _median_indicators(diagnoses: list[Diagnosis], names: list[str]) -> dict:
    """Each indicator's median over the windows that have it (None where none has), as
    ``np.median`` of those values gives it, all indicators at once: sorted per column, the
    middle value or the mean of the two middle ones."""
    table = np.array([[d.indicators[n] for n in names] for d in diagnoses], dtype=float)
    count = np.sum(~np.isnan(table), axis=0)  # None became NaN; a value is never NaN
    ordered = np.sort(table, axis=0)  # NaN last
    columns = np.arange(len(names))
    upper, lower = ordered[count // 2, columns], ordered[np.maximum(count - 1, 0) // 2, columns]
    middle = np.where(count % 2 == 1, upper, (lower + upper) / 2.0)
    return {n: (float(m) if k else None) for n, m, k in zip(names, middle, count)}


def diagnose_window(run: Run, bundle: ModelBundle) -> Diagnosis:
    """Diagnosis of one window (a :class:`Run` of about the model's window length)."""
    row = bundle.indicators(run)
    return diagnose_indicators(
        [row], bundle, [tuple(run.channels)], run.operating.design, [run.sample_rate]
    )[0]


def split_windows(run: Run, length: float) -> tuple[list[Run], list[str]]:
    """Windows of ``length`` seconds covering the recording, and warnings about what is not.

    A recording shorter than one window (but ≥ the indicators' minimum) is one window; a tail
    of at least :data:`MIN_TAIL_FRACTION` of a window is a last, shorter window; a shorter tail
    is dropped with a warning (:meth:`Run.windows <prsm_health.core.run.Run.windows>` cuts).
    """
    return run.windows(length, min_tail=MIN_TAIL_FRACTION)


def diagnose(
    run: Run,
    bundle: ModelBundle | None = None,
    *,
    window: float | None = None,
    windows: tuple[list[Run], list[str]] | None = None,
    baseline=None,
    commissioning=None,
) -> Diagnosis:
    """Diagnose a recording: a :class:`Diagnosis` of the whole, with one per window — or, for a
    health-check recording and a bundle with a check model, one of the check read phase by
    phase (:func:`prsm_health.diagnostics.check_model.diagnose_check`).

    Parameters
    ----------
    run : Run
    bundle : ModelBundle, default the shipped model
    window : float or None [s]
        Window length; default the model's training window (see :func:`split_windows`).
    windows : (windows, notes) or None
        ``run`` already cut by :func:`split_windows`, for a caller that needs the windows too
        (it then cuts once); ``window`` is ignored.
    baseline : Baseline or None
        The unit's own baseline (:class:`prsm_health.diagnostics.baseline.Baseline`): a check
        recording is then read against it too.
    commissioning : Commissioning or None
        The unit's constant lost motion fixed at commissioning
        (:class:`prsm_health.diagnostics.clearance_gauge.Commissioning`): a check's measured
        clearance reads against it.
    """
    split = None if windows is None else [windows]
    return diagnose_runs(
        [run], bundle, window=window, split=split, baseline=baseline, commissioning=commissioning
    )[0]


def diagnose_runs(
    runs: list[Run],
    bundle: ModelBundle | None = None,
    *,
    window: float | None = None,
    split: list[tuple[list[Run], list[str]]] | None = None,
    baseline=None,
    commissioning=None,
) -> list[Diagnosis]:
    """Diagnose several recordings in one batch (every window's indicators in one call):
    one :class:`Diagnosis` per run, each as :func:`diagnose` gives it; ``split``: each run
    already cut by :func:`split_windows` (``window`` then ignored); ``baseline`` and
    ``commissioning``: of the unit all the runs belong to."""
    from .check_model import diagnose_check, is_check, read_check_by_physics

    bundle = bundle or load_bundle()
    for run in runs:
        reason = bundle.refuses(run.operating)
        if reason is not None:
            raise PRSMHealthError(reason)
    runs = [run.without_truth().validate() for run in runs]
    if bundle.check_only and not all(is_check(run) for run in runs):
        raise PRSMHealthError(CHECK_ONLY.format(name=bundle.name))
    # a check recording is read phase by phase when the model can (and was not cut already)
    checks = {
        i: diagnose_check(run, bundle, baseline, commissioning)
        for i, run in enumerate(runs)
        if bundle.check is not None and split is None and is_check(run)
    }
    rest = [i for i in range(len(runs)) if i not in checks]
    windowed = _diagnose_windowed(
        [runs[i] for i in rest],
        bundle,
        window=window,
        split=None if split is None else [split[i] for i in rest],
    )
    if bundle.check is None:  # one line on why; what physics reads without a model
        for i, d in zip(rest, windowed):
            if is_check(runs[i]):
                d.warnings.append(NO_CHECK_PART.format(name=bundle.name))
                read_check_by_physics(runs[i], bundle, d, commissioning)
    if baseline is not None and bundle.check is not None:
        for d in windowed:
            d.warnings.append(
                "the unit's baseline is read against its health-check recordings; this "
                "recording, no check, is read alone"
            )
    out = dict(checks) | dict(zip(rest, windowed))
    return [out[i] for i in range(len(runs))]


#: The warning of a health-check recording diagnosed by a bundle without a check part.
NO_CHECK_PART = (
    "model {name!r} has no health-check part: this check is read window by window across its "
    "phases, which no window of its training mixed (expect out-of-distribution windows or "
    "cannot_tell) — only what physics reads alone is the check's (the clearance from its "
    "reversals, the torque ratio, the temperature); to read it phase by phase, train one with "
    '`prsm-health train` on a dataset of check recordings (docs/diagnostics.md, "A health '
    'check for your own actuator")'
)

#: The refusal of a recording that is no health check by a bundle with a check part only.
CHECK_ONLY = (
    "model {name!r} has a health-check part only: it reads health-check recordings (their "
    "phases known) and this recording is none; diagnose it with a window model, or train one "
    "and add the check part to it (prsm-health train CHECKS --window-model MODEL)"
)


def _diagnose_windowed(runs, bundle, *, window, split) -> list[Diagnosis]:
    if not runs:
        return []
    if split is None:
        split = [split_windows(run, window or bundle.window) for run in runs]
    elif len(split) != len(runs):
        raise ValueError(f"{len(split)} window sets for {len(runs)} runs")
    split = [([part.without_truth() for part in parts], notes) for parts, notes in split]
    rows = bundle.indicators_batch([part for parts, _ in split for part in parts])
    channels = [tuple(run.channels) for run, (parts, _) in zip(runs, split) for _ in parts]
    designs = [run.operating.design for run, (parts, _) in zip(runs, split) for _ in parts]
    rates = [run.sample_rate for run, (parts, _) in zip(runs, split) for _ in parts]
    per_window = []
    for design in dict.fromkeys(designs):  # one call per design (usually one)
        at = [i for i, d in enumerate(designs) if d == design]
        found = diagnose_indicators(
            [rows[i] for i in at],
            bundle,
            [channels[i] for i in at],
            design,
            [rates[i] for i in at],
        )
        per_window.extend(zip(at, found))
    per_window = [d for _, d in sorted(per_window, key=lambda pair: pair[0])]
    results, start = [], 0
    for parts, notes in split:
        mine = per_window[start : start + len(parts)]
        start += len(parts)
        for k, (part, d) in enumerate(zip(parts, mine)):
            d.window = WindowSpan(k, float(part.time[0]), float(part.time[-1]))
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

    from .not_observable import diagnosis_message

    length = window or (bundle.window if bundle else 1.0)
    writer = DiagnosisWriter(path, out) if (out and bundle) else None
    stream = iter_windows(path, length, rate=rate, topics=MEASURED_TOPICS)
    try:
        for w in stream:
            step = ReplayStep(w.index, w.start, w.end)
            if bundle is not None:
                step.diagnosis = diagnose_window(
                    Run(w.time, w.channels, w.sample_rate, w.labels, operating=w.operating),
                    bundle,
                )
                if writer is not None:
                    writer.add(w.end_ns, diagnosis_message(step.diagnosis.to_json()))
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
