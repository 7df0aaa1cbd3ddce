"""What a diagnosis shows of a target the model could not see: one rule for the CLI's tables,
replay's lines and the figures (the dashboard applies the same rule to the same JSON fields in
``static/dashboard/common.js``: ``PH.observable``, ``PH.notObservableText``).

A Diagnosis carries its numbers whether or not the recording let the model see the target
(``observability``): where it did not, the clearance interval is the whole trained range and
the class probabilities are those of a window the classes do not differ in. Printed like the
others they read as a reading ("clearance 4.7 [0.1, 39.3] µm", "P(spall) 0.42"), so they are
shown as "not observable", with why where the diagnosis says (``undecided.missing``) and the
clearance interval only as context, marked.
"""

from __future__ import annotations

from collections.abc import Mapping

from . import contract

#: What is shown instead of a target's numbers.
NOT_OBSERVABLE = "not observable"


def part(diagnosis, name: str):
    """A field of a Diagnosis, of its JSON, or of an object with its fields (None if absent)."""
    if isinstance(diagnosis, Mapping):
        return diagnosis.get(name)
    return getattr(diagnosis, name, None)


def observable(diagnosis, target: str) -> bool:
    """Whether a diagnosis' ``target`` (``clearance`` or ``fault``) is shown as numbers.

    Yes where the model saw it: in the window, or in any window of a recording (the
    recording's value is then of those windows alone); and a clearance a health check measured
    by physics. A diagnosis without ``observability`` (an answer stored before it was kept)
    is shown as it was."""
    if target == "clearance" and part(diagnosis, "measured_clearance"):
        return True
    seen = (part(diagnosis, "observability") or {}).get(target)
    return seen is None or bool(seen)


def why(diagnosis) -> str:
    """Why the recording could not show its targets, in a few words: the conditions it lacked
    (``undecided.missing``), or "" where the diagnosis names none (its warnings say why)."""
    undecided = part(diagnosis, "undecided")
    if undecided is None or part(undecided, "kind") != contract.NOT_OBSERVABLE:
        return ""
    missing = part(undecided, "missing") or []
    return f"needs {', '.join(missing)}" if missing else ""


def not_observable_text(diagnosis, target: str) -> str | None:
    """The text shown instead of ``target``'s numbers (the clearance with its interval as
    context, marked); None where it is observable: then the numbers are shown."""
    if observable(diagnosis, target):
        return None
    reason = why(diagnosis)
    text = f"{NOT_OBSERVABLE} — {reason}" if reason else NOT_OBSERVABLE
    if target == "clearance":
        c = part(diagnosis, "clearance") or {}
        lower, upper = c.get("lower"), c.get("upper")
        if lower is not None and upper is not None:
            text += f" (interval {1e6 * lower:.1f}–{1e6 * upper:.1f} µm)"
    return text


#: What :func:`shown` says of a target the model saw.
OBSERVABLE = "observable"


def shown(diagnosis) -> dict:
    """What a plot may draw of a diagnosis (the ``shown`` object of the ``/prsm/diagnosis``
    messages that Foxglove plots, docs/live.md): the clearance and its interval [m] and the
    class probabilities where the model saw them, null where it did not — a gap in a plot,
    never a number — and each target's state in words (:data:`OBSERVABLE`, or
    :func:`not_observable_text`). The keys are always there (a schema inferred from one
    message holds for all)."""
    c = part(diagnosis, "clearance") or {}  # a ClearanceInterval is a Mapping too
    seen_clearance, seen_fault = observable(diagnosis, "clearance"), observable(diagnosis, "fault")
    probabilities = part(diagnosis, "class_probabilities") or {}
    return {
        "clearance": c.get("estimate") if seen_clearance else None,
        "clearance_lower": c.get("lower") if seen_clearance else None,
        "clearance_upper": c.get("upper") if seen_clearance else None,
        "clearance_state": not_observable_text(diagnosis, "clearance") or OBSERVABLE,
        "class_probabilities": {k: (p if seen_fault else None) for k, p in probabilities.items()},
        "fault_state": not_observable_text(diagnosis, "fault") or OBSERVABLE,
    }


def diagnosis_message(diagnosis_json: dict) -> dict:
    """A ``/prsm/diagnosis`` message (replay's MCAP, the live view): the Diagnosis contract's
    JSON and, beside it, what a plot may draw of it (:func:`shown`)."""
    return {**diagnosis_json, "shown": shown(diagnosis_json)}
