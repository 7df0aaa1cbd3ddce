"""The shipped prognostics model's recipe and its evaluation (``models/prognostics.json``).

How the shipped RUL model is built and judged, as functions a user can call to rebuild and
check it for their own fleet recipe:

1. :func:`diagnosed_fleet` — generates the fleet recipe (``datasets/fleet-check.toml``: 20
   units × 10 health checks over their lives, resumable) and diagnoses every check with the
   shipped diagnosis model — the clearance measured from the check's lost motion, each unit
   commissioned by its first check (:func:`~prsm_health.prognostics.fleet_histories`) — as
   the histories a user's fleet would give (cached beside the dataset as
   ``<dataset>-diagnoses.parquet``);
2. :func:`train_prognostics_model` — fits the model with
   :func:`~prsm_health.prognostics.fit_prognostics_model` (what ``prsm-health train FLEET
   --target rul`` runs) on the training units, its failure threshold on the *diagnosed*
   clearance (:func:`~prsm_health.prognostics.diagnosed_threshold`: the recipe's limit is on the
   true clearance, which the diagnosis reads with its own bias); scores the three methods
   (degradation model, similarity baseline, physics) on the held-out units, every history
   prefix (RMSE, α–λ accuracy after half of life, 90 % interval coverage, prognostic horizon:
   :mod:`prsm_health.prognostics.metrics`), and on every unit of the fleet, each predicted by
   a model fitted without it (:data:`FOLDS` folds,
   :func:`~prsm_health.prognostics.cross_validate_units`): the default method is the one with
   the best cross-validated α–λ accuracy after half of life (the held-out split alone is 6
   units, whose score moves by ±0.2 with the split); measures what limits it
   (:func:`sensitivity`); writes the model, its metrics (:func:`prognostics_metrics`, JSON) and
   its card (:func:`~prsm_health.release.prognostics_card.write_prognostics_card`).

Figures (:data:`FIGURES`) are drawn by the caller (``prsm_health.apps.plots.plot_prognostics``,
a layer above this one) from the tables :func:`train_prognostics_model` returns.
``tools/release/train_prognostics_model.py`` is the command line of this module.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from prsm_health.core.errors import PRSMHealthError
from prsm_health.datasets import Dataset, Recipe, generate, load_recipe
from prsm_health.prognostics import (
    DEFAULT_PROGNOSTICS_MODEL,
    HISTORY_COLUMNS,
    RULModel,
    cross_validate_units,
    fit_prognostics_model,
    fleet_histories,
    load_prognostics_model,
    save_prognostics_model,
    simulated_histories,
)
from prsm_health.prognostics.metrics import evaluate_units
from prsm_health.release.prognostics_card import write_prognostics_card

#: The fleet recipe of the shipped model (repository layout, like :data:`DEFAULT_PROGNOSTICS_MODEL`).
FLEET_RECIPE = DEFAULT_PROGNOSTICS_MODEL.parents[1] / "datasets" / "fleet-check.toml"
#: α of the α–λ accuracy and of the prognostic horizon.
ALPHA = 0.2
#: Folds over the units of the cross-validated score (and of the default method's choice).
FOLDS = 4
#: Life fractions the accuracy-by-age table bins the cross-validated predictions in.
LIFE_BINS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
#: Sensitivity study: usage variability and health-indicator noise (life model only, no
#: dynamics): 60 units each, 40 to fit, 20 to score.
USAGE_LEVELS = (0.0, 0.15, 0.3)
#: m, 1σ of a diagnosis' error: a commissioned check ≈ 0.3–0.5 µm, an in-service window ≈ 2 µm
NOISE_LEVELS = (0.0, 0.3e-6, 1e-6, 2e-6)
#: The figures the card links, drawn by ``prsm_health.apps.plots.plot_prognostics``.
FIGURES = ("prognostics_rul.png", "prognostics_indicator.png")


@dataclass(frozen=True)
class PrognosticsModelResult:
    """What :func:`train_prognostics_model` wrote, and the tables for the figures."""

    model: RULModel
    metrics: dict
    histories: pd.DataFrame
    """Every snapshot's diagnosis (:func:`diagnosed_fleet`)."""
    predictions: pd.DataFrame
    """The held-out units' predictions (every method, every history prefix)."""
    model_path: Path
    metrics_path: Path
    card_path: Path


def fleet_recipe(path: str | Path = FLEET_RECIPE) -> Recipe:
    """The fleet recipe of the prognostics model (default: the shipped
    ``datasets/fleet-check.toml``)."""
    return load_recipe(path)


