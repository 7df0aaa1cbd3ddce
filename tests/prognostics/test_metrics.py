"""Prognostic metrics (Saxena et al. 2010) on hand-made arrays, and the fleet evaluation.

The cross-checks against progpy's own metrics are in test_metrics_progpy.py.
"""

import math

import numpy as np
import pandas as pd
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.prognostics import RULModel
from prsm_health.prognostics.metrics import (
    PREDICTION_COLUMNS,
    alpha_lambda_accuracy,
    evaluate_units,
    interval_coverage,
    prognostic_horizon,
    rmse,
)

Z90 = 1.6448536269514722


def test_rmse_by_hand():
    assert rmse([0, 0, 0, 0], [1, -1, 1, -1]) == 1.0
    assert rmse([3.0, 4.0], [0.0, 0.0]) == pytest.approx(math.sqrt((9 + 16) / 2))
    assert rmse([5.0], [5.0]) == 0.0


def test_alpha_lambda_counts_the_shrinking_cone():
    # alpha = 0.2 around r* = 100: [80, 120]. 110 and 85 and 100 inside, 121 outside -> 3/4.
    assert alpha_lambda_accuracy([100, 100, 100, 100], [110, 85, 121, 100]) == 0.75
    # the cone shrinks with the true RUL: an error of 15 h is inside at r* = 100, outside at 50
    assert alpha_lambda_accuracy([100, 50], [115, 65]) == 0.5
    # r* = 0 admits only 0; alpha widens the cone
    assert alpha_lambda_accuracy([0, 0], [0, 1]) == 0.5
    assert alpha_lambda_accuracy([100], [140], alpha=0.5) == 1.0
    assert alpha_lambda_accuracy([100], [140], alpha=0.3) == 0.0


def test_prognostic_horizon_by_hand():
    ages = [0, 10, 20, 30, 40]
    true = [50, 40, 30, 20, 10]  # failure at 50 h; alpha * EoL = 10 h around r*
    # errors 20 (out), 5 (in), 25 (out), 5 (in), 2 (in): inside for good from age 30
    assert prognostic_horizon(ages, true, [70, 45, 55, 25, 12], 50.0) == 50.0 - 30.0
    assert prognostic_horizon(ages, true, true, 50.0) == 50.0  # always inside
    assert prognostic_horizon(ages, true, [50, 40, 30, 20, 31], 50.0) == 0.0  # ends outside
    # the bound is alpha * EoL, not alpha * r*: an error of 9 h at r* = 10 is still inside
    assert prognostic_horizon([40], [10], [19], 50.0) == 10.0


def test_interval_coverage_by_hand():
    true = [10, 20, 30, 40, 50]
    lower = [5, 21, 30, 0, 49]
    upper = [15, 25, 31, 39, 50]
    # inside: 10 in [5,15], 30 in [30,31], 50 in [49,50]; 20 below 21, 40 above 39 -> 3/5
    assert interval_coverage(true, lower, upper) == 0.6


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: rmse([1, 2], [1]), "must hold 2 values"),
        (lambda: rmse([], []), "at least one value"),
        (lambda: rmse([1, np.nan], [1, 2]), "true[1]"),
        (lambda: alpha_lambda_accuracy([-1, 2], [1, 2]), "true_rul[0]"),
        (lambda: alpha_lambda_accuracy([1], [1], alpha=0.0), "alpha"),
        (lambda: prognostic_horizon([0, 0], [1, 1], [1, 1], 5.0), "ages[1]"),
        (lambda: prognostic_horizon([0], [1], [1], -5.0), "failure_age"),
        (lambda: interval_coverage([1], [0], [np.inf]), "upper[0]"),
    ],
)
def test_metric_input_errors(call, words):
    with pytest.raises(ParameterError) as info:
        call()
    assert words in str(info.value) and "\n" not in str(info.value)


def _fleet(n_units, n_points, seed, first_id=0):
    """Exponential wear S = 8 µm + exp(ln theta + beta t) with 0.3 µm diagnosis noise."""
    rng = np.random.default_rng(seed)
    parts, lives = [], {}
    for uid in range(first_id, first_id + n_units):
        ln_theta = math.log(2e-6) + 0.15 * rng.standard_normal()
        beta = 2.4e-4 * (1 + 0.15 * rng.standard_normal())
        life = (math.log(22e-6) - ln_theta) / beta
        ages = np.linspace(0.0, life, n_points, endpoint=False)
        value = 8e-6 + np.exp(ln_theta + beta * ages) + 0.3e-6 * rng.standard_normal(n_points)
        parts.append(
            pd.DataFrame(
                {
                    "unit_id": uid,
                    "age_hours": ages,
                    "clearance": value,
                    "clearance_lower": value - Z90 * 0.3e-6,
                    "clearance_upper": value + Z90 * 0.3e-6,
                }
            )
        )
        lives[uid] = life
    return pd.concat(parts, ignore_index=True), lives


