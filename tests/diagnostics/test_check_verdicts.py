"""A check diagnosis phase by phase (:func:`prsm_health.diagnostics.check_verdicts`): each role's
phase, readings, baseline z-scores and targets come from the diagnosis JSON."""

from prsm_health.diagnostics.check_model import ROLE_OF_CLASS
from prsm_health.diagnostics.check_verdicts import check_verdicts
from prsm_health.signals.check_indicators import CHECK_INDICATORS, ROLE_INDICATORS, ROLES


def diagnosis(**given):
    base = {
        "check_phases": {"no_load": "quiet", "torque_pair": "slow / fast", "reversal": "swing"},
        "indicators": {name: float(k) for k, name in enumerate(CHECK_INDICATORS)},
        "class_probabilities": {"healthy": 0.6, "wear": 0.2, "spall": 0.1, "lubrication": 0.1},
        "clearance": {"estimate": 10e-6, "lower": 8e-6, "upper": 12e-6},
        "observability": {"clearance": True, "fault": False},
    }
    return {**base, **given}


def test_a_window_diagnosis_has_none():
    assert check_verdicts({"indicators": {}, "check_phases": {}}) is None
    assert check_verdicts({"indicators": {}}) is None


def test_each_role_its_phase_readings_and_targets():
    d = diagnosis()
    d["indicators"] = {**d["indicators"], **dict.fromkeys(ROLE_INDICATORS["high_load"])}
    verdicts = {v["role"]: v for v in check_verdicts(d)}
    assert list(verdicts) == list(ROLES)
    assert verdicts["torque_pair"]["phase"] == "slow / fast" and verdicts["no_load"]["read"]
    # the check lacks the high-load condition: no phase, not read, its class still shown
    high = verdicts["high_load"]
    assert high["phase"] is None and not high["read"]
    assert high["classes"] == {"spall": 0.1}
    assert verdicts["reversal"]["classes"] == {"wear": 0.2}
    assert verdicts["reversal"]["clearance"] == d["clearance"]
    assert verdicts["no_load"]["clearance"] is None
    for role, verdict in verdicts.items():
        assert [r["name"] for r in verdict["readings"]] == list(ROLE_INDICATORS[role])
        assert all(r["unit"] == CHECK_INDICATORS[r["name"]] for r in verdict["readings"])
        assert all(r["z"] is None for r in verdict["readings"])  # read alone
        assert set(verdict["classes"]) == {
            c for c in d["class_probabilities"] if ROLE_OF_CLASS.get(c) == role
        }


def test_against_the_baseline_the_z_scores_and_a_hidden_clearance():
    changes = {"check_reversal_lost_motion": 3.5, "check_noload_centroid": -1.25}
    d = diagnosis(
        asset={"baseline": {"recordings": 3, "needed": 3, "changes": changes}},
        observability={"clearance": False, "fault": True},
    )
    readings = {r["name"]: r for v in check_verdicts(d) for r in v["readings"]}
    assert {k: readings[k]["z"] for k in changes} == changes
    assert readings["check_torque_ratio"]["z"] is None  # not among the baseline's changes
    reversal = next(v for v in check_verdicts(d) if v["role"] == "reversal")
    assert reversal["clearance"] is None  # not observable: no interval shown as a reading