def diagnosed_fleet(
    recipe: Recipe, dataset_dir: str | Path, *, workers: int = 2, progress: bool = False
) -> tuple[pd.DataFrame, dict]:
    """Generate ``recipe`` into ``dataset_dir`` unless complete, and diagnose every snapshot with
    the shipped diagnosis model (cached as ``<dataset_dir>-diagnoses.parquet``).

    Returns
    -------
    histories : pandas.DataFrame
        :func:`~prsm_health.prognostics.fleet_histories`' table.
    generation : dict
        ``runs``, ``resumed_runs``, ``workers`` and ``seconds`` (the generation's wall time;
        None when part of the dataset was already there, so the time is not the whole one's).
    """
    report = generate(recipe, dataset_dir, workers=workers, progress=progress)
    generation = {
        "runs": report.total_runs,
        "resumed_runs": report.resumed_runs,
        "workers": workers,
        "seconds": report.seconds if report.resumed_runs == 0 else None,
    }
    cache = Path(str(dataset_dir).rstrip("/") + "-diagnoses.parquet")
    if cache.exists():
        return pd.read_parquet(cache), generation
    histories = fleet_histories(Dataset(dataset_dir), progress=progress)
    histories.to_parquet(cache)
    return histories, generation


def held_out_scores(
    model: RULModel, histories: pd.DataFrame, *, alpha: float = ALPHA, progress: bool = False
) -> tuple[pd.DataFrame, dict]:
    """A fitted model scored as it is on the held-out units (split ``test``) of ``histories``:
    every method it can run (physics only when it carries the fleet's ageing model)."""
    test = histories[histories["split"] == "test"]
    failure = test.groupby("unit_id")["failure_age_hours"].first().to_dict()
    physics = getattr(model, "ageing_", None) is not None
    methods = ("degradation", "similarity") + (("physics",) if physics else ())
    return evaluate_units(test, failure, model, alpha=alpha, methods=methods, progress=progress)


def accuracy_by_age(
    predictions: pd.DataFrame, *, alpha: float = ALPHA, bins: tuple = LIFE_BINS
) -> dict:
    """α–λ accuracy of each method in bins of life fraction (the α cone narrows to the end of
    life): ``{"bins": [[lo, hi], …], "methods": {method: [share inside, …]}}`` (NaN for an
    empty bin)."""
    life = predictions["age_hours"] + predictions["true_rul"]
    share = predictions["age_hours"] / life
    inside = (predictions["estimate"] - predictions["true_rul"]).abs() <= alpha * predictions[
        "true_rul"
    ]
    edges = list(zip(bins[:-1], bins[1:]))
    methods = {}
    for method in predictions["method"].unique():
        mine = predictions["method"] == method
        methods[str(method)] = [
            float(inside[mine & (share >= lo) & (share < hi)].mean()) for lo, hi in edges
        ]
    return {"bins": [[lo, hi] for lo, hi in edges], "methods": methods}


def per_unit_scores(
    predictions: pd.DataFrame,
    failure_ages: dict,
    failure_modes: dict,
    *,
    method: str = "degradation",
    alpha: float = ALPHA,
) -> list[dict]:
    """Each unit's scores after half of its life, one method: α–λ accuracy, 90 % interval
    coverage and RMSE [h], with its life [h] and failure mode."""
    rows = []
    chosen = predictions[predictions["method"] == method]
    for unit, p in chosen.groupby("unit_id"):
        life = float(failure_ages[unit])
        late = p[p["age_hours"] >= 0.5 * life]
        err = late["estimate"] - late["true_rul"]
        rows.append(
            {
                "unit": int(unit),
                "life_hours": life,
                "failure_mode": str(failure_modes[unit]),
                "alpha_lambda": float((np.abs(err) <= alpha * late["true_rul"]).mean()),
                "coverage": float(
                    (
                        (late["lower"] <= late["true_rul"]) & (late["true_rul"] <= late["upper"])
                    ).mean()
                ),
                "rmse": float(np.sqrt(np.mean(err**2))),
            }
        )
    return rows


