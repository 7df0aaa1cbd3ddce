"""A health check's diagnosis phase by phase: for each role a check is read for, the phase it was
read in, whether it was read, its readings (each with its unit and, against the unit's baseline,
its robust z-score) and the targets it shows (the clearance, the classes whose signature it
carries, with their probabilities).

:func:`check_verdicts` reads the Diagnosis **JSON** (``Diagnosis.to_json()`` or the service's
stored copy), so the CLI's figure (:mod:`prsm_health.apps.check_plot`) and the dashboard's
asset page show the same verdicts from the same numbers, and neither repeats which indicators
and classes belong to which role.
"""

from __future__ import annotations

from prsm_health.signals.check_indicators import CHECK_INDICATORS, ROLE_INDICATORS, ROLES

from .check_model import ROLE_CONDITION, ROLE_OF_CLASS

#: The role whose phase shows the clearance (the reversal: the lost motion).
CLEARANCE_ROLE = "reversal"


def check_verdicts(diagnosis: dict) -> list[dict] | None:
    """Each role of a check diagnosis, in :data:`ROLES` order; None for a diagnosis that is no
    check's (no ``check_phases``).

    Parameters
    ----------
    diagnosis : dict
        A Diagnosis as JSON (``check_phases``, ``indicators``, ``class_probabilities``,
        ``clearance``, ``observability`` and, diagnosed under an asset id, ``asset``).

    Returns
    -------
    list of dict
        ``{"role", "condition", "phase", "read", "readings", "classes", "clearance"}``:
        ``phase`` the phase name(s) the role was read in (None: the check lacks the
        condition); ``read`` whether any of its indicators has a value; ``readings`` a list
        of ``{"name", "value", "unit", "z"}`` (value None: not read; z None: no complete
        baseline); ``classes`` class → probability of the classes the role's phase shows;
        ``clearance`` the clearance interval for the reversal when observable, else None.
    """
    phases = diagnosis.get("check_phases") or {}
    if not phases:
        return None
    indicators = diagnosis.get("indicators") or {}
    asset = diagnosis.get("asset") or {}
    changes = (asset.get("baseline") or {}).get("changes") or {}
    probabilities = diagnosis.get("class_probabilities") or {}
    seen = (diagnosis.get("observability") or {}).get("clearance")
    out = []
    for role in ROLES:
        readings = [
            {
                "name": name,
                "value": indicators.get(name),
                "unit": CHECK_INDICATORS[name],
                "z": changes.get(name),
            }
            for name in ROLE_INDICATORS[role]
        ]
        out.append(
            {
                "role": role,
                "condition": ROLE_CONDITION[role],
                "phase": phases.get(role),
                "read": role in phases and any(r["value"] is not None for r in readings),
                "readings": readings,
                "classes": {c: p for c, p in probabilities.items() if ROLE_OF_CLASS.get(c) == role},
                "clearance": diagnosis.get("clearance")
                if role == CLEARANCE_ROLE and seen
                else None,
            }
        )
    return out
