"""An asset's status at a glance — ``healthy``, ``unknown``, ``watch`` or ``alarm`` — with the
reasons, from
what the store keeps of it: its evidence and change statistic after its latest recording, its
baseline, and its latest diagnosis's class. The one rule the fleet page shows
(docs/service.md, Dashboard); the page only displays it.

* **alarm**: the change statistic crossed its threshold (the asset has changed from its own
  baseline), or the accumulated evidence names a fault (its posterior reached the naming
  threshold);
* **watch**: the change statistic above half its threshold (a change building up), the
  evidence's most probable class a fault though not yet named, or the latest diagnosis naming a
  fault class (one recording: the evidence has not confirmed it);
* **healthy**: none of these, and something says healthy — the evidence names it or leans to
  it, or the latest diagnosis names it; said with its limits (the reasons say so while the
  baseline is incomplete or before any evidence has accumulated);
* **unknown**: none of these, and nothing says healthy either (the diagnoses could not tell
  the class, no evidence yet): the page says "cannot tell" and what to record next, never
  "healthy" for an asset nothing has shown to be.
"""

from __future__ import annotations

from collections.abc import Mapping

from prsm_health.diagnostics.contract import CANNOT_TELL

from .asset import HEALTHY

#: The status levels, from the best to the worst.
LEVELS = ("healthy", "unknown", "watch", "alarm")
#: A change statistic above this share of its threshold puts the asset on watch.
WATCH_SHARE = 0.5


def _is_fault(name) -> bool:
    return name not in (None, CANNOT_TELL, HEALTHY)


def asset_status(
    evidence: Mapping | None, baseline: Mapping | None, latest_class: str | None
) -> dict:
    """The asset's status: ``{"level": one of LEVELS, "reasons": [text, …]}``.

    Parameters
    ----------
    evidence : mapping or None
        Its evidence after its latest recording (``fault_class``, ``posterior``,
        ``change_statistic``, ``change_alarm``, ``change_threshold``; the service's
        ``/v1/assets`` ``evidence``); None: no recording judged against a baseline yet.
    baseline : mapping or None
        ``recordings`` and ``needed``.
    latest_class : str or None
        The latest diagnosis's ``fault_class``.
    """
    alarm, watch, notes = [], [], []
    evidence = evidence or {}
    statistic = evidence.get("change_statistic")
    threshold = evidence.get("change_threshold")
    if evidence.get("change_alarm"):
        alarm.append("changed from its baseline (change alarm)")
    elif statistic is not None and threshold and statistic > WATCH_SHARE * threshold:
        watch.append(
            f"change statistic {statistic:.3g} above {WATCH_SHARE:g} of its threshold "
            f"{threshold:.3g}"
        )
    named = evidence.get("fault_class")
    posterior = evidence.get("posterior") or {}
    if _is_fault(named):
        alarm.append(f"evidence names {named}")
    elif posterior:
        top = max(posterior, key=posterior.get)
        if _is_fault(top):
            watch.append(f"evidence leans to {top} ({posterior[top]:.2f}), not yet named")
    if _is_fault(latest_class):
        watch.append(f"latest diagnosis names {latest_class}")
    if baseline is None:
        notes.append("no baseline yet: no change scored")
    elif baseline.get("needed") is not None and baseline["recordings"] < baseline["needed"]:
        notes.append(
            f"baseline {baseline['recordings']} of {baseline['needed']}: no change scored yet"
        )
    elif evidence.get("recordings") == 0:
        notes.append("no evidence accumulated yet (the baseline's recordings add none)")
    if latest_class == CANNOT_TELL:
        notes.append("the latest diagnosis cannot tell the class")
    top = max(posterior, key=posterior.get) if posterior and evidence.get("recordings") else None
    says_healthy = HEALTHY in (named, top, latest_class)
    if alarm or watch:
        level = "alarm" if alarm else "watch"
    elif says_healthy:
        level = "healthy"
    else:
        level = "unknown"
        notes.append("record next: health checks of the unit (its baseline, then evidence)")
    return {"level": level, "reasons": alarm + watch + notes}
