"""The asset status rule (healthy / unknown / watch / alarm) of the fleet page: each branch of
:func:`prsm_health.monitoring.status.asset_status` on the evidence the store keeps."""

import pytest

from prsm_health.monitoring.status import LEVELS, WATCH_SHARE, asset_status

BASELINE = {"recordings": 3, "needed": 3}


def evidence(**given):
    state = {
        "recordings": 4,
        "posterior": {"healthy": 0.9, "spall": 0.1},
        "fault_class": "cannot_tell",
        "change_statistic": 0.0,
        "change_alarm": False,
        "change_threshold": 5.0,
    }
    return {**state, **given}


@pytest.mark.parametrize(
    ("state", "latest", "level", "reason"),
    [
        (evidence(), "healthy", "healthy", None),
        (evidence(change_alarm=True, change_statistic=6.0), "healthy", "alarm", "change alarm"),
        (evidence(fault_class="spall", posterior={"spall": 0.97}), "spall", "alarm", "names spall"),
        # just above / at half the threshold
        (evidence(change_statistic=WATCH_SHARE * 5.0 + 0.01), "healthy", "watch", "statistic"),
        (evidence(change_statistic=WATCH_SHARE * 5.0), "healthy", "healthy", None),
        (evidence(posterior={"healthy": 0.3, "wear": 0.7}), "healthy", "watch", "leans to wear"),
        (evidence(), "wear", "watch", "latest diagnosis names wear"),
        # the evidence leans to healthy: healthy, with the latest's limit said
        (evidence(), "cannot_tell", "healthy", "cannot tell the class"),
        # nothing says healthy: unknown, never healthy, and what to record next
        (evidence(recordings=0, posterior={}), "cannot_tell", "unknown", "record next"),
    ],
)
def test_each_branch_of_the_rule(state, latest, level, reason):
    status = asset_status(state, BASELINE, latest)
    assert status["level"] == level
    if reason is None:
        assert status["reasons"] == []
    else:
        assert any(reason in text for text in status["reasons"]), status


def test_the_worst_level_wins_and_every_reason_is_kept():
    state = evidence(change_alarm=True, posterior={"healthy": 0.4, "wear": 0.6})
    status = asset_status(state, BASELINE, "wear")
    assert status["level"] == "alarm" and status["level"] == LEVELS[-1]
    assert LEVELS.index("unknown") < LEVELS.index("watch")
    assert len(status["reasons"]) == 3  # the alarm first, then the two watches
    assert "change alarm" in status["reasons"][0]


def test_without_a_complete_baseline_it_says_no_change_is_scored():
    status = asset_status(None, None, "healthy")
    assert status["level"] == "healthy" and "no baseline yet" in status["reasons"][0]
    making = asset_status(
        evidence(change_statistic=None, recordings=0), {"recordings": 1, "needed": 3}, "healthy"
    )
    assert making["level"] == "healthy" and "baseline 1 of 3" in making["reasons"][0]
    complete = asset_status(evidence(recordings=0), BASELINE, "healthy")
    assert complete["level"] == "healthy" and "no evidence" in complete["reasons"][0]


def test_an_asset_nothing_has_shown_healthy_is_not_called_healthy():
    # one recording, its class not told, no evidence: "unknown" with why and what to record
    status = asset_status(
        evidence(recordings=0, posterior={}), {"recordings": 1, "needed": 3}, "cannot_tell"
    )
    assert status["level"] == "unknown"
    assert any("baseline 1 of 3" in r for r in status["reasons"])
    assert any("record next" in r for r in status["reasons"])