def sensitivity(recipe: Recipe, *, alpha: float = ALPHA) -> dict:
    """α–λ accuracy and 90 % coverage after half of life (degradation and similarity) against
    usage variability (:data:`USAGE_LEVELS`) and health-indicator noise (:data:`NOISE_LEVELS`):
    the life model's trajectories (60 units, 40 fitted, 20 scored; no dynamics) observed with
    Gaussian errors of a given σ (intervals ±1.645σ, at least ±0.2 µm), so what limits a RUL
    is seen apart from the diagnosis.

    Returns
    -------
    dict
        ``usage``, ``noise`` [m] and ``cells``: per usage level, per noise level,
        ``{method: {"alpha_lambda", "coverage_after"}}``.
    """
    from prsm_health.actuator.design_files import load_design
    from prsm_health.physics.life import fleet_lives

    spec0 = recipe.life_spec
    cells = []
    for usage in USAGE_LEVELS:
        spec = replace(spec0, units=60, scatter=replace(spec0.scatter, usage=usage))
        lives = fleet_lives(load_design(recipe.design), spec, recipe.seed + 1)
        failure = {u.unit_id: u.failure_age for u in lives}
        row = []
        for noise in NOISE_LEVELS:
            rng = np.random.default_rng([recipe.seed, int(noise * 1e9)])
            table = simulated_histories(lives, spec.snapshots, noise, rng, min_half_width=0.2e-6)
            table = table[["unit_id", *HISTORY_COLUMNS]]
            train, test = table[table["unit_id"] < 40], table[table["unit_id"] >= 40]
            model = RULModel(threshold=spec.failure_clearance, design=recipe.design)
            model.fit(train, {u: failure[u] for u in range(40)})
            _, summary = evaluate_units(
                test, {u: failure[u] for u in range(40, 60)}, model, alpha=alpha
            )
            row.append(
                {
                    m: {k: float(summary[m][k]) for k in ("alpha_lambda", "coverage_after")}
                    for m in ("degradation", "similarity")
                }
            )
        cells.append(row)
    return {"usage": list(USAGE_LEVELS), "noise": list(NOISE_LEVELS), "cells": cells}


def indicator_errors(histories: pd.DataFrame) -> dict:
    """How the fleet's diagnosed clearance reads the true installed clearance, every snapshot:
    ``bias``, ``sd`` [m] of the error, ``unit_bias_sd`` [m] (sd of the units' mean errors),
    ``coverage`` of the 90 % intervals."""
    error = histories["clearance"] - histories["clearance_mean_true"]
    inside = (histories["clearance_lower"] <= histories["clearance_mean_true"]) & (
        histories["clearance_mean_true"] <= histories["clearance_upper"]
    )
    return {
        "bias": float(error.mean()),
        "sd": float(error.std()),
        "unit_bias_sd": float(error.groupby(histories["unit_id"]).mean().std()),
        "coverage": float(inside.mean()),
    }


