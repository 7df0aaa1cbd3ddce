"""An asset's history (prsm_health.monitoring.asset): the baseline fills with its first
recordings, then evidence and the change statistic accumulate; a recording recorded twice
counts once; the history round-trips exactly through JSON. Synthetic diagnoses, no model.
The stores are tests/monitoring/test_store.py."""

import dataclasses
import json
import math

import numpy as np
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.core.jsonable import dumps
from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.contract import (
    CANNOT_TELL,
    AssetState,
    ClearanceInterval,
    Diagnosis,
    ModelReference,
    Observability,
)
from prsm_health.monitoring.asset import (
    BASELINE_RECORDINGS,
    AssetHistory,
    bundle_priors,
    names_a_fault,
    training_spread,
    validate_asset_id,
)
from prsm_health.monitoring.evidence import Cusum, Evidence

CLASSES = ("healthy", "lubrication", "wear")


def diagnosis(
    a=1.0,
    b=10.0,
    probabilities=None,
    fault_class=CANNOT_TELL,
    class_set=None,
    observable=True,
    ood_score=None,
):
    probabilities = probabilities or {"healthy": 0.5, "lubrication": 0.25, "wear": 0.25}
    return Diagnosis(
        clearance=ClearanceInterval(10e-6, 8e-6, 12e-6),
        fault_class=fault_class,
        class_probabilities=probabilities,
        class_set=list(CLASSES) if class_set is None else class_set,
        observability=Observability(True, observable),
        ood_score=ood_score,
        indicators={"a": a, "b": b, "gone": None},
        model=ModelReference("m", "1", "paper01", "flight-ema"),
    )


WEAR = {"healthy": 0.1, "lubrication": 0.1, "wear": 0.8}
PRIOR = {"a": 0.1, "b": 1.0}


def recorded(values, **kwargs):
    """A history after recording ``values`` = [(a, b, probabilities or None), …] as r0, r1 …"""
    h, out = AssetHistory("unit-1"), []
    for i, (a, b, p) in enumerate(values):
        h, d = h.record(f"r{i}", diagnosis(a, b, p), prior_scale=PRIOR, **kwargs)
        out.append(d)
    return h, out


BASE = [(1.0, 10.0, None), (1.1, 10.5, None), (0.9, 9.5, None)]


def test_baseline_fills_with_the_first_three_then_evidence_accumulates():
    assert BASELINE_RECORDINGS == 3
    h, out = recorded(BASE[:2])
    assert h.baseline(PRIOR) is None
    assert [d.asset.baseline.recordings for d in out] == [1, 2]
    h, out = recorded([*BASE, (1.5, 10.0, WEAR), (1.6, 10.2, WEAR)])
    assert [e.baseline for e in h.entries] == [True, True, True, False, False]
    assert [d.asset.baseline.recordings for d in out] == [1, 2, 3, 3, 3]
    # nothing scored, no evidence, while the baseline fills
    for d in out[:3]:
        assert d.asset.baseline.changes == {} and d.asset.baseline.distance is None
        assert d.asset.evidence.recordings == 0
    assert out[1].asset.evidence.change_statistic is None
    assert out[2].asset.evidence.change_statistic == 0.0  # complete: the CUSUM starts
    # then each recording is scored against the baseline and adds its evidence
    baseline = Baseline.fit(
        [{"a": a, "b": b} for a, b, _ in BASE], prior_scale=PRIOR, recordings=["r0", "r1", "r2"]
    )
    assert h.baseline(PRIOR) == baseline
    fourth = out[3].asset
    z = baseline.change({"a": 1.5, "b": 10.0})
    assert fourth.baseline.changes == {"a": z["a"], "b": z["b"]}  # largest |z| first
    assert list(fourth.baseline.changes) == ["a", "b"]
    assert fourth.baseline.distance == baseline.distance({"a": 1.5, "b": 10.0})
    expected = Evidence.start(CLASSES).update(WEAR).update(WEAR)
    assert out[4].asset.evidence.recordings == 2 == h.evidence.recordings
    assert out[4].asset.evidence.posterior == expected.posterior()
    assert out[4].asset.evidence.fault_class == expected.named()
    cusum = Cusum().update(fourth.baseline.distance).update(h.entries[4].distance)
    assert h.cusum == cusum
    assert out[4].asset.evidence.change_statistic == cusum.statistic
    # the diagnosis itself is the one given, with the asset attached
    assert out[4].fault_class == CANNOT_TELL and out[4].to_json()["asset"]["asset_id"] == "unit-1"