def test_evaluate_units_table_and_summary():
    train, train_lives = _fleet(8, 12, seed=0)
    model = RULModel(n_samples=500).fit(train, train_lives)
    test, lives = _fleet(4, 10, seed=1, first_id=50)
    # a diagnosis after failure is not scored
    extra = test[test["unit_id"] == 50].iloc[[-1]].copy()
    extra["age_hours"] = lives[50] + 100.0
    test = pd.concat([test, extra], ignore_index=True)
    predictions, summary = evaluate_units(test, lives, model, after_fraction=0.5)

    assert list(predictions.columns) == list(PREDICTION_COLUMNS)
    assert len(predictions) == 2 * 4 * (10 - 1)  # 2 methods x 4 units x prefixes of 2..10 rows
    assert (predictions["true_rul"] >= 0).all()
    assert set(predictions["method"]) == {"degradation", "similarity"}
    # every row is the prediction from the rows up to its age only
    unit = test[test["unit_id"] == 51].reset_index(drop=True)
    for k in (2, 7):
        row = predictions[
            (predictions["unit_id"] == 51)
            & (predictions["method"] == "similarity")
            & (predictions["age_hours"] == unit["age_hours"].iloc[k - 1])
        ]
        alone = model.predict(unit.iloc[:k], method="similarity").rul_hours
        assert row[["estimate", "lower", "upper"]].iloc[0].tolist() == [
            alone["estimate"],
            alone["lower"],
            alone["upper"],
        ]
        assert row["true_rul"].iloc[0] == pytest.approx(lives[51] - unit["age_hours"].iloc[k - 1])

    # the summary, recomputed from the table with plain numpy
    for method in ("degradation", "similarity"):
        part = predictions[predictions["method"] == method]
        err = part["estimate"] - part["true_rul"]
        late = part[part["age_hours"] >= 0.5 * (part["age_hours"] + part["true_rul"])]
        s = summary[method]
        assert s["n_predictions"] == len(part) and s["n_units"] == 4
        assert s["rmse"] == pytest.approx(math.sqrt(np.mean(err**2)))
        inside = np.abs(late["estimate"] - late["true_rul"]) <= 0.2 * late["true_rul"]
        assert s["alpha_lambda"] == pytest.approx(inside.mean())
        anywhere = np.abs(err) <= 0.2 * part["true_rul"]
        assert s["alpha_lambda_all"] == pytest.approx(anywhere.mean())
        covered = (part["lower"] <= part["true_rul"]) & (part["true_rul"] <= part["upper"])
        assert s["coverage"] == pytest.approx(covered.mean())
        assert 0.0 <= s["prognostic_horizon"] <= max(lives.values())
        # progpy's CRA and monotonicity, per unit then averaged (Saxena 2010 section 6.3;
        # Coble & Hines 2009), against the plain formulas
        cra, mono = [], []
        for _, u in part.sort_values("age_hours").groupby("unit_id"):
            keep = u["true_rul"] > 0
            cra.append(np.mean(1 - np.abs(err[u.index][keep]) / u["true_rul"][keep]))
            steps = np.sign(np.diff(u["estimate"].to_numpy()))
            mono.append(abs(steps.sum()) / steps.size)
        assert s["cra"] == pytest.approx(np.mean(cra), rel=1e-12)
        assert s["monotonicity"] == pytest.approx(np.mean(mono), rel=1e-12)
        assert s["cra"] <= 1.0 and 0.0 <= s["monotonicity"] <= 1.0


def test_evaluate_units_refusals():
    train, lives = _fleet(4, 6, seed=2)
    model = RULModel(n_samples=200).fit(train, lives)
    with pytest.raises(ParameterError, match="no failure age"):
        evaluate_units(train, {0: lives[0]}, model)
    with pytest.raises(ParameterError, match="after_fraction"):
        evaluate_units(train, lives, model, after_fraction=1.0)
    with pytest.raises(ParameterError, match="unit_id"):
        evaluate_units(train.drop(columns="unit_id"), lives, model)