def _plain(value):
    """``value`` as plain JSON: numpy scalars as Python numbers, a NaN (a score of no
    prediction, an empty bin) as None — the card prints it as missing."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def prognostics_metrics(
    recipe: Recipe,
    model: RULModel,
    histories: pd.DataFrame,
    held_out: tuple[pd.DataFrame, dict],
    cross_validated: tuple[pd.DataFrame, dict],
    generation: dict,
    limits: dict,
    *,
    alpha: float = ALPHA,
) -> dict:
    """Everything the card prints, as plain JSON (``models/prognostics.metrics.json``; a score
    that could not be computed, e.g. a bin without predictions, is None).

    Parameters
    ----------
    recipe : Recipe
        The fleet recipe.
    model : RULModel
        The fitted model (its form, threshold and default method).
    histories : pandas.DataFrame
        Every snapshot's diagnosis (the units' lives, failure modes and splits).
    held_out, cross_validated : (predictions, summary)
        :func:`held_out_scores` (or the fit's) and
        :func:`~prsm_health.prognostics.cross_validate_units`' results.
    generation : dict
        :func:`diagnosed_fleet`'s.
    limits : dict
        :func:`sensitivity`'s.

    Returns
    -------
    dict
        ``alpha``, ``model``, ``fleet``, ``held_out``, ``cross_validated`` (``folds``,
        ``summary``, ``accuracy_by_age``, ``alpha_lambda_50_80``: α–λ accuracy pooled between 50
        and 80 % of life), ``indicator`` (:func:`indicator_errors`),
        ``per_unit`` (the held-out units, the default method), ``sensitivity`` and ``figures``.
    """
    predictions, summary = held_out
    cv_predictions, cv_summary = cross_validated
    spec = recipe.life_spec
    lives = histories.groupby("unit_id")[["failure_age_hours", "failure_mode", "split"]].first()
    modes = lives["failure_mode"].value_counts()
    metrics = {
        "alpha": alpha,
        "model": {"form": model.form_, "threshold": float(model.threshold), "method": model.method},
        "fleet": {
            "recipe": recipe.name,
            "check": bool(recipe.profile.get("check")),
            "units": spec.units,
            "snapshots": spec.snapshots,
            "recordings": spec.recordings,
            "duration": recipe.duration,
            "failure_clearance": spec.failure_clearance,
            "failure_spall_length": spec.failure_spall_length,
            "generation": generation,
            "lives_hours": [
                float(lives["failure_age_hours"].min()),
                float(lives["failure_age_hours"].max()),
            ],
            "failure_modes": {str(k): int(v) for k, v in modes.items()},
            "train_units": sorted(int(u) for u in lives.index[lives["split"] == "train"]),
            "test_units": sorted(int(u) for u in lives.index[lives["split"] == "test"]),
        },
        "held_out": summary,
        "cross_validated": {
            "folds": FOLDS,
            "summary": cv_summary,
            "accuracy_by_age": accuracy_by_age(cv_predictions, alpha=alpha),
            "alpha_lambda_50_80": {
                m: v[0]
                for m, v in accuracy_by_age(cv_predictions, alpha=alpha, bins=(0.5, 0.8))[
                    "methods"
                ].items()
            },
        },
        "indicator": indicator_errors(histories),
        "per_unit": per_unit_scores(
            predictions,
            lives["failure_age_hours"].to_dict(),
            lives["failure_mode"].to_dict(),
            method=model.method,
            alpha=alpha,
        ),
        "sensitivity": limits,
        "figures": list(FIGURES),
    }
    return _plain(metrics)


def train_prognostics_model(
    out_dir: str | Path,
    recipe: Recipe | None = None,
    *,
    dataset: str | Path,
    workers: int = 2,
    evaluate_only: bool = False,
    progress: bool = False,
) -> PrognosticsModelResult:
    """Build the prognostics model from its fleet recipe, evaluate it and write its card.

    Writes ``out_dir/prognostics.json`` (unless ``evaluate_only``),
    ``out_dir/prognostics.metrics.json`` (:func:`prognostics_metrics`) and
    ``out_dir/PROGNOSTICS_CARD.md``.

    Parameters
    ----------
    out_dir : path
        Where the model, its metrics and its card go (the shipped ones: ``models/``).
    recipe : Recipe or None
        The fleet recipe (default: :func:`fleet_recipe`).
    dataset : path
        Where the fleet is generated (resumable) and its diagnoses cached.
    workers : int
        Generation processes.
    evaluate_only : bool
        Re-score the model already in ``out_dir`` without fitting it.
    progress : bool
        Progress bars on stderr.

    Returns
    -------
    PrognosticsModelResult

    Raises
    ------
    PRSMHealthError
        ``evaluate_only`` without a model in ``out_dir``; the errors of generation and fitting.
    """
    out_dir = Path(out_dir)
    recipe = fleet_recipe() if recipe is None else recipe
    model_path = out_dir / "prognostics.json"
    if evaluate_only and not model_path.exists():
        raise PRSMHealthError(f"evaluate_only: {model_path} must exist (train first)")
    out_dir.mkdir(parents=True, exist_ok=True)
    histories, generation = diagnosed_fleet(recipe, dataset, workers=workers, progress=progress)
    fleet = Dataset(dataset)
    if evaluate_only:  # the model as it is: no fit
        model = load_prognostics_model(model_path)
        held_out = held_out_scores(model, histories, progress=progress)
    else:
        model, fit = fit_prognostics_model(
            fleet, histories=histories, alpha=ALPHA, progress=progress
        )
        held_out = fit.predictions, fit.summary
    cross = cross_validate_units(fleet, histories, folds=FOLDS, alpha=ALPHA, progress=progress)
    if not evaluate_only:
        # the default: the best α–λ accuracy after half of life over every unit
        model.method = max(cross[1], key=lambda m: cross[1][m]["alpha_lambda"])
        save_prognostics_model(model_path, model)
    metrics = prognostics_metrics(
        recipe, model, histories, held_out, cross, generation, sensitivity(recipe)
    )
    metrics_path = out_dir / "prognostics.metrics.json"
    metrics_path.write_text(json.dumps(metrics, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    card_path = write_prognostics_card(metrics, out_dir / "PROGNOSTICS_CARD.md")
    return PrognosticsModelResult(
        model, metrics, histories, held_out[0], model_path, metrics_path, card_path
    )