def test_a_confident_fault_stays_out_of_a_baseline_in_the_making():
    h = AssetHistory("u")
    wear = diagnosis(probabilities=WEAR, fault_class="wear", class_set=["wear"])
    assert names_a_fault(wear)
    # named but healthy not ruled out, or not named: not confident
    assert not names_a_fault(diagnosis(probabilities=WEAR, fault_class="wear"))
    assert not names_a_fault(diagnosis(fault_class="healthy", class_set=["healthy"]))
    h, d = h.record("w", wear)
    assert not h.entries[0].baseline and h.evidence.recordings == 1
    assert d.asset.baseline.recordings == 0
    assert any("not put in the baseline" in w for w in d.warnings)
    # a label decides: healthy=True puts it in, healthy=False keeps a plain one out
    h, _ = h.record("w2", wear, healthy=True)
    h, _ = h.record("x", diagnosis(), healthy=False)
    assert [e.baseline for e in h.entries] == [False, True, False]
    assert h.evidence.recordings == 2  # the recordings outside the baseline


def test_healthy_label_adds_to_a_complete_baseline():
    h, _ = recorded(BASE)
    h, d = h.record("late", diagnosis(1.2, 10.1), healthy=True, prior_scale=PRIOR)
    assert h.entries[-1].baseline and d.asset.baseline.recordings == 4
    assert h.baseline(PRIOR).count == 4
    assert h.evidence is None and h.cusum == Cusum()  # baseline recordings add no evidence
    assert d.asset.baseline.distance is not None  # scored against the baseline before it


def test_the_same_recording_twice_is_counted_once():
    h, out = recorded([*BASE, (1.5, 10.0, WEAR)])
    again, d = h.record("r3", diagnosis(5.0, 50.0, WEAR), prior_scale=PRIOR)
    assert again is h
    assert d.asset == out[3].asset
    assert any("already in the history" in w for w in d.warnings)
    again, _ = h.record("r0", diagnosis(), healthy=True)
    assert again is h and sum(e.baseline for e in h.entries) == 3


def test_evidence_restarts_when_the_classes_change():
    h, _ = recorded([*BASE, (1.5, 10.0, WEAR)])
    other = {"healthy": 0.2, "spall": 0.8}
    h, d = h.record("new", diagnosis(1.0, 10.0, other), prior_scale=PRIOR)
    assert h.evidence.classes == ("healthy", "spall") and h.evidence.recordings == 1
    assert any("starts afresh" in w for w in d.warnings)


def test_training_prior_is_used_when_it_covers_the_classes():
    prior = {"healthy": 0.5, "lubrication": 0.25, "wear": 0.25}
    h, _ = recorded([*BASE, (1.0, 10.0, prior)], training_prior=prior)
    # the classifier said its own prior: no evidence either way
    assert h.evidence.posterior() == pytest.approx({c: 1 / 3 for c in CLASSES})
    h, _ = recorded([*BASE, (1.0, 10.0, prior)], training_prior={"healthy": 1.0})
    assert h.evidence.posterior()["healthy"] == pytest.approx(0.5)  # not covering: uniform


def test_cusum_alarm_is_a_warning():
    h, out = recorded([*BASE, *[(5.0, 30.0, WEAR)] * 2])
    assert out[3].asset.baseline.distance > 6.5  # k + h: at once
    assert out[3].asset.evidence.change_alarm
    assert any("has changed from its baseline" in w for w in out[3].warnings)


