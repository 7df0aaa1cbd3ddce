"""An asset's recorded history — its baseline, accumulated evidence and change statistic.

An **asset** is one unit (one actuator) recorded again and again over its life. Its history
is a sequence of :class:`AssetEntry`, one per recording, in the order the recordings reached
it, and the sequential state they built: the class :class:`~.evidence.Evidence` and the
:class:`~.evidence.Cusum` on the baseline distance. :meth:`AssetHistory.record` adds one
diagnosed recording and attaches the asset's state to the diagnosis (``Diagnosis.asset``):

* while the baseline is incomplete (fewer than :data:`BASELINE_RECORDINGS` recordings in
  it), a recording joins the baseline unless it is labelled not healthy or the diagnosis
  names a fault with confidence (:func:`names_a_fault`); a recording labelled healthy joins
  it at any time;
* every recording not put in the baseline adds its class probabilities to the evidence and,
  once the baseline is complete, its distance from the baseline to the CUSUM — unless the
  model could not see its fault class (:func:`unobservable`): then it adds neither, and its
  diagnosis says so; its distance and changes are shown all the same;
* recording the same ``recording_id`` again changes nothing: the diagnosis comes back with
  the state stored the first time (an interrupted or repeated run counts each recording once).

The histories are kept by a store (:mod:`.store`: one JSON file per asset for the CLI, an
SQLite database for the service) and changed by the steps of :mod:`.steps`, which the CLI and
the service both call.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

from prsm_health.core.errors import require
from prsm_health.core.identifiers import ASSET_ID_PATTERN, ASSET_ID_RULE
from prsm_health.core.jsonable import as_finite, finite_or_none
from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.clearance_gauge import GAUGE_INDICATORS, Commissioning
from prsm_health.diagnostics.contract import (
    CANNOT_TELL,
    OOD_LIMIT,
    AssetState,
    BaselineState,
    Diagnosis,
    EvidenceState,
)

from .evidence import EVIDENCE_NAME_PROBABILITY, Cusum, Evidence

#: Recordings a baseline needs before recordings are scored against it. Three is the fewest
#: whose median is robust (one odd recording of three cannot move it beyond the other two)
#: and whose spread, with the prior scale worth :data:`~.baseline.PRIOR_WEIGHT` recordings,
#: has 5 degrees of freedom; it is also what a commissioning routine can afford (three health
#: checks of a new unit). More come in as recordings labelled healthy.
BASELINE_RECORDINGS = 3
#: The class of a healthy unit.
HEALTHY = "healthy"
#: The share of a recording's windows in which its fault class must have been observable
#: (``Diagnosis.observability["fault"]``) for the recording to add class evidence and a CUSUM
#: step. A recording's indicators are the medians of all its windows and its class
#: probabilities the mean of the windows that saw the class: below one half, its indicators
#: (hence its distance) are mostly those of windows that did not show the class, and a few
#: windows would speak for the whole recording.
OBSERVABLE_SHARE = 0.5
#: Version of the history's JSON form.
FORMAT = 1


def validate_asset_id(asset_id, field_name: str = "asset_id") -> str:
    """``asset_id`` if it is a valid asset id, else :class:`ParameterError` naming the field."""
    require(
        isinstance(asset_id, str) and re.fullmatch(ASSET_ID_PATTERN, asset_id) is not None,
        field_name,
        asset_id,
        ASSET_ID_RULE,
    )
    return asset_id


def names_a_fault(diagnosis: Diagnosis) -> bool:
    """Whether ``diagnosis`` names a fault with confidence: a class other than healthy is
    named (observable, calibrated probability ≥ 0.5) and healthy is outside its class set,
    i.e. ruled out at the set's coverage (90 % for the shipped model). Such a recording is kept
    out of a baseline in the making."""
    named = diagnosis.fault_class not in (None, CANNOT_TELL, HEALTHY)
    return named and HEALTHY not in (diagnosis.class_set or [])


def unobservable(diagnosis: Diagnosis) -> str | None:
    """Why ``diagnosis`` adds nothing to a unit's class evidence and change statistic, or None
    when it does. It adds nothing when the model could not see its fault class:

    * its out-of-distribution score is above :data:`~prsm_health.diagnostics.contract.OOD_LIMIT`
      (its indicators are unlike the training set: their change from the baseline and the
      class probabilities say what the recording was, not how the unit is), or
    * its fault class was observable (``observability["fault"]``) in fewer than
      :data:`OBSERVABLE_SHARE` of its windows; a window's or a check's observability is a
      bool, False counting as none.

    A check read by a model's check part has no OOD score; a check lacking a phase that a
    class needs is not observable (``observability["fault"]`` False)."""
    ood = finite_or_none(diagnosis.ood_score)
    if ood is not None and ood > OOD_LIMIT:
        return (
            f"its indicators are unlike the model's training set (out-of-distribution score "
            f"{ood:.3g} > {OOD_LIMIT:g})"
        )
    seen = diagnosis.observability.get("fault")
    share = 0.0 if seen is None else float(seen)
    if share >= OBSERVABLE_SHARE:
        return None
    if isinstance(seen, float):  # a recording's: the share of its windows
        return (
            f"its fault class was observable in {100 * share:.0f} % of its windows (at least "
            f"{100 * OBSERVABLE_SHARE:.0f} % needed)"
        )
    missing = diagnosis.undecided.missing if diagnosis.undecided is not None else []
    return "the recording could not show its fault class" + (
        f" (it lacked {', '.join(missing)})" if missing else ""
    )


def training_spread(bundle) -> dict[str, float] | None:
    """Indicator → the robust spread (IQR/1.349) of the window model's training windows, as
    its out-of-distribution guard stored it
    (:class:`~prsm_health.diagnostics.estimators.DistributionGuard` ``scale_``); None without
    a guard. The spread is between all the training windows — units, operating points and
    health states — so it is an upper bound of the within-unit repeatability."""
    guard = getattr(bundle, "guard", None)
    scale = getattr(guard, "scale_", None)
    names = getattr(guard, "feature_names_in_", None)
    if names is None:
        names = getattr(bundle, "feature_names", None)
    if scale is None or names is None or len(names) != len(scale):
        return None
    spread = {str(n): finite_or_none(s) for n, s in zip(names, scale)}
    return {n: s for n, s in spread.items() if s is not None and s > 0} or None


def bundle_priors(bundle, check: bool = True) -> tuple[dict | None, dict | None, list[str] | None]:
    """What a model bundle tells a unit's history about one kind of recording: (prior scale per
    indicator, training prior per class, the indicators a baseline of that kind is of).

    A health check (``check``) and a bundle with a check part
    (:class:`~prsm_health.diagnostics.check_model.CheckModel`): the check model's — the prior
    scale is its within-unit repeatability, measured on its training units' repeat checks.
    Otherwise (in-service windows, or a check read window by window by a bundle without a
    check part) the window model's indicators, with the spread of its training windows as prior
    scale (:func:`training_spread`) and no training prior (uniform, the default of
    :meth:`AssetHistory.record`). That spread is between units, operating points and health
    states, an upper bound of the within-unit repeatability: three baseline recordings that
    happen to agree closely never give near-zero scales (a healthy unit read against them
    cannot raise the alarm), and the change statistic sees only changes of about the training
    set's spread. A unit's check recordings and its in-service windows have baselines of their
    own: their indicators differ."""
    part = getattr(bundle, "check", None) or {}
    if check and part:
        scale, prior = part.get("repeatability"), part.get("training_prior")
        names = part.get("feature_names")
        return (
            dict(scale) if scale else None,
            dict(prior) if prior else None,
            list(names) if names else None,
        )
    names = getattr(bundle, "feature_names", None)
    return training_spread(bundle), None, (list(names) if names else None)


def _by_size(changes: Mapping[str, float]) -> dict[str, float]:
    """The finite z-scores, the largest |z| first."""
    finite = {k: float(v) for k, v in changes.items() if math.isfinite(v)}
    return dict(sorted(finite.items(), key=lambda kv: -abs(kv[1])))


class OperatingRow(NamedTuple):
    """A recorded diagnosis with operating hours, as a prognosis reads it
    (:meth:`AssetHistory.operating_history`, the service's
    :meth:`~.sqlite_store.HistoryStore.operating_history`); ``design`` is the diagnosing
    model's."""

    operating_hours: float
    clearance_estimate: float | None
    clearance_lower: float | None
    clearance_upper: float | None
    fault_class: str | None
    design: str | None


