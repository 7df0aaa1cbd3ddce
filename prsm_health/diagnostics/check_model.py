"""Diagnosis of a health-check recording: each phase read for what it can show, one answer for
the check, and — for a unit with a baseline — its indicators read as change against it.

A check recording (``run.check_phase``; :mod:`prsm_health.actuator.health_check`) is not cut
into windows: :func:`prsm_health.signals.check_indicators.check_indicators` finds its phases by
their commanded condition (no-load stroke, torque at two speeds under one load, slow reversal
under load, the highest-load stroke) and reads each for its signature; the model bundle's
``check`` part (:class:`CheckModel`, trained by :mod:`prsm_health.training.check_training`)
turns them into a clearance with its interval and class probabilities:

* **alone** — one recording, absolute indicators (``fault``);
* **against the unit's baseline** — the same indicators plus each one's robust z-score against
  the unit's own baseline (:class:`~prsm_health.diagnostics.baseline.Baseline`, fitted on its
  first check recordings; ``fault_relative``): healthy units differ from each other more than a
  young fault changes one of them, so the change against itself is what shows the fault.

Classes a check cannot show (:attr:`CheckModel.not_observable`, measured) are named as such in
the warnings with the measured reason, never merged silently into another class.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from prsm_health.core.jsonable import finite_or_none
from prsm_health.core.run import Run

from .answer import ambiguous, fault_answer, not_observable
from .contract import (
    CANNOT_TELL,
    ClearanceInterval,
    Diagnosis,
    MeasuredClearance,
    Observability,
    ReversalRead,
)

#: Prefix of a change feature: the robust z-score of an indicator against the unit's baseline.
CHANGE_PREFIX = "z_"
#: The phases (roles) each class's signature needs: without one, the class is not observable.
ROLE_OF_CLASS = {
    "wear": "reversal",
    "severe_wear": "reversal",
    "preload_loss": "no_load",
    "lubrication": "torque_pair",
    "spall": "high_load",
}
#: The condition each role stands for, in the words of ``Undecided.missing``.
ROLE_CONDITION = {
    "no_load": "a constant-speed phase without load",
    "torque_pair": "two constant-speed phases under one load at different speeds",
    "reversal": "a slow reversal under load",
    "high_load": "a constant-speed phase at ≥ 20 % of C_a",
}


@dataclass(frozen=True)
class CheckModel:
    """The ``check`` part of a model bundle (a dict in the model file, read by
    :meth:`from_part`).

    Attributes
    ----------
    feature_names : tuple of str
        The check indicators the models read.
    clearance : ClearanceEstimator
    fault : FaultClassifier
        One recording alone.
    fault_relative : FaultClassifier or None
        The indicators and their change against the unit's baseline (:data:`CHANGE_PREFIX`).
    repeatability : dict
        Indicator → its within-unit scatter between check recordings of a healthy unit (the
        baseline's prior scale).
    training_prior : dict
        Class → its share of the training recordings (the classifiers' prior: evidence
        accumulation divides it out).
    not_observable : dict
        Class → why a check cannot show it (measured).
    baseline_only : dict
        Class → why one check alone cannot show it, though its change against the unit's
        baseline does (measured): ``fault_relative`` knows the class, ``fault`` does not.
    clearance_range : (float, float) [m]
    """

    feature_names: tuple[str, ...]
    clearance: object
    fault: object
    fault_relative: object | None
    repeatability: dict
    training_prior: dict
    not_observable: dict
    clearance_range: tuple[float, float]
    baseline_only: dict = field(default_factory=dict)

    @classmethod
    def from_part(cls, part: dict) -> CheckModel:
        return cls(
            tuple(part["feature_names"]),
            part.get("clearance"),
            part.get("fault"),
            part.get("fault_relative"),
            dict(part.get("repeatability", {})),
            dict(part.get("training_prior", {})),
            dict(part.get("not_observable", {})),
            tuple(part.get("clearance_range", (math.nan, math.nan))),
            dict(part.get("baseline_only", {})),
        )

    def relative_names(self) -> list[str]:
        return [*self.feature_names, *(CHANGE_PREFIX + n for n in self.feature_names)]


def is_check(run: Run) -> bool:
    """Whether ``run`` is a health-check recording (its phases known)."""
    return run.check_phase is not None and run.check is not None


def check_reading(run: Run, design):
    """The check indicators of ``run`` (:func:`prsm_health.signals.check_indicators.check_indicators`)."""
    from prsm_health.signals.check_indicators import check_indicators

    return check_indicators(run, design)


def change_row(row: dict, baseline, names) -> dict:
    """The indicators of ``row`` and their change against ``baseline`` (robust z-scores,
    :data:`CHANGE_PREFIX`; NaN without a baseline)."""
    z = baseline.change(row) if baseline is not None else {}
    out = {n: row.get(n, math.nan) for n in names}
    out.update({CHANGE_PREFIX + n: z.get(n, math.nan) for n in names})
    return out


def _matrix(rows: list[dict], names: list[str]):
    import pandas as pd

    values = np.array([[_number(r.get(n)) for n in names] for r in rows], dtype=float)
    # from an array with an object column index: pandas' inference over lists of floats and
    # its default (Arrow strings) index cost more than the check model's predictions
    return pd.DataFrame(values, columns=pd.Index(names, dtype=object), copy=False)


def _number(value) -> float:
    return math.nan if value is None else float(value)


def baseline_only_note(cls: str, reason: str) -> str:
    """The note of a class one check alone cannot show but the unit's baseline can, saying
    how to get that reading."""
    return (
        f"not observable by one check alone: {cls} — {reason}; against this unit's baseline "
        "(its first health checks) it is observable: diagnose the unit's checks under its "
        "asset id (diagnose --asset ID, or the service's asset_id) to read them against it"
    )


def measured_clearance(reading, bundle, commissioning, learnt, notes: list[str], indicators: dict):
    """(the clearance measured by physics, its contract part) from a check's reversals
    (:mod:`~prsm_health.diagnostics.clearance_gauge`), the learnt reading ``learnt`` (a
    :class:`ClearanceInterval` or None) beside it; (None, None) without a reversal or a
    design. Adds to ``notes`` why a reversal was not read, the gauge's own notes, a
    disagreement with the learnt reading and, not commissioned, how to narrow the interval;
    to ``indicators`` the gauge's (:data:`~.clearance_gauge.GAUGE_INDICATORS`)."""
    gauge = bundle.clearance_gauge
    if gauge is None or not reading.reversals:
        return None, None
    measured = gauge.read(reading.reversals, commissioning)
    indicators.update(measured.indicators())
    for phase, why in reading.unread_reversals.items():
        notes.append(
            f'reversal "{phase}" not read ({why}): the clearance is measured from '
            f"{len(measured.reversals)} reversal(s)"
            + ("" if measured.stiffness_factor is not None else ", through the nominal chain")
        )
    notes.extend(measured.notes)
    clearance = ClearanceInterval(measured.estimate, measured.lower, measured.upper)
    agree = None
    if learnt is not None and learnt.estimate is not None:
        agree = bool(learnt.lower <= measured.upper and measured.lower <= learnt.upper)
        if not agree:
            notes.append(
                f"measured clearance {_um(measured.estimate)} [{_um(measured.lower)}, "
                f"{_um(measured.upper)}] µm and the learnt model's {_um(learnt.estimate)} "
                f"[{_um(learnt.lower)}, {_um(learnt.upper)}] µm disagree beyond their intervals: "
                "the measured one is the actuator's physics, the learnt one what the training "
                "fleet taught — a unit unlike that fleet, or a sensor to check"
            )
    if not measured.commissioned:
        notes.append(
            f"clearance measured without this unit's commissioning: its interval holds the "
            f"datasheets' ranges of bearing play and gearhead backlash (±"
            f"{_um(measured.upper - measured.estimate)} µm); give the as-built clearance once "
            "(diagnose --asset ID --as-built-clearance B) to narrow it"
        )
    part = MeasuredClearance(
        zero_load_lost_motion=measured.zero_load_lost_motion,
        stiffness_factor=measured.stiffness_factor,
        reversals=[ReversalRead(p, load, lost) for p, load, lost in measured.reversals],
        commissioned=measured.commissioned,
        budget=dict(measured.budget),
        learnt=learnt,
        agree=agree,
    )
    return clearance, part


#: The indicators physics reads from a check without a trained model: the lubricant's torque
#: ratio and the housing temperature (and the measured clearance).
PHYSICS_INDICATORS = (
    "check_torque_low",
    "check_torque_high",
    "check_torque_ratio",
    "check_temperature",
)


def read_check_by_physics(run: Run, bundle, diagnosis: Diagnosis, commissioning=None) -> None:
    """What a check shows without a trained check part, into ``diagnosis`` (of its windows):
    the clearance measured from its reversals (then ``clearance``, observable) and the
    physics indicators (:data:`PHYSICS_INDICATORS`, :data:`ZERO_LOAD_LOST_MOTION`)."""
    if bundle.design is None:
        return
    reading = check_reading(run, bundle.design)
    notes: list[str] = []
    clearance, measured = measured_clearance(
        reading, bundle, commissioning, None, notes, diagnosis.indicators
    )
    for name in PHYSICS_INDICATORS:
        diagnosis.indicators[name] = finite_or_none(reading.indicators.get(name))
    if measured is not None:
        diagnosis.clearance = clearance
        diagnosis.measured_clearance = measured
        # a recording's observability is a share of its windows: the check shows it whole
        diagnosis.observability = Observability(1.0, diagnosis.observability.fault)
    diagnosis.warnings.extend(notes)


def _um(value: float) -> str:
    return f"{value * 1e6:.1f}"


def cut_note(cut: dict[str, str], classes, clearance_read: bool = False) -> str:
    """The one line of a check whose phases are cut short or too short to read (``cut``: role
    → its shortfall, :attr:`CheckReading.cut
    <prsm_health.signals.check_indicators.CheckReading.cut>`): which phases, how long against
    what they need, what that hides (the clearance unless another reversal measured it —
    ``clearance_read`` —, and those of ``classes`` whose role is cut), what to do."""
    hidden = (
        ["the clearance (its interval is the whole trained range)"]
        if "reversal" in cut and not clearance_read
        else []
    )
    hidden += [c for c, r in ROLE_OF_CLASS.items() if r in cut and c in classes]
    shortfalls = "; ".join(dict.fromkeys(cut.values()))
    return (
        f"check cut short — not read: {shortfalls}; so not observable: "
        f"{', '.join(hidden) or 'nothing the model reads'}; record the whole check"
    )


def diagnose_check(run: Run, bundle, baseline=None, commissioning=None) -> Diagnosis:
    """Diagnosis of one health-check recording by the bundle's check model.

    Parameters
    ----------
    run : Run
        A check recording (:func:`is_check`), without truth.
    bundle : ModelBundle
        With a ``check`` part.
    baseline : Baseline or None
        The unit's own baseline: the change model reads the recording against it.
    commissioning : Commissioning or None
        The unit's constant lost motion fixed at commissioning
        (:class:`~prsm_health.diagnostics.clearance_gauge.Commissioning`): the measured
        clearance then reads against it.
    """
    model = CheckModel.from_part(bundle.check)
    reading = check_reading(run, bundle.design)
    row = dict(reading.indicators)
    names = list(model.feature_names)
    notes: list[str] = []
    missing_channels = bundle.missing_channels(tuple(run.channels))
    if missing_channels:
        notes.append(
            f"channel(s) {', '.join(missing_channels)} missing: the check model was trained "
            f"with them; their indicators are NaN"
        )
    for role, reason in reading.missing.items():
        if role not in reading.cut:  # a cut phase has its own line
            notes.append(f"check phase missing ({ROLE_CONDITION.get(role, role)}): {reason}")
    # clearance: the reversal shows it
    sees_clearance = "reversal" in reading.roles and "nut_position" not in missing_channels
    x = _matrix([row], names)
    estimate = float(model.clearance.predict(x)[0])
    lower, upper = (float(a[0]) for a in model.clearance.predict_interval(x))
    learnt = ClearanceInterval(finite_or_none(estimate), lower, upper) if sees_clearance else None
    clearance, measured = measured_clearance(reading, bundle, commissioning, learnt, notes, row)
    if clearance is None:
        clearance = ClearanceInterval(finite_or_none(estimate), lower, upper)
        if not sees_clearance:
            clearance = ClearanceInterval(finite_or_none(estimate), *model.clearance_range)
            if "reversal" not in reading.cut:
                notes.append(
                    "no slow reversal under load in this check: clearance is not observable; "
                    "the interval is the whole trained range"
                )
    sees_clearance = sees_clearance or measured is not None
    relative = baseline is not None and model.fault_relative is not None
    if relative:
        classifier = model.fault_relative
        x_fault = _matrix([change_row(row, baseline, names)], model.relative_names())
    else:
        classifier = model.fault
        x_fault = x
    classes = [str(c) for c in classifier.classes_]
    if reading.cut:  # the first line: what to fix first
        notes.insert(0, cut_note(reading.cut, classes, clearance_read=measured is not None))
    probabilities = {
        c: float(p) for c, p in zip(classes, np.asarray(classifier.predict_proba(x_fault))[0])
    }
    absent_roles = [r for r in ROLE_CONDITION if r not in reading.roles]
    blind = [c for c, r in ROLE_OF_CLASS.items() if r in absent_roles and c in probabilities]
    observable = not blind and not missing_channels
    fault_class, class_set = fault_answer(probabilities, observable, classifier, notes)
    undecided = None
    if fault_class == CANNOT_TELL:
        if not observable:
            conditions = [ROLE_CONDITION[r] for r in absent_roles]
            conditions += [f"channel {c}" for c in missing_channels]
            undecided = not_observable(conditions, has_check=True)
            notes.append(
                f"fault class: cannot tell — this check cannot show {', '.join(blind)}"
                if blind
                else "fault class: cannot tell — channel(s) missing"
            )
        else:
            undecided = ambiguous(class_set, baseline=relative, check=True)
    for cls, reason in model.not_observable.items():
        notes.append(f"not observable by this check: {cls} — {reason}")
    if not relative:
        notes += [baseline_only_note(cls, reason) for cls, reason in model.baseline_only.items()]
    if baseline is None and model.fault_relative is not None:
        notes.append(
            "read alone: no baseline of this unit (its first health checks); against a "
            "baseline the change of each indicator is read too"
        )
    return Diagnosis(
        clearance=clearance,
        fault_class=fault_class,
        class_probabilities=probabilities,
        class_set=class_set,
        indicators={k: finite_or_none(v) for k, v in row.items()},
        model=bundle.model_reference(),
        warnings=notes,
        observability=Observability(sees_clearance, observable),
        ood_score=None,
        indicator_groups={},
        undecided=undecided,
        check_phases=dict(reading.roles),
        measured_clearance=measured,
    )
