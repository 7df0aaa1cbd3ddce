"""A unit's accumulated class evidence and the CUSUM on its baseline distance
(prsm_health.monitoring.evidence): the Bayesian updates against their closed forms, exact JSON
round trips. Pure numpy, no model."""

import json
import math

import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.diagnostics.contract import CANNOT_TELL
from prsm_health.monitoring.evidence import EVIDENCE_FLOOR, Cusum, Evidence


# ----------------------------------------------------------------------------- Evidence
def test_evidence_rises_monotonically_to_the_closed_form():
    # three recordings each favouring B at p = 0.6 (A and C at 0.2), uniform training prior:
    # the log odds of B against each other class grow by ℓ = log 3 per recording, discounted
    # by λ: d_t = ℓ (1 − λ^t)/(1 − λ); P(B) = 1/(1 + 2 e^(−d_t))
    p = {"A": 0.2, "B": 0.6, "C": 0.2}
    for lam in (1.0, 0.8):
        e = Evidence.start(("A", "B", "C"))
        assert e.posterior() == pytest.approx({"A": 1 / 3, "B": 1 / 3, "C": 1 / 3})
        previous = 1 / 3
        for t in (1, 2, 3):
            e = e.update(p, forgetting=lam)
            d = math.log(3) * (t if lam == 1 else (1 - lam**t) / (1 - lam))
            assert e.posterior()["B"] == pytest.approx(1 / (1 + 2 * math.exp(-d)), rel=1e-12)
            assert e.posterior()["B"] > previous
            previous = e.posterior()["B"]
        assert e.recordings == 3
        # λ = 1: P(B) = 3³/(3³ + 2) = 27/29 = 0.931, named; λ = 0.8: d = 2.68, P(B) = 0.879,
        # not yet (the 4th recording names it: d = 3.24, P(B) = 0.927)
        assert e.named() == ("B" if lam == 1 else CANNOT_TELL)
        assert e.named(threshold=0.85) == "B" and e.named(threshold=0.99) == CANNOT_TELL
    assert e.update(p).named() == "B"
    assert Evidence.start(("A", "B", "C")).update(p, forgetting=1.0).update(
        p, forgetting=1.0
    ).update(p, forgetting=1.0).posterior()["B"] == pytest.approx(27 / 29, rel=1e-12)


def test_training_prior_is_divided_out():
    # a recording on which the classifier returns its own training prior says nothing
    prior = {"A": 0.75, "B": 0.25}
    e = Evidence.start(("A", "B")).update(prior, training_prior=prior)
    assert e.posterior() == pytest.approx({"A": 0.5, "B": 0.5})
    # without dividing by it, A would have gained
    assert Evidence.start(("A", "B")).update(prior).posterior()["A"] == pytest.approx(0.75)


def test_floor_bounds_a_veto():
    # one recording that gives A probability 0: A falls to floor/(1 + floor), not to 0 …
    e = Evidence.start(("A", "B")).update({"A": 0.0, "B": 1.0}, forgetting=1.0)
    f = EVIDENCE_FLOOR
    assert e.posterior()["A"] == pytest.approx(f / (1 + f), rel=1e-12)
    # … and one recording the other way brings it back: one recording never rules a class out
    e = e.update({"A": 1.0, "B": 0.0}, forgetting=1.0)
    assert e.posterior()["A"] == pytest.approx(0.5, rel=1e-12)
    # a class missing from the probabilities counts as probability 0 (the floor)
    assert Evidence.start(("A", "B")).update({"B": 1.0}, forgetting=1.0) == Evidence.start(
        ("A", "B")
    ).update({"A": 0.0, "B": 1.0}, forgetting=1.0)


def test_forgetting_follows_a_change_of_state():
    # 20 recordings favouring A, then recordings favouring B (p = 0.8 vs 0.2): each moves the
    # log odds d of B against A by ℓ = log 4, so with λ = 0.8 d_t = λ d_(t−1) + ℓ from
    # d_0 = −ℓ (1 − λ^20)/(1 − λ); B is named once P(B) = 1/(1 + e^(−d)) ≥ 0.9
    ell = math.log(0.8 / 0.2)

    def recordings_to_follow(lam):
        e = Evidence.start(("A", "B"))
        for _ in range(20):
            e = e.update({"A": 0.8, "B": 0.2}, forgetting=lam)
        for t in range(1, 60):
            e = e.update({"A": 0.2, "B": 0.8}, forgetting=lam)
            if e.named() == "B":
                return t, e
        return None, e

    d = -ell * (1 - 0.8**20) / (1 - 0.8)
    t_expected = 0
    while 1 / (1 + math.exp(-d)) < 0.9:
        d = 0.8 * d + ell
        t_expected += 1
    t, e = recordings_to_follow(0.8)
    assert t == t_expected == 5
    assert e.posterior()["B"] == pytest.approx(1 / (1 + math.exp(-d)), rel=1e-9)
    # without forgetting the 20 old recordings hold it for 22 more: −20ℓ + tℓ ≥ log 9
    t, _ = recordings_to_follow(1.0)
    assert t == 22


def test_evidence_json_round_trip_and_errors():
    e = Evidence.start(("A", "B", "C"), prior={"A": 2, "B": 1, "C": 1}).update(
        {"A": 0.1, "B": 0.7, "C": 0.2}
    )
    assert Evidence.from_json(json.loads(json.dumps(e.to_json()))) == e
    with pytest.raises(ParameterError, match="probabilities"):
        e.update({"D": 1.0})
    with pytest.raises(ParameterError, match="forgetting"):
        e.update({"A": 1.0}, forgetting=0.0)
    with pytest.raises(ParameterError, match="floor"):
        e.update({"A": 1.0}, floor=1.0)
    with pytest.raises(ParameterError, match="training_prior"):
        e.update({"A": 1.0}, training_prior={"A": 1.0})
    with pytest.raises(ParameterError, match="prior"):
        Evidence.start(("A", "B"), prior={"A": 1.0, "B": 0.0})


# ----------------------------------------------------------------------------- Cusum
def test_cusum_steps_by_hand():
    c = Cusum(reference=1.5, threshold=5.0)
    seen = []
    for x in (1.0, 3.0, 3.0, 0.0, 4.0, 4.0, float("nan"), 4.0, 0.0):
        c = c.update(x)
        seen.append((c.statistic, c.alarm))
    # S_t = max(0, S_(t−1) + x − 1.5); alarm while S > 5; NaN leaves S as it is
    assert seen == [
        (0.0, False),
        (1.5, False),
        (3.0, False),
        (1.5, False),
        (4.0, False),
        (6.5, True),
        (6.5, True),
        (9.0, True),
        (7.5, True),
    ]
    assert Cusum.from_json(json.loads(json.dumps(c.to_json()))) == c
    # one recording alarms only above k + h
    assert not Cusum().update(6.5).alarm and Cusum().update(6.51).alarm
    with pytest.raises(ParameterError, match="threshold"):
        Cusum(threshold=0.0)