@dataclass(frozen=True)
class AssetEntry:
    """One recording of an asset, as recorded in its history.

    Parameters
    ----------
    recording_id : str
        The recording's identifier (unique within the history).
    time : str
        When it was recorded (ISO 8601), or "".
    operating_hours : float or None [h]
        The asset's operating hours then.
    indicators : dict
        Indicator → value (None where not computable), from the diagnosis.
    class_probabilities : dict
        Class → calibrated probability, from the diagnosis.
    fault_class : str or None
        The diagnosis's class.
    clearance : dict
        The diagnosis's clearance estimate and interval [m].
    baseline : bool
        Whether the recording was put in the baseline.
    distance : float or None
        Its distance from the baseline (:meth:`Baseline.distance`); None before the baseline
        was complete.
    state : AssetState or None
        The asset's state attached to the diagnosis when it was recorded.
    source : str
        How the recording came: ``file`` (a file read by the CLI or uploaded to the
        service) or the body format of a service request (``json``, ``arrow``, ``parquet``,
        ``mcap``).
    filename : str or None
        The recording's file name, for people.
    healthy : bool or None
        The label given with the recording (None: not said).
    design : str or None
        The diagnosing model's design (None in histories recorded before it was kept).
    """

    recording_id: str
    time: str = ""
    operating_hours: float | None = None
    indicators: dict = field(default_factory=dict)
    class_probabilities: dict = field(default_factory=dict)
    fault_class: str | None = None
    clearance: dict = field(default_factory=dict)
    baseline: bool = False
    distance: float | None = None
    state: AssetState | None = None
    source: str = ""
    filename: str | None = None
    healthy: bool | None = None
    design: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "state", AssetState.of(self.state))

    def to_json(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["state"] = None if self.state is None else self.state.to_json()
        return out

    @classmethod
    def from_json(cls, data: Mapping) -> AssetEntry:
        names = {f.name for f in dataclasses.fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in names})