def test_history_json_round_trip_is_exact():
    h, _ = recorded([*BASE, (1.5, 10.0, WEAR), (1.3, 9.0, WEAR)], operating_hours=12.5)
    h, _ = h.record("t", diagnosis(), time="2024-05-01T10:00:00+00:00", source="t.mcap")
    text = dumps(h.to_json())
    again = AssetHistory.from_json(json.loads(text))
    assert again == h
    assert isinstance(again.entries[0].state, AssetState)
    assert again.entries[-1].time == "2024-05-01T10:00:00+00:00"
    assert again.entries[0].indicators["gone"] is None
    assert dumps(again.to_json()) == text


def test_report_has_a_row_per_recording():
    h, _ = recorded([*BASE, (1.5, 10.0, WEAR)])
    r = h.report(PRIOR)
    assert r["baseline"]["complete"] and set(r["baseline"]["indicators"]) == {"a", "b"}
    assert [row["baseline"] for row in r["entries"]] == [True, True, True, False]
    assert r["entries"][0]["leading_class"] is None  # no evidence yet: no leader
    assert r["entries"][3]["leading_class"] == "wear"
    assert r["evidence"]["recordings"] == 1
    json.dumps(r, allow_nan=False)


def test_bad_input_names_the_field():
    with pytest.raises(ParameterError, match="asset_id"):
        AssetHistory("../etc")
    for bad in ("", "a/b", "-x", "a b", "x" * 129, None):
        with pytest.raises(ParameterError, match="asset_id"):
            validate_asset_id(bad)
    assert validate_asset_id("Pump-7:left_1.2") == "Pump-7:left_1.2"
    h = AssetHistory("u")
    with pytest.raises(ParameterError, match="recording_id"):
        h.record("", diagnosis())
    with pytest.raises(ParameterError, match="operating_hours"):
        h.record("r", diagnosis(), operating_hours=-1.0)


def test_bundle_priors_read_the_check_part():
    class Bundle:
        check = {
            "repeatability": {"a": 0.1},
            "training_prior": {"healthy": 0.6, "wear": 0.4},
            "feature_names": ["a"],
        }

    assert bundle_priors(Bundle()) == ({"a": 0.1}, {"healthy": 0.6, "wear": 0.4}, ["a"])
    assert bundle_priors(object()) == (None, None, None)


def test_baseline_of_other_indicators_is_none():
    h, _ = recorded(BASE)
    assert h.baseline(PRIOR, names=["elsewhere"]) is None
    assert h.baseline(PRIOR, names=["b"]).names == ("b",)


def test_distance_is_finite_json(tmp_path):
    # a recording with no finite indicator of the baseline: distance null, CUSUM unchanged
    h, _ = recorded(BASE)
    h, d = h.record("empty", diagnosis(math.nan, math.nan, WEAR), prior_scale=PRIOR)
    assert d.asset.baseline.distance is None and h.cusum == Cusum()
    assert np.isfinite(h.evidence.log_posterior).all()
    json.dumps(d.to_json()["asset"], allow_nan=False)


def test_checks_and_windows_of_a_unit_keep_baselines_of_their_own():
    # three in-service windows (indicators a, b) fill the windows' baseline; a health check
    # (indicators check_x) then starts the checks' own baseline instead of being scored
    # against indicators it does not have
    h, _ = recorded(BASE)
    assert h.baseline(PRIOR, ["a", "b"]) is not None
    check = Diagnosis(
        clearance=ClearanceInterval(10e-6, 8e-6, 12e-6),
        fault_class="healthy",
        class_probabilities={"healthy": 0.9, "wear": 0.1},
        class_set=["healthy"],
        observability=Observability(True, True),
        indicators={"check_x": 1.0},
        model=ModelReference("m", "1", "paper01", "flight-ema"),
        check_phases={"reversal": "slow reversal"},
    )
    h, d = h.record("check-0", check, names=["check_x"])
    assert h.entries[-1].baseline and d.asset.baseline.recordings == 1
    assert h.baseline(None, ["check_x"]) is None  # one check: the checks' baseline not complete
    assert h.baseline(PRIOR, ["a", "b"]).count == 3  # the windows' baseline unchanged


