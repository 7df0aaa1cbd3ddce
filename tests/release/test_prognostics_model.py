"""prsm_health.release.prognostics_model: the prognostics model's recipe and the numbers of its
card, on hand-made predictions with known scores (fitting and scoring themselves are tested in
tests/prognostics; the release run is tools/release/train_prognostics_model.py)."""

import json
import types

import numpy as np
import pandas as pd
import pytest

from prsm_health.core.errors import PRSMHealthError
from prsm_health.release.prognostics_card import prognostics_card
from prsm_health.release.prognostics_model import (
    FIGURES,
    FLEET_RECIPE,
    FOLDS,
    accuracy_by_age,
    fleet_recipe,
    per_unit_scores,
    prognostics_metrics,
    train_prognostics_model,
)


def predictions(unit, life, ages, errors, method="degradation", half_width=10.0):
    """One unit's predictions at ``ages`` [h], each ``errors`` [h] off the true RUL."""
    true = life - np.asarray(ages, float)
    estimate = true + np.asarray(errors, float)
    return pd.DataFrame(
        {
            "unit_id": unit,
            "method": method,
            "age_hours": ages,
            "true_rul": true,
            "estimate": estimate,
            "lower": estimate - half_width,
            "upper": estimate + half_width,
        }
    )


def test_fleet_recipe_is_the_shipped_fleet():
    assert FLEET_RECIPE.name == "fleet-check.toml"
    recipe = fleet_recipe()
    assert recipe.name == "fleet-check" and recipe.life_spec.units == 20
    assert recipe.profile["check"] == "health-check"  # checks, read by the clearance gauge


def test_accuracy_by_age_bins_each_method_by_life_fraction():
    # life 100 h, one prediction per bin: exact before 80 % of life, 50 % of the RUL off after
    ages = [55.0, 65.0, 75.0, 85.0, 95.0]
    errors = [0.0, 0.0, 0.0, 7.5, 2.5]
    table = pd.concat(
        [
            predictions(0, 100.0, ages, errors),
            predictions(0, 100.0, ages, [0.0] * 5, method="similarity"),
        ]
    )
    by_age = accuracy_by_age(table, alpha=0.2)
    assert by_age["bins"][0] == [0.5, 0.6] and len(by_age["bins"]) == 5
    assert by_age["methods"] == {"degradation": [1, 1, 1, 0, 0], "similarity": [1] * 5}


def test_per_unit_scores_count_only_the_second_half_of_life():
    # life 100 h: the prediction at 20 h (80 h off) is before half of life and not scored
    table = predictions(3, 100.0, [20.0, 60.0, 80.0], [80.0, 4.0, 30.0], half_width=10.0)
    (row,) = per_unit_scores(table, {3: 100.0}, {3: "wear"}, alpha=0.2)
    assert row["unit"] == 3 and row["failure_mode"] == "wear"
    assert row["alpha_lambda"] == 0.5  # 4 ≤ 0.2·40 inside, 30 > 0.2·20 outside
    assert row["coverage"] == 0.5  # ±10 h holds the truth 4 h off, not 30 h off
    assert row["rmse"] == pytest.approx(np.sqrt((4.0**2 + 30.0**2) / 2))


def _summary(n):
    keys = ("alpha_lambda", "alpha_lambda_all", "coverage_after", "coverage", "rmse_after")
    entry = {k: np.float64(0.5) for k in keys}
    entry.update(
        rmse=np.float64(120.4),
        prognostic_horizon=np.float64(900.0),
        prognostic_horizon_first=np.float64(1000.0),
        cra=np.float64(0.7),
        monotonicity=np.float64(0.6),
        n_predictions=np.int64(n),
    )
    return {"degradation": entry, "similarity": dict(entry)}


def test_the_metrics_are_json_and_render_the_card():
    recipe = fleet_recipe()
    held = pd.concat([predictions(u, 100.0 * (u + 1), [60.0, 90.0], [1.0, 2.0]) for u in (1, 2)])
    histories = pd.DataFrame(
        {
            "unit_id": [0, 1, 2],
            "failure_age_hours": [100.0, 200.0, 300.0],
            "failure_mode": ["wear", "wear", "spall"],
            "split": ["train", "test", "test"],
            "clearance": [10e-6, 21e-6, 30e-6],
            "clearance_lower": [9e-6, 20e-6, 29.5e-6],
            "clearance_upper": [11e-6, 22e-6, 30.5e-6],
            "clearance_mean_true": [10.5e-6, 20e-6, 31e-6],  # errors −0.5, +1, −1 µm
        }
    )
    model = types.SimpleNamespace(form_="linear", threshold=3.25e-5, method="degradation")
    generation = {"runs": 180, "resumed_runs": 0, "workers": 3, "seconds": 95.2}
    limits = {
        "usage": [0.0],
        "noise": [0.0, 2e-6],
        "cells": [[{m: {"alpha_lambda": 0.5, "coverage_after": 0.9} for m in ("degradation", "similarity")}] * 2],
    }  # fmt: skip
    metrics = prognostics_metrics(
        recipe, model, histories, (held, _summary(4)), (held, _summary(4)), generation, limits
    )
    stored = json.loads(json.dumps(metrics, allow_nan=False))  # plain JSON, no numpy
    assert stored == metrics
    assert stored["fleet"]["train_units"] == [0] and stored["fleet"]["test_units"] == [1, 2]
    assert stored["fleet"]["failure_modes"] == {"wear": 2, "spall": 1}
    assert stored["cross_validated"]["folds"] == FOLDS
    assert [r["unit"] for r in stored["per_unit"]] == [1, 2]
    assert stored["figures"] == list(FIGURES)
    card = prognostics_card(stored)
    assert "degradation model (`linear` form" in card
    assert "Default method: **`degradation`**" in card
    assert "default method `degradation`, after half of life" in card
    # the indicator's errors from the histories: mean −1/6 µm, two of three intervals cover
    assert stored["indicator"]["coverage"] == pytest.approx(2 / 3)
    assert "bias -0.17 µm" in card and "covering 0.67" in card
    assert "× 10 ages × 1 health check of 2.62 s" in card and "`datasets/fleet-check.toml`" in card
    assert "Between 50 and 80 % of life, pooled: degradation –" in card  # no prediction there
    assert "(180 runs; generated in 95 s on 3 workers)" in card
    assert "scored on the 2 held-out units ([1, 2])" in card
    assert "Lives 100–300 h; failure modes wear 2, spall 1." in card
    assert "32.50 µm" in card
    assert (
        "| similarity | 0.500 | 0.500 | 0.500 | 0.500 | 0 | 120 | 900 / 1000 | 0.700 | 0.600 | 4 |"
        in card
    )
    assert "[prognostics_rul](figures/prognostics_rul.png)" in card
    # these predictions are all before half of life: the by-age bins are empty, not zero
    assert stored["cross_validated"]["accuracy_by_age"]["methods"]["degradation"] == [None] * 5
    assert "| degradation | – | – | – | – | – |" in card


def test_evaluate_only_needs_a_model(tmp_path):
    with pytest.raises(PRSMHealthError, match="evaluate_only"):
        train_prognostics_model(tmp_path, dataset=tmp_path / "fleet", evaluate_only=True)
    assert list(tmp_path.iterdir()) == []  # nothing generated
