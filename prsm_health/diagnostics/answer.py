"""From class probabilities to the answer a maintainer acts on: a named class, the classes the
evidence cannot rule out, or ``cannot_tell`` — and then why, and what to record next.

A diagnosis cannot tell for one of two reasons, which call for different actions
(:class:`~prsm_health.diagnostics.contract.Undecided`):

* **not observable** — the recording could not show the class: a condition the signature needs
  was absent (no load or motion reversal, no steady segment at speed, too little load), a channel
  is missing, or the recording is unlike anything the model was trained on. Recording it again
  the same way will not help; :func:`not_observable` names the missing conditions and the
  recording that has them.
* **ambiguous** — the recording showed it, and the classes were not separated (no class reaches
  :data:`NAME_PROBABILITY`, or the class set holds several). :func:`ambiguous` names the classes
  left and the recording that separates them (:data:`DECIDING_RECORDING`): usually the phase of
  the health check built for that signature, or more recordings of the same unit against its
  baseline (evidence accumulates: :mod:`prsm_health.diagnostics.baseline`).
"""

from __future__ import annotations

from .contract import AMBIGUOUS, CANNOT_TELL, NOT_OBSERVABLE, Undecided

#: A class is named when its calibrated probability reaches this: more probable than all the
#: others together, so the named class is right more often than not (calibration figure of the
#: model card); below it the answer is ``cannot_tell`` with the candidates in a warning.
NAME_PROBABILITY = 0.5
#: How the class-set part of a fault-class warning begins.
SET_NOTE = "not ruled out at "

#: What brings out the recirculating PRSM's own faults: its resets' comb at one commanded load.
_RESET_COMB_RECORDING = (
    "a steady stroke at a commanded load against the unit's own baseline (the "
    "recirculating-check's high-load stroke: the reset comb's shape)"
)
#: The recording that brings out each class's signature (docs/faults.md "At realistic duty",
#: the built-in health check of :mod:`prsm_health.actuator.health_check`).
DECIDING_RECORDING = {
    "healthy": "the health check (every phase: its signatures all read healthy)",
    "wear": "a slow load reversal under load (the health check's slow reversal at ±25 % C_a: "
    "lost motion)",
    "severe_wear": "a slow load reversal under load (the health check's slow reversal at "
    "±25 % C_a: lost motion)",
    "preload_loss": "a stroke without load (the health check's no-load stroke: the nut's "
    "axial resonance) and a slow reversal (lost motion)",
    "lubrication": "the drive torque at two speeds under one load (the health check's low- and "
    "high-speed strokes), with the housing temperature",
    "spall": "a steady stroke at the highest load on the service flanks (the health check's "
    "high-load stroke: synchronous averages at the nut-pass and roller-spin periods)",
    "tooth_damage": "none the instrumentation can give: a damaged ring or roller-gear tooth "
    "changes the nut vibration below the accelerometer's noise (docs/faults.md)",
    "cam_ring": _RESET_COMB_RECORDING,
    "reentry_edge": _RESET_COMB_RECORDING,
}
#: What to record when the recording lacked a condition: the health check does all of them.
RUN_THE_CHECK = (
    "run the health check (prsm-health simulate --profile health-check shows it; "
    "recirculating-check for a recirculating PRSM)"
)


def not_observable(missing: list[str], *, has_check: bool) -> Undecided:
    """The answer of a recording that could not show the class: the missing conditions and,
    where the model reads health checks, the check (which has them all)."""
    wanted = ", ".join(missing) if missing else "a recording like the training recordings"
    advice = (
        f"{RUN_THE_CHECK}; or a recording with {wanted}"
        if has_check
        else f"a recording with {wanted}"
    )
    return Undecided(kind=NOT_OBSERVABLE, missing=list(missing), next_recording=advice)


def ambiguous(candidates: list[str], *, baseline: bool, check: bool) -> Undecided:
    """The answer of a recording that showed the class without separating ``candidates``:
    the recording that separates them (:data:`DECIDING_RECORDING`) — for a health check
    already recorded, more checks of the unit against its own baseline."""
    if check:
        advice = (
            "another health check of this unit: the evidence accumulates over its recordings"
            if baseline
            else "the unit's baseline (three health checks while it is known healthy), then "
            "its checks are read against it"
        )
    else:
        wanted = [DECIDING_RECORDING[c] for c in candidates if c in DECIDING_RECORDING]
        advice = "; ".join(dict.fromkeys(wanted)) or RUN_THE_CHECK
    return Undecided(kind=AMBIGUOUS, candidates=list(candidates), next_recording=advice)


def fault_answer(
    probabilities: dict, observable: bool, classifier, notes: list
) -> tuple[str | None, list[str]]:
    """(fault class, class set) of class probabilities, and a warning when the set holds more
    than the named class or no class is named.

    The class is named when the fault is observable and its probability reaches
    :data:`NAME_PROBABILITY`; otherwise ``cannot_tell``. The class set (the classifier's
    conformal set) lists what the evidence cannot rule out: where the instrumentation cannot
    tell classes apart, their held-out probabilities overlap and the set holds them all."""
    from .estimators import class_sets  # scikit-learn only when a model is used

    if not probabilities:
        return None, []
    names = list(probabilities)
    if not observable:
        return CANNOT_TELL, names
    best = max(probabilities, key=probabilities.get)
    thresholds = getattr(classifier, "set_thresholds_", None)
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
    coverage = float(getattr(classifier, "set_coverage", 0.9))
    notes.append(
        f"{head}; {SET_NOTE}{100 * coverage:.0f} %: {', '.join(others)}"
        + (f"; ruled out: {', '.join(ruled_out)}" if ruled_out else "")
    )
    return (best if named else CANNOT_TELL), members
