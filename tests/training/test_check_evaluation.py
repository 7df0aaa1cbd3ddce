"""The check model's scores on fresh units, on hand-made records with known answers."""

from __future__ import annotations

import types

import pytest

from prsm_health.training.check_evaluation import (
    _accumulated,
    _class_scores,
    _sensitivity,
)

MODEL = types.SimpleNamespace(not_observable={"preload_loss": "measured reason"})


def record(state, truth, alone, top, against=None, noise=20.0, clearance=5e-6, estimate=6e-6):
    return {
        "state": state,
        "fault_class": truth,
        "unit_id": 0,
        "predicted_alone": alone,
        "top_alone": top,
        "predicted_against": against or alone,
        "top_against": top,
        "clearance": clearance,
        "estimate": estimate,
        "lower": 0.0,
        "upper": 1e-5,
        "conditions": {"instrumentation.nut_axial_accel.noise_density_ug": noise},
    }


@pytest.fixture
def records():
    return [
        record("healthy", "healthy", "healthy", 0.9, noise=20.0),
        record("healthy", "healthy", "cannot_tell", 0.45, noise=30.0),
        record("healthy", "healthy", "healthy", 0.55, noise=40.0),
        record("wear", "wear", "wear", 0.95, noise=50.0),
        record("wear", "wear", "spall", 0.7, noise=60.0),  # confident and wrong
        record("spall_nut", "spall", "spall", 0.65, noise=25.0),
        # not observable: reported in the confusion, out of the scores
        record("preload_loss", "preload_loss", "healthy", 0.99, noise=35.0),
    ]


def test_scores_count_cannot_tell_as_a_miss_and_leave_out_what_is_not_observable(records):
    scores = _class_scores(records, "predicted_alone", MODEL)
    assert scores["n"] == 6
    assert scores["healthy_named_healthy"] == pytest.approx(2 / 3)
    assert scores["wrong_fraction"] == pytest.approx(1 / 6)
    assert scores["confident_wrong_fraction"] == pytest.approx(1 / 6)  # 0.7 > CONFIDENT
    assert scores["cannot_tell_fraction"] == pytest.approx(1 / 6)
    assert scores["confusion"]["preload_loss"] == {"healthy": 1}
    # a stricter rule: at 0.6 the 0.55 healthy check becomes cannot_tell; at 0.8 the wrong
    # spall (0.7) does too
    by_t = {row["threshold"]: row for row in scores["naming_thresholds"]}
    assert by_t[0.5]["healthy_named_healthy"] == pytest.approx(2 / 3)
    assert by_t[0.6]["healthy_named_healthy"] == pytest.approx(1 / 3)
    assert by_t[0.7]["wrong_fraction"] == pytest.approx(1 / 6)
    assert by_t[0.8]["wrong_fraction"] == 0.0


def test_sensitivity_splits_each_factor_into_thirds(records):
    rows = _sensitivity(records, MODEL)
    assert [r["n"] for r in rows] == [2, 2, 2]  # the preload-loss check is not scored
    assert rows[0]["low"] == 20.0 and rows[-1]["high"] == 60.0
    # noise 20, 25 → both right; 50, 60 → one right, one wrong
    assert rows[0]["named_right"] == 1.0 and rows[2]["wrong"] == 0.5
    assert rows[0]["clearance_mae"] == pytest.approx(1e-6)


def test_spall_detection_is_the_auc_of_the_accumulated_spall_posterior():
    # the card's section on these numbers: tests/release/test_diagnosis_card.py
    units = [
        {"state": "healthy", "fault_class": "healthy", "named": "healthy",
         "posterior": {"healthy": 0.95, "spall": 0.05}},
        {"state": "spall_nut", "fault_class": "spall", "named": "spall",
         "posterior": {"healthy": 0.02, "spall": 0.98}},
        {"state": "spall_nut", "fault_class": "spall", "named": "cannot_tell",
         "posterior": {"healthy": 0.97, "spall": 0.03}},  # below the healthy unit's 0.05
    ]  # fmt: skip
    assert _accumulated(units, MODEL, 0.9)["spall_auc"] == {"spall_nut": 0.5}


def test_the_evidence_rule_trade_off_names_each_unit_from_its_posterior():
    units = [
        {"state": "healthy", "fault_class": "healthy", "named": "healthy",
         "posterior": {"healthy": 0.97, "spall": 0.03}},
        {"state": "spall_nut", "fault_class": "spall", "named": "cannot_tell",
         "posterior": {"healthy": 0.15, "spall": 0.85}},
        {"state": "spall_roller", "fault_class": "spall", "named": "cannot_tell",
         "posterior": {"healthy": 0.75, "spall": 0.25}},  # a wrong name below 0.8
    ]  # fmt: skip
    by_t = {r["threshold"]: r for r in _accumulated(units, MODEL, 0.9)["thresholds"]}
    assert by_t[0.7]["wrong_fraction"] == pytest.approx(1 / 3)
    assert by_t[0.7]["cannot_tell_fraction"] == 0.0
    assert by_t[0.8]["wrong_fraction"] == 0.0
    assert by_t[0.8]["cannot_tell_fraction"] == pytest.approx(1 / 3)
    assert by_t[0.9]["cannot_tell_fraction"] == pytest.approx(2 / 3)
    assert by_t[0.95]["macro_f1"] == by_t[0.9]["macro_f1"]


def test_two_state_checks_are_a_degraded_lubricant_under_another_label():
    import pandas as pd

    from prsm_health.training.check_training import two_states

    table = pd.DataFrame(
        {
            "fault_class": ["spall", "lubrication", "spall", "healthy", "wear"],
            "lubricant_degradation": [0.7, 0.7, 0.2, 0.49, 0.1],
            "lubricant_starvation": [0.0, 0.0, 0.0, 0.0, 0.6],  # starved is degraded too
            "friction_scale": [1.0, 1.0, 1.0, 1.0, 1.0],
        }
    )
    assert two_states(table).tolist() == [True, False, False, False, True]
