"""The prognostic metrics against NASA's progpy on the same inputs (Saxena et al. 2010).

Each test keeps a small reference formula of its own, only to cross-check progpy's result.
"""

import math
import subprocess
import sys

import numpy as np
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.prognostics.metrics import (
    alpha_lambda_accuracy,
    cumulative_relative_accuracy,
    monotonicity,
    prognostic_horizon,
    prognostic_horizon_first,
)


def _profile(ages, rul):
    """progpy ToE profile of point predictions, ToE = age + RUL [h], as progpy's users build it."""
    from progpy.predictors import ToEPredictionProfile
    from progpy.uncertain_data import ScalarData

    profile = ToEPredictionProfile()
    for t, r in zip(ages, rul):
        profile.add_prediction(float(t), ScalarData({"EOL": float(t) + float(r)}))
    return profile


def _unit(seed, n=25, life=8000.0):
    """Prediction ages [h], true and noisy predicted RULs [h] of one unit failing at ``life``."""
    rng = np.random.default_rng(seed)
    ages = np.sort(rng.uniform(0.0, 0.95 * life, n))
    true = life - ages
    pred = true * (1.0 + 0.25 * rng.standard_normal(n))
    return ages, true, np.clip(pred, 0.0, None)


def test_progpy_is_imported_lazily():
    # progpy's import takes ~2 s: importing the package must not pay it
    code = (
        "import prsm_health, prsm_health.prognostics, prsm_health.prognostics.metrics, sys; "
        "print('progpy' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    assert out.stdout.strip() == "False"


# --- cumulative relative accuracy (Saxena section 6.3) ------------------------------------


def _cra_reference(true, pred):
    """Saxena's CRA, uniform weights: mean of RA = 1 - |r* - r| / r* over instants with r* > 0."""
    true, pred = np.asarray(true, float), np.asarray(pred, float)
    keep = true > 0
    return float(np.mean(1.0 - np.abs(true[keep] - pred[keep]) / true[keep]))


def test_cra_through_progpy_equals_saxena_formula():
    assert cumulative_relative_accuracy([50, 40, 30, 20, 10], [70, 45, 55, 25, 12]) == (
        pytest.approx((0.6 + 0.875 + 1 / 6 + 0.75 + 0.8) / 5)
    )
    for seed in range(3):
        _, true, pred = _unit(seed)
        true[-1], pred[-1] = 0.0, 3.0  # r* = 0: RA undefined, skipped
        assert cumulative_relative_accuracy(true, pred) == pytest.approx(
            _cra_reference(true, pred), rel=1e-12
        )
    # samples: RA of their mean
    rng = np.random.default_rng(5)
    samples = 100.0 + 10.0 * rng.standard_normal((3, 50))
    true = [90.0, 100.0, 120.0]
    assert cumulative_relative_accuracy(true, samples) == pytest.approx(
        _cra_reference(true, samples.mean(axis=1)), rel=1e-12
    )
    assert math.isnan(cumulative_relative_accuracy([0.0, 0.0], [1.0, 0.0]))


def test_progpy_own_cra_divides_by_the_time_of_event_not_the_true_rul():
    # why cumulative_relative_accuracy does not call progpy.metrics.cumulative_relative_accuracy
    from progpy.metrics import cumulative_relative_accuracy as progpy_cra

    ages, true, pred = _unit(1)
    life = 8000.0
    theirs = progpy_cra(_profile(ages, pred), {"EOL": life})["EOL"]
    assert theirs == pytest.approx(1.0 - np.mean(np.abs(pred - true)) / life, rel=1e-9)
    assert abs(theirs - _cra_reference(true, pred)) > 0.05


# --- monotonicity (Coble & Hines 2009, as in progpy) --------------------------------------


def _monotonicity_reference(pred):
    steps = np.sign(np.diff(np.asarray(pred, float)))
    return float(abs(steps.sum()) / steps.size)


def test_monotonicity_through_progpy_equals_the_formula():
    ages = [0.0, 10.0, 20.0, 30.0, 40.0]
    assert monotonicity(ages, [50, 40, 30, 20, 10]) == 1.0
    assert monotonicity(ages, [10, 20, 30, 40, 50]) == 1.0
    assert monotonicity(ages, [70, 45, 55, 25, 12]) == 0.5  # -1 +1 -1 -1
    for seed in range(3):
        a, _, pred = _unit(seed)
        assert monotonicity(a, pred) == _monotonicity_reference(pred)


def test_monotonicity_keeps_equal_predictions_equal():
    # RULs capped at a horizon: progpy's (age + RUL) - age on raw floats turns the flat
    # stretch into +-1 ulp steps; the metric snaps ages and RULs to a dyadic grid first
    from progpy.metrics import monotonicity as progpy_monotonicity

    ages = [3118.3, 4092.0, 5118.2, 8277.0, 9486.5]
    rul = [30000.3, 30000.3, 30000.3, 30000.3, 500.0]
    assert _monotonicity_reference(rul) == 0.25
    assert monotonicity(ages, rul) == 0.25
    assert progpy_monotonicity(_profile(ages, rul))["EOL"] != 0.25  # the naive profile


# --- alpha-lambda (Saxena section 6.2) ----------------------------------------------------


def test_progpy_alpha_lambda_tests_the_same_cone_at_one_instant():
    # progpy's alpha_lambda at lambda = each prediction age is that prediction's in-cone
    # indicator: their mean is the project's fraction (away from the bounds)
    from progpy.metrics import alpha_lambda

    life, alpha = 8000.0, 0.2
    for seed in range(3):
        ages, true, pred = _unit(seed)
        off_bound = np.abs(np.abs(pred - true) - alpha * true) > 1e-6 * true
        ages, true, pred = ages[off_bound], true[off_bound], pred[off_bound]
        profile = _profile(ages, pred)
        each = [alpha_lambda(profile, {"EOL": life}, t, alpha, 1.0)["EOL"] for t in ages]
        assert np.mean(each) == alpha_lambda_accuracy(true, pred, alpha)


def test_progpy_alpha_lambda_differs_on_the_bounds_and_in_what_it_answers():
    from progpy.metrics import alpha_lambda

    # on the bound (1 + alpha) r*, and an exact 0 at r* = 0: inside here, outside in progpy
    assert alpha_lambda_accuracy([100.0], [120.0]) == 1.0
    assert alpha_lambda(_profile([0.0], [120.0]), {"EOL": 100.0}, 0.0, 0.2, 1.0) == {"EOL": False}
    assert alpha_lambda_accuracy([0.0], [0.0]) == 1.0
    assert alpha_lambda(_profile([50.0], [0.0]), {"EOL": 50.0}, 50.0, 0.2, 1.0) == {"EOL": False}


# --- prognostic horizon (Saxena section 6.1) ----------------------------------------------


def _ph_stay_reference(ages, true, pred, life, alpha):
    """PH from the earliest age after which every prediction is inside r* +- alpha EoL."""
    inside = np.abs(np.asarray(pred) - np.asarray(true)) <= alpha * life
    if not inside[-1]:
        return 0.0
    out = np.flatnonzero(~inside)
    return float(life - ages[0 if out.size == 0 else out[-1] + 1])


def test_prognostic_horizons_agree_when_predictions_stay_inside():
    life, alpha = 8000.0, 0.2
    for seed in range(3):
        rng = np.random.default_rng(seed)
        ages = np.sort(rng.uniform(0.0, 0.95 * life, 25))
        true = life - ages
        # errors shrinking from 0.5 EoL: they enter the bounds once and for all
        pred = true + 0.5 * life * (1.0 - ages / life) ** 2 * rng.choice([-1.0, 1.0], 25)
        ours = prognostic_horizon(ages, true, pred, life, alpha)
        assert ours == _ph_stay_reference(ages, true, pred, life, alpha)
        assert prognostic_horizon_first(ages, pred, life, alpha) == pytest.approx(ours, abs=1e-5)


def test_prognostic_horizons_differ_when_predictions_leave_the_bounds():
    ages, true, life = [0, 10, 20, 30, 40], [50, 40, 30, 20, 10], 50.0
    pred = [70, 45, 55, 25, 12]  # errors 20 (out), 5 (in), 25 (out), 5, 2: bounds +-10 h
    assert prognostic_horizon(ages, true, pred, life) == 20.0  # from 30 h, inside for good
    assert prognostic_horizon_first(ages, pred, life) == 40.0  # from 10 h, first inside
    assert prognostic_horizon(ages, true, [50, 40, 30, 20, 31], life) == 0.0  # ends outside
    assert prognostic_horizon_first(ages, [50, 40, 30, 20, 31], life) == 50.0
    assert prognostic_horizon_first(ages, [90, 80, 70, 60, 50], life) == 0.0  # never inside
    # samples: beta, the share inside [30, 50] h at 10 h
    samples = np.tile(np.asarray(pred, float)[:, None], (1, 4))
    samples[1] = [35.0, 45.0, 49.0, 55.0]  # 3 of 4 inside
    assert prognostic_horizon_first(ages, samples, life, beta=0.75) == 40.0
    assert prognostic_horizon_first(ages, samples, life, beta=0.8) == 20.0  # from 30 h


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: cumulative_relative_accuracy([1.0, -1.0], [1.0, 1.0]), "true_rul[1]"),
        (lambda: cumulative_relative_accuracy([1.0, 2.0], [1.0]), "pred"),
        (lambda: cumulative_relative_accuracy([1.0], [[np.nan]]), "pred[0, 0]"),
        (lambda: monotonicity([0.0], [1.0]), ">= 2 predictions"),
        (lambda: monotonicity([0.0, 0.0], [1.0, 1.0]), "ages[1]"),
        (lambda: monotonicity([0.0, 1e-9], [1.0, 1.0]), "apart"),
        (lambda: prognostic_horizon_first([0.0], [50.0], 0.0), "failure_age"),
    ],
)
def test_progpy_metric_input_errors(call, words):
    with pytest.raises(ParameterError) as info:
        call()
    assert words in str(info.value) and "\n" not in str(info.value)