def test_bundle_priors_are_those_of_the_recordings_kind():
    class Bundle:
        feature_names = ["a", "b"]
        check = {
            "repeatability": {"check_x": 0.5},
            "training_prior": {"healthy": 1.0},
            "feature_names": ["check_x"],
        }

    assert bundle_priors(Bundle(), check=True) == ({"check_x": 0.5}, {"healthy": 1.0}, ["check_x"])
    assert bundle_priors(Bundle(), check=False) == (None, None, ["a", "b"])


@pytest.mark.parametrize(
    ("blind", "why"),
    [
        ({"observable": 0.2}, "observable in 20 % of its windows"),
        ({"observable": False}, "could not show its fault class"),
        ({"observable": 1.0, "ood_score": 3.0}, "unlike the model's training set"),
    ],
)
def test_an_answer_the_model_could_not_see_adds_no_evidence_and_no_cusum_step(blind, why):
    before, _ = recorded([*BASE, (1.5, 10.0, WEAR)])
    h, d = before.record("blind", diagnosis(5.0, 30.0, WEAR, **blind), prior_scale=PRIOR)
    assert h.evidence == before.evidence and h.cusum == before.cusum
    assert len(h.entries) == 5 and not h.entries[-1].baseline  # recorded all the same
    # its distance and changes are shown: seen, it would have alarmed at once (> k + h)
    assert h.entries[-1].distance == d.asset.baseline.distance > 6.5
    assert d.asset.baseline.changes
    assert d.asset.evidence.recordings == 1 and not d.asset.evidence.change_alarm
    assert any("added no class evidence" in w and why in w for w in d.warnings)


def test_an_answer_seen_in_half_its_windows_adds_its_evidence_and_cusum_step():
    before, _ = recorded(BASE)
    seen = diagnosis(5.0, 30.0, WEAR, observable=0.5, ood_score=1.4)
    h, d = before.record("half", seen, prior_scale=PRIOR)
    assert h.evidence.recordings == 1
    assert h.cusum == Cusum().update(d.asset.baseline.distance) and h.cusum.alarm
    assert not any("added no class evidence" in w for w in d.warnings)
    # in a baseline in the making an answer not seen joins it as any other (no note)
    h, d = AssetHistory("u").record("first", diagnosis(observable=0.0))
    assert h.entries[0].baseline and h.evidence is None and d.warnings == []


def test_without_a_measured_repeatability_the_training_spread_keeps_a_healthy_unit_quiet():
    import pandas as pd

    from prsm_health.diagnostics.estimators import DistributionGuard

    # a window model's guard fitted on 40 units' windows: each unit's level its own (between
    # units σ = 1), its windows scattering σ = 0.1 around it
    rng = np.random.default_rng(5)
    names = ["a", "b", "c"]
    levels = rng.normal([2.0, -1.0, 0.5], 1.0, size=(40, 3))
    rows = np.repeat(levels, 10, axis=0) + rng.normal(0.0, 0.1, (400, 3))

    class Bundle:  # no check part: no repeatability measured
        feature_names = names
        guard = DistributionGuard().fit(pd.DataFrame(rows, columns=names))
        check = None

    scale, prior, baseline_names = bundle_priors(Bundle(), check=False)
    assert scale == training_spread(Bundle()) and baseline_names == names and prior is None
    assert all(0.5 < scale[n] < 2.0 for n in names)  # the spread between units, ≫ 0.1
    # a healthy unit: three baseline recordings that agree to 1e-4, then ten that scatter as
    # its windows do
    unit = rng.normal([2.0, -1.0, 0.5], 1.0)
    noise = [1e-4] * 3 + [0.1] * 10
    values = [unit + rng.normal(0.0, sigma, 3) for sigma in noise]

    def alarms(prior_scale):
        h, out = AssetHistory("u"), []
        for i, x in enumerate(values):
            d = dataclasses.replace(diagnosis(), indicators=dict(zip(names, x.tolist())))
            h, d = h.record(f"r{i}", d, prior_scale=prior_scale, names=names)
            out.append(d.asset.evidence.change_alarm)
        return out

    assert not any(alarms(scale))
    assert any(alarms(None))  # the baseline's own near-zero spread: the same unit cries wolf
