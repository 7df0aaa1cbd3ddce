"""The Diagnosis contract, declared once: :class:`Diagnosis` and its typed parts.

Every field carries its meaning (``metadata["description"]``, units in brackets).
:meth:`Diagnosis.to_json` walks these fields to make the JSON that the CLI prints, the service
answers and replay writes on ``/prsm/diagnosis``; the service's OpenAPI schema is generated
from the same fields (:func:`prsm_health.apps.service.schemas.contract_model`), so the field
list exists once. A field marked ``omit_empty`` is left out of the JSON when it is None or
empty (``window`` of a recording, ``windows`` of a window); every other field is always there,
``null`` where it has no value.

The parts (:class:`ClearanceInterval`, :class:`Observability`, :class:`ModelReference`,
:class:`WindowSpan`) are frozen and also read as the mappings they were before they had types
(``d.clearance["estimate"]``, ``d.observability.get("clearance")``, equality with a dict), so
code written against the dicts keeps working.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

#: The class of a window whose class the model cannot see (clearance hidden, channels missing,
#: indicators unlike the training set, or no class probable enough).
CANNOT_TELL = "cannot_tell"
#: Out-of-distribution score above which a window is unlike the training set
#: (``Diagnosis.ood_score``). The score is 1 at the 99th percentile of the training windows' own
#: scores; 1.5 leaves room for the held-out windows of the same recipe (models/MODEL_CARD.md:
#: the share of them above it).
OOD_LIMIT = 1.5


def describe(description: str, *, omit_empty: bool = False, **kwargs):
    """A dataclass field with its meaning (and whether JSON leaves it out when empty)."""
    return field(metadata={"description": description, "omit_empty": omit_empty}, **kwargs)


def contract_json(value):
    """Plain JSON values of a contract object: dataclasses by their fields (``omit_empty``
    fields left out when None or empty), lists and dicts item by item."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out = {}
        for f in dataclasses.fields(value):
            item = getattr(value, f.name)
            if f.metadata.get("omit_empty") and (
                item is None or (isinstance(item, (list, dict)) and not item)
            ):
                continue
            out[f.name] = contract_json(item)
        return out
    if isinstance(value, Mapping):
        return {k: contract_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [contract_json(v) for v in value]
    return value


class ContractPart(Mapping):
    """A frozen part of the contract, also readable as the mapping of its fields."""

    def __getitem__(self, key):
        if key not in self._names():
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self):
        return iter(self._names())

    def __len__(self):
        return len(self._names())

    @classmethod
    def _names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def of(cls, value):
        """``value`` as this part (a mapping of its fields is converted)."""
        return value if isinstance(value, cls) or value is None else cls(**value)

    def to_json(self) -> dict:
        return contract_json(self)


@dataclass(frozen=True, eq=False)
class ClearanceInterval(ContractPart):
    """The clearance estimate and its interval."""

    estimate: float | None = describe("thread half-clearance estimate [m]")
    lower: float | None = describe(
        "lower bound of the prediction interval (90 % for the shipped model) [m]; the lower end "
        "of the trained range where the clearance is not observable"
    )
    upper: float | None = describe(
        "upper bound of the prediction interval [m]; the upper end of the trained range where "
        "the clearance is not observable"
    )


@dataclass(frozen=True, eq=False)
class ReversalRead(ContractPart):
    """One reversal of a health check the clearance was measured from."""

    phase: str = describe("the phase's name")
    load: float = describe("its load amplitude [N]")
    lost_motion: float = describe("its lost motion over the settled samples [m]")


@dataclass(frozen=True, eq=False)
class MeasuredClearance(ContractPart):
    """A health check's clearance measured by physics (the reversals' lost motion through the
    actuator's compliance chain, docs/diagnostics.md "Clearance measured by physics"): the
    diagnosis' ``clearance`` then, with the learnt model's beside it as a cross-check."""

    zero_load_lost_motion: float = describe(
        "the lost motion extrapolated to zero load (two reversals) or read through the nominal "
        "chain (one) [m]"
    )
    stiffness_factor: float | None = describe(
        "the unit's elastic lost motion against the chain's, from the two reversals; null with "
        "one (the nominal chain)"
    )
    reversals: list[ReversalRead] = describe("the reversals read, heaviest first")
    commissioned: bool = describe(
        "whether the constant offset (bearing play, gearhead backlash, sensor lag) is the unit's "
        "own, fixed at commissioning from its as-built clearance; false: the datasheets' "
        "ranges, in the budget"
    )
    budget: dict[str, float] = describe(
        "error budget: term → its standard deviation [m of clearance]; the interval is their "
        "root sum square times a conformal factor"
    )
    learnt: ClearanceInterval | None = describe(
        "the learnt check model's clearance on the same recording (null without a check model)"
    )
    agree: bool | None = describe(
        "whether the measured and learnt intervals overlap (null without a learnt one); a "
        "warning says when they do not"
    )

    def __post_init__(self):
        # read back from JSON: the parts as mappings
        object.__setattr__(self, "reversals", [ReversalRead.of(r) for r in self.reversals])
        object.__setattr__(self, "learnt", ClearanceInterval.of(self.learnt))