@dataclass(frozen=True)
class AssetHistory:
    """An asset's recorded history: its entries (oldest first) and the sequential state they
    built.

    Parameters
    ----------
    asset_id : str
        The asset (:data:`ASSET_ID_PATTERN`).
    entries : tuple of AssetEntry
        One per recording, in the order they were recorded.
    evidence : Evidence or None
        The class evidence of the recordings not in the baseline (None before the first).
    cusum : Cusum
        The change statistic of their distances from the baseline.
    as_built_clearance : float or None [m]
        The unit's clearance as built (measured at assembly), given at commissioning: its
        baseline checks then fix the gauge's constant offset (:meth:`commissioning`).
    """

    asset_id: str
    entries: tuple[AssetEntry, ...] = ()
    evidence: Evidence | None = None
    cusum: Cusum = Cusum()
    as_built_clearance: float | None = None

    def __post_init__(self):
        validate_asset_id(self.asset_id)
        object.__setattr__(self, "entries", tuple(self.entries))

    def baseline(
        self,
        prior_scale: Mapping[str, float] | None = None,
        names: Sequence[str] | None = None,
    ) -> Baseline | None:
        """The baseline fitted on the entries put in it (:meth:`Baseline.fit`) that have any of
        ``names`` (the baseline of one kind of recording: health checks, or in-service
        windows); None until :data:`BASELINE_RECORDINGS` of them. Its indicators: ``names``
        (those the members have), else every indicator finite in all of them."""
        members = self.members(names)
        if len(members) < BASELINE_RECORDINGS:
            return None
        return Baseline.fit(
            [e.indicators for e in members],
            prior_scale=prior_scale,
            names=names,
            recordings=[e.recording_id for e in members],
        )

    def commissioning(self):
        """The unit's constant lost motion fixed at commissioning
        (:class:`~prsm_health.diagnostics.clearance_gauge.Commissioning`): its as-built
        clearance and the zero-load lost motion of its baseline checks; None without either."""
        if self.as_built_clearance is None:
            return None
        members = self.members(list(GAUGE_INDICATORS)[:1])  # the checks the gauge read
        if not members:
            return None
        rows = [{n: finite_or_none(e.indicators.get(n)) for n in GAUGE_INDICATORS} for e in members]
        return Commissioning.from_indicators(rows, self.as_built_clearance)

    def operating_history(self) -> list[OperatingRow]:
        """Its recordings with operating hours, as a prognosis reads them
        (:func:`prsm_health.prognostics.history_of_readings`), in the order recorded."""
        return [
            OperatingRow(
                e.operating_hours,
                finite_or_none(e.clearance.get("estimate")),
                finite_or_none(e.clearance.get("lower")),
                finite_or_none(e.clearance.get("upper")),
                e.fault_class,
                e.design,
            )
            for e in self.entries
            if e.operating_hours is not None
        ]

    def members(self, names: Sequence[str] | None = None) -> list[AssetEntry]:
        """The baseline's recordings of one kind: those put in it that have any of ``names``
        (all of them when None)."""

        def has(entry):
            return any(finite_or_none(entry.indicators.get(n)) is not None for n in names)

        return [e for e in self.entries if e.baseline and (names is None or has(e))]

    def entry(self, recording_id: str) -> AssetEntry | None:
        """The entry of ``recording_id``, or None."""
        return next((e for e in self.entries if e.recording_id == recording_id), None)

    def record(
        self,
        recording_id: str,
        diagnosis: Diagnosis,
        *,
        healthy: bool | None = None,
        operating_hours: float | None = None,
        time: str = "",
        prior_scale: Mapping[str, float] | None = None,
        training_prior: Mapping[str, float] | None = None,
        names: Sequence[str] | None = None,
        source: str = "",
        filename: str | None = None,
    ) -> tuple[AssetHistory, Diagnosis]:
        """Add a diagnosed recording: the new history, and the diagnosis with
        ``asset`` (an :class:`AssetState`) attached.

        Parameters
        ----------
        recording_id : str
            The recording's identifier. Already recorded: the same history comes back, with
            the diagnosis carrying the state stored then (nothing is counted twice).
        diagnosis : Diagnosis
            The recording's diagnosis.
        healthy : bool or None
            A label: True puts the recording in the baseline (at any time), False keeps it
            out; None lets the rule decide (it joins an incomplete baseline unless
            :func:`names_a_fault`). A recording not put in the baseline adds its class
            probabilities to the evidence and its distance to the CUSUM, unless its fault
            class was not observable (:func:`unobservable`: an OOD score above the limit, or
            observable in fewer than half its windows): then it adds neither, a warning says
            why, and it is recorded with its distance and changes all the same.
        operating_hours : float or None [h]
            The asset's operating hours at the recording, ≥ 0.
        time : str
            When it was recorded (ISO 8601), or "".
        prior_scale : mapping or None
            Indicator → within-unit repeatability (:meth:`Baseline.fit`).
        training_prior : mapping or None
            Class → training share of the classifier (:meth:`Evidence.update`); uniform when
            None or when it lacks one of the diagnosis's classes.
        names : sequence of str or None
            The indicators of the baseline (default: every one finite in all its recordings).
        source, filename : str
            How the recording came and its file name (:class:`AssetEntry`), kept for people.

        Returns
        -------
        (AssetHistory, Diagnosis)

        Raises
        ------
        ParameterError
            An empty recording id, negative or non-finite operating hours, a training prior
            that is not > 0.
        """
        require(
            isinstance(recording_id, str) and recording_id != "",
            "recording_id",
            recording_id,
            "a non-empty string",
        )
        require(
            operating_hours is None
            or (finite_or_none(operating_hours) is not None and operating_hours >= 0),
            "operating_hours",
            operating_hours,
            "a finite number of hours >= 0, or None",
        )
        stored = self.entry(recording_id)
        if stored is not None:
            note = (
                f"recording {recording_id} is already in the history of asset {self.asset_id}: "
                "its state as recorded then is shown, nothing was counted twice"
            )
            return self, dataclasses.replace(
                diagnosis, asset=stored.state, warnings=[*diagnosis.warnings, note]
            )

        baseline = self.baseline(prior_scale, names)
        indicators = {str(k): finite_or_none(v) for k, v in diagnosis.indicators.items()}
        changes, distance = {}, None
        if baseline is not None:
            changes = _by_size(baseline.change(indicators))
            distance = finite_or_none(baseline.distance(indicators))
        notes = []
        if healthy is None:
            in_baseline = baseline is None and not names_a_fault(diagnosis)
            if baseline is None and not in_baseline:
                notes.append(
                    f"not put in the baseline of asset {self.asset_id}: the diagnosis names "
                    f"{diagnosis.fault_class} with healthy ruled out; label the recording "
                    "healthy if it is"
                )
        else:
            in_baseline = bool(healthy)

        evidence, cusum = self.evidence, self.cusum
        probabilities = {str(k): float(v) for k, v in diagnosis.class_probabilities.items()}
        blind = None if in_baseline else unobservable(diagnosis)
        if blind is not None and (probabilities or baseline is not None):
            notes.append(
                f"added no class evidence and no change-statistic step to asset "
                f"{self.asset_id}: {blind}"
            )
        if not in_baseline and blind is None:
            if probabilities:
                if evidence is not None and set(evidence.classes) != set(probabilities):
                    notes.append(
                        f"the model's classes differ from those of asset {self.asset_id}'s "
                        f"evidence ({', '.join(evidence.classes)}): its evidence starts afresh"
                    )
                    evidence = None
                if evidence is None:
                    evidence = Evidence.start(tuple(probabilities))
                # a prior of another classifier's classes (a check model's, for a recording
                # read by the window model) does not apply: uniform
                prior = training_prior
                if prior is not None and any(c not in prior for c in probabilities):
                    prior = None
                evidence = evidence.update(probabilities, training_prior=prior)
            if baseline is not None:
                cusum = cusum.update(distance)
                if cusum.alarm:
                    notes.append(
                        f"asset {self.asset_id} has changed from its baseline: change "
                        f"statistic {cusum.statistic:.3g} above {cusum.threshold:g} "
                        "(CUSUM of the baseline distance)"
                    )

        members = len(self.members(names)) + in_baseline
        complete = members >= BASELINE_RECORDINGS
        if evidence is None and probabilities:
            shown = Evidence.start(tuple(probabilities))
        else:
            shown = evidence
        state = AssetState(
            asset_id=self.asset_id,
            baseline=BaselineState(
                recordings=members,
                needed=BASELINE_RECORDINGS,
                changes=changes,
                distance=distance,
            ),
            evidence=EvidenceState(
                recordings=0 if evidence is None else evidence.recordings,
                posterior={} if shown is None else shown.posterior(),
                fault_class=CANNOT_TELL if evidence is None else evidence.named(),
                change_statistic=cusum.statistic if complete else None,
                change_alarm=cusum.alarm,
            ),
        )
        entry = AssetEntry(
            recording_id=recording_id,
            time=str(time or ""),
            operating_hours=None if operating_hours is None else float(operating_hours),
            indicators=indicators,
            class_probabilities=probabilities,
            fault_class=diagnosis.fault_class,
            clearance=dict(diagnosis.clearance.to_json()),
            baseline=in_baseline,
            distance=distance,
            state=state,
            source=str(source or ""),
            filename=filename,
            healthy=healthy,
            design=diagnosis.model.design if diagnosis.model is not None else None,
        )
        history = dataclasses.replace(
            self, entries=(*self.entries, entry), evidence=evidence, cusum=cusum
        )
        return history, dataclasses.replace(
            diagnosis, asset=state, warnings=[*diagnosis.warnings, *notes]
        )

    def state(self) -> AssetState:
        """The asset's state after its last recording (an empty one before any)."""
        if self.entries:
            return self.entries[-1].state
        return AssetState(
            asset_id=self.asset_id,
            baseline=BaselineState(recordings=0, needed=BASELINE_RECORDINGS),
            evidence=EvidenceState(recordings=0),
        )

    def report(
        self,
        prior_scale: Mapping[str, float] | None = None,
        names: Sequence[str] | None = None,
    ) -> dict:
        """The asset in plain JSON values, for people and tables: its baseline (centre and
        scale per indicator once complete, as :meth:`baseline` fits it with ``prior_scale`` and
        ``names``), its evidence, its change statistic, and one row per recording (in the
        baseline?, distance, the leading class and its posterior then, the class named then)."""
        baseline = self.baseline(prior_scale, names)
        members = len(self.members(names))
        evidence = self.evidence
        rows = []
        for e in self.entries:
            told = e.state is not None and e.state.evidence is not None
            told = told and e.state.evidence.recordings > 0  # else the prior: no leader
            posterior = e.state.evidence.posterior if told else {}
            leading = max(posterior, key=posterior.get) if posterior else None
            rows.append(
                {
                    "recording_id": e.recording_id,
                    "source": e.source,
                    "filename": e.filename,
                    "time": e.time,
                    "operating_hours": e.operating_hours,
                    "baseline": e.baseline,
                    "distance": e.distance,
                    "fault_class": e.fault_class,
                    "leading_class": leading,
                    "leading_posterior": None if leading is None else posterior[leading],
                    "named": e.state.evidence.fault_class if e.state else CANNOT_TELL,
                    "change_statistic": e.state.evidence.change_statistic if e.state else None,
                }
            )
        return {
            "asset_id": self.asset_id,
            "recordings": len(self.entries),
            "baseline": {
                "recordings": members,
                "needed": BASELINE_RECORDINGS,
                "complete": baseline is not None,
                "indicators": {}
                if baseline is None
                else {
                    n: {"center": c, "scale": s}
                    for n, c, s in zip(baseline.names, baseline.center, baseline.scale)
                },
            },
            "evidence": {
                "recordings": 0 if evidence is None else evidence.recordings,
                "posterior": {} if evidence is None else evidence.posterior(),
                "fault_class": CANNOT_TELL if evidence is None else evidence.named(),
                "name_probability": EVIDENCE_NAME_PROBABILITY,
            },
            "change": self.cusum.to_json(),
            "entries": rows,
        }

    def to_json(self) -> dict:
        """Plain JSON values; :meth:`from_json` restores an equal history."""
        return {
            "format": FORMAT,
            "asset_id": self.asset_id,
            "entries": [e.to_json() for e in self.entries],
            "evidence": None if self.evidence is None else self.evidence.to_json(),
            "cusum": self.cusum.to_json(),
            "as_built_clearance": self.as_built_clearance,
        }

    @classmethod
    def from_json(cls, data: Mapping) -> AssetHistory:
        """The history of :meth:`to_json`'s values (:class:`ParameterError` for another
        format version)."""
        require(data.get("format") == FORMAT, "format", data.get("format"), f"{FORMAT}")
        evidence = data.get("evidence")
        return cls(
            data["asset_id"],
            tuple(AssetEntry.from_json(e) for e in data["entries"]),
            None if evidence is None else Evidence.from_json(evidence),
            Cusum.from_json(data["cusum"]),
            as_finite(data.get("as_built_clearance")),  # histories before it: None
        )


__all__ = [
    "ASSET_ID_PATTERN",
    "BASELINE_RECORDINGS",
    "HEALTHY",
    "OBSERVABLE_SHARE",
    "AssetEntry",
    "AssetHistory",
    "bundle_priors",
    "names_a_fault",
    "training_spread",
    "unobservable",
    "validate_asset_id",
]