@dataclass(frozen=True, eq=False)
class Observability(ContractPart):
    """Whether the recording lets the model see each target.

    Per window a bool; for a recording the fraction of its windows (0 … 1). A target is not
    observable where a warning says why."""

    clearance: bool | float = describe(
        "clearance: a load or motion reversal (the rollers cross the clearance), the model's "
        "channels, indicators like the training windows, and an interval narrower than the "
        "trained range. Per window a bool, for a recording the fraction of its windows"
    )
    fault: bool | float = describe(
        "fault class: the clearance observable (the wear classes differ by clearance) and the "
        "window like the training windows. Per window a bool, for a recording the fraction of "
        "its windows"
    )

    #: The targets, in field order.
    TARGETS: ClassVar[tuple[str, ...]] = ("clearance", "fault")


@dataclass(frozen=True, eq=False)
class ModelReference(ContractPart):
    """The model bundle that made the diagnosis."""

    name: str = describe("model name")
    version: str = describe("model version")
    design: str = describe("design the model was trained for")
    instrumentation: str | None = describe(
        "instrumentation profile of the training runs (null: not recorded in the bundle)",
        default=None,
    )


@dataclass(frozen=True, eq=False)
class WindowSpan(ContractPart):
    """Where a window lies in its recording."""

    index: int = describe("window number from 0")
    start: float = describe("time of the window's first sample from the recording start [s]")
    end: float = describe("time of the window's last sample [s]")


#: ``Undecided.kind`` of a class the recording could not show (a condition or channel missing).
NOT_OBSERVABLE = "not_observable"
#: ``Undecided.kind`` of a class the recording showed, with the classes not separated.
AMBIGUOUS = "ambiguous"


@dataclass(frozen=True, eq=False)
class Undecided(ContractPart):
    """Why the diagnosis names no class (``fault_class`` is ``cannot_tell``), and what to
    record next to decide."""

    kind: str = describe(
        f"{NOT_OBSERVABLE!r}: the recording could not show the class (a condition or channel "
        f"missing); {AMBIGUOUS!r}: it showed it, and the classes were not separated"
    )
    missing: list[str] = describe(
        "the conditions the recording lacked (e.g. 'load reversal', 'load ≥ 10 % of C_a', "
        "'steady segment', 'channel nut_position', 'health check'); empty when ambiguous",
        default_factory=list,
    )
    candidates: list[str] = describe(
        "the classes left (the class set) when ambiguous", default_factory=list
    )
    next_recording: str = describe(
        "the recording that would decide, in words a maintainer can act on", default=""
    )


@dataclass(frozen=True, eq=False)
class BaselineState(ContractPart):
    """A unit's own baseline and how far this recording lies from it."""

    recordings: int = describe("recordings in the unit's baseline")
    needed: int = describe("recordings a baseline needs before changes are scored")
    changes: dict[str, float] = describe(
        "indicator → robust z-score of this recording against the baseline (the largest |z| "
        "first); empty until the baseline is complete",
        default_factory=dict,
    )
    distance: float | None = describe(
        "combined change score against the baseline (RMS of the robust z-scores: 0 at the "
        "baseline's centre, about 1 for a recording like the baseline's; see docs/diagnostics.md)",
        default=None,
    )


@dataclass(frozen=True, eq=False)
class EvidenceState(ContractPart):
    """The class evidence accumulated over a unit's recordings."""

    recordings: int = describe("recordings whose evidence has accumulated")
    posterior: dict[str, float] = describe(
        "class → posterior probability after those recordings (sum 1)", default_factory=dict
    )
    fault_class: str = describe(
        f"the class whose posterior reaches the naming threshold, else {CANNOT_TELL!r}",
        default=CANNOT_TELL,
    )
    change_statistic: float | None = describe(
        "sequential change statistic of the baseline distance (CUSUM, docs/diagnostics.md)",
        default=None,
    )
    change_alarm: bool = describe(
        "the change statistic crossed its threshold: the unit has changed from its baseline",
        default=False,
    )


@dataclass(frozen=True, eq=False)
class AssetState(ContractPart):
    """The unit (asset) a recording belongs to: its baseline and accumulated evidence."""

    asset_id: str = describe("the asset's identifier")
    baseline: BaselineState | None = describe("its baseline", default=None)
    evidence: EvidenceState | None = describe("its accumulated evidence", default=None)

    def __post_init__(self):
        object.__setattr__(self, "baseline", BaselineState.of(self.baseline))
        object.__setattr__(self, "evidence", EvidenceState.of(self.evidence))


@dataclass(kw_only=True)
class Diagnosis:
    """The Diagnosis contract (docs/formats.md): of a window (with ``window``) or of a whole
    recording (with ``windows``).

    A recording's values: the clearance the medians over the windows where it was observable
    (over all windows if none), the class probabilities the means over the windows given a
    class, the indicators and OOD score the medians over the windows.
    """

    clearance: ClearanceInterval = describe("clearance estimate and interval [m]")
    fault_class: str | None = describe(
        "the most probable class when the window shows the fault and its probability reaches "
        f"0.5, else {CANNOT_TELL!r}; null without a fault model"
    )
    class_probabilities: dict[str, float] = describe(
        "class → calibrated probability (sum 1), given even with cannot_tell"
    )
    class_set: list[str] = describe(
        "classes the evidence cannot rule out (the model's conformal class set; every class "
        "where the fault is not observable)",
        default_factory=list,
    )
    observability: Observability = describe(
        "per target, whether the model can see it (window: bool; recording: fraction of windows)",
        default_factory=lambda: Observability(False, False),
    )
    ood_score: float | None = describe(
        "out-of-distribution score of the indicators (1 = the training windows' 99th "
        f"percentile; above {OOD_LIMIT:g} unlike the training set); a recording's is the median of its "
        "windows'",
        default=None,
    )
    indicators: dict[str, float | None] = describe(
        "condition indicators by name (units in prsm_health.signals.features.FEATURES); null "
        "where not computable"
    )
    indicator_groups: dict[str, str] = describe(
        "indicator group → 'computed', or why not", default_factory=dict
    )
    model: ModelReference = describe("the model bundle")
    warnings: list[str] = describe(
        "sentences a person can act on: why a target is not observable, a missing channel, a "
        "recording outside the trained range, a tail left undiagnosed",
        default_factory=list,
    )
    window: WindowSpan | None = describe(
        "the window's place in its recording (window diagnoses only)", omit_empty=True, default=None
    )
    windows: list[Diagnosis] = describe(
        "per-window diagnoses (recording diagnoses only)", omit_empty=True, default_factory=list
    )
    undecided: Undecided | None = describe(
        f"why fault_class is {CANNOT_TELL!r} and the recording that would decide (only then)",
        omit_empty=True,
        default=None,
    )
    measured_clearance: MeasuredClearance | None = describe(
        "a health check with a reversal under load: the clearance measured by physics (then "
        "``clearance``), its budget and the learnt model's reading beside it",
        omit_empty=True,
        default=None,
    )
    check_phases: dict[str, str] = describe(
        "a health-check recording: role → the phase that gave it (e.g. 'no_load' → 'no-load "
        "stroke'); the roles the check lacked are in undecided.missing or the warnings",
        omit_empty=True,
        default_factory=dict,
    )
    asset: AssetState | None = describe(
        "the unit the recording belongs to, when given: its baseline and accumulated evidence",
        omit_empty=True,
        default=None,
    )

    def __post_init__(self):
        # mappings accepted where a part is expected (code written before the parts had types)
        self.clearance = ClearanceInterval.of(self.clearance)
        self.observability = Observability.of(self.observability)
        self.model = ModelReference.of(self.model)
        self.window = WindowSpan.of(self.window)
        self.undecided = Undecided.of(self.undecided)
        self.asset = AssetState.of(self.asset)
        self.measured_clearance = MeasuredClearance.of(self.measured_clearance)

    def to_json(self) -> dict:
        """The Diagnosis contract as plain JSON values."""
        return contract_json(self)
