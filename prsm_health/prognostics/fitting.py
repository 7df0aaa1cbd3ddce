"""Fitting a prognostics model for a fleet of any design: the fleet's snapshots diagnosed into
histories, the model fitted on the training units, scored on the held-out ones.

A fleet is a dataset generated from a life recipe (``[life]``, docs/prognostics.md) of the
design the model is for — a preset or one's own design file. The model carries that design
(its name and fingerprint), so it refuses the histories of another design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from prsm_health.actuator.design_files import design_fingerprint, same_design
from prsm_health.core.errors import PRSMHealthError, require

from .ageing_rul import PhysicsRUL
from .fleet import fleet_histories
from .metrics import evaluate_units, pooled_scores
from .rul import RULModel

#: Diagnoses of a unit's last share of life used to read the indicator at failure.
LAST_SHARE = 0.25
#: Accuracy bound of the held-out score's α–λ accuracy and prognostic horizon.
ALPHA = 0.2


def diagnosed_threshold(
    train: pd.DataFrame, last_share: float = LAST_SHARE, failure_clearance: float | None = None
) -> float:
    """The diagnosed clearance at failure [m], learnt from the training units.

    A unit fails when its *true* clearance reaches the recipe's limit; the diagnosis reads
    the clearance with its own bias, so the model's threshold is on the diagnosed clearance.
    Where the training histories carry the true mean clearance (``clearance_mean_true``, a
    simulated fleet) and the limit ``failure_clearance`` is given: the limit plus the
    diagnosis' bias late in life — the median over the units of each one's mean diagnosed
    minus true clearance in its last ``last_share`` of life. Otherwise: the median over the
    units of a straight line through each one's diagnoses in its last ``last_share`` of life
    (at least its last two), evaluated at its failure age — which reads an accelerating
    wear curve low (measured on the shipped fleet: 31.8 µm against 32.7 µm from its bias).

    Parameters
    ----------
    train : pandas.DataFrame
        ``unit_id``, ``age_hours`` [h], ``clearance`` [m], ``failure_age_hours`` [h];
        optionally ``clearance_mean_true`` [m].
    last_share : float
        Share of a unit's life, at its end, whose diagnoses are used, in (0, 1].
    failure_clearance : float or None [m]
        The true limit (the life recipe's ``failure_clearance``).
    """
    by_truth = failure_clearance is not None and "clearance_mean_true" in train.columns
    values = []
    for _, unit in train.groupby("unit_id"):
        unit = unit.sort_values("age_hours")
        failure = float(unit["failure_age_hours"].iloc[0])
        late = unit["age_hours"] >= (1 - last_share) * failure
        late.iloc[-2:] = True  # a coarse history has few diagnoses in its last share
        if by_truth:
            bias = unit["clearance"][late] - unit["clearance_mean_true"][late]
            values.append(failure_clearance + float(bias.mean()))
            continue
        slope, intercept = np.polyfit(unit["age_hours"][late], unit["clearance"][late], 1)
        values.append(intercept + slope * failure)
    return float(np.median(values))


@dataclass
class FitReport:
    """What :func:`fit_prognostics_model` did: the data, the threshold and the held-out score."""

    design: str
    """Name of the fleet's design."""
    design_fingerprint: str | None
    threshold: float
    """The model's failure threshold on the diagnosed clearance [m]."""
    threshold_learnt: bool
    """True when learnt from the training units (:func:`diagnosed_threshold`)."""
    true_failure_clearance: float | None
    """The life recipe's limit on the true clearance [m], for comparison."""
    train_units: list
    test_units: list
    histories: pd.DataFrame = field(repr=False)
    """Every snapshot's diagnosis (:func:`~prsm_health.prognostics.fleet_histories`)."""
    predictions: pd.DataFrame | None = field(repr=False)
    """Held-out predictions (:func:`~prsm_health.prognostics.metrics.evaluate_units`); None
    without held-out units."""
    summary: dict = field(default_factory=dict)
    """Per method: the held-out metrics (RMSE, α–λ accuracy, coverage, prognostic horizon)."""

    def as_dict(self) -> dict:
        """The report without its tables, JSON-able (for a CLI's ``--json``)."""
        return {
            "design": self.design,
            "design_fingerprint": self.design_fingerprint,
            "threshold": self.threshold,
            "threshold_learnt": self.threshold_learnt,
            "true_failure_clearance": self.true_failure_clearance,
            "train_units": [int(u) for u in self.train_units],
            "test_units": [int(u) for u in self.test_units],
            "snapshots": len(self.histories),
            "summary": self.summary,
        }


def fit_prognostics_model(
    fleet,
    *,
    bundle=None,
    threshold: float | None = None,
    histories: pd.DataFrame | None = None,
    method: str = "degradation",
    n_samples: int = 4000,
    random_state: int | None = 0,
    evaluate: bool = True,
    alpha: float = ALPHA,
    progress: bool = False,
) -> tuple[RULModel, FitReport]:
    """Fit a :class:`~prsm_health.prognostics.RULModel` on a fleet dataset of any design.

    1. Every snapshot is diagnosed (:func:`~prsm_health.prognostics.fleet_histories`) by
       ``bundle``, unless ``histories`` are given (e.g. kept from an earlier call).
    2. The model is fitted on the training units (split ``train``) against their true failure
       ages, with ``threshold`` on the diagnosed clearance (default: learnt,
       :func:`diagnosed_threshold`), for the fleet's design (name and fingerprint).
    3. With ``evaluate``, both methods are scored on the held-out units (split ``test``),
       every history prefix (:func:`~prsm_health.prognostics.metrics.evaluate_units`).

    Parameters
    ----------
    fleet : str, Path or :class:`~prsm_health.datasets.Dataset`
        A dataset generated from a life recipe.
    bundle : ModelBundle, optional
        The diagnosis model the histories are read with (default the shipped one); it must be
        trained on the fleet's design.
    threshold : float or None [m]
        Failure threshold on the diagnosed clearance; None learns it from the training units.
    histories : pandas.DataFrame, optional
        The fleet's diagnosed histories (columns of :func:`fleet_histories`), instead of
        diagnosing; they must be of the fleet's design.
    method, n_samples, random_state
        Of the :class:`RULModel`.
    evaluate : bool
        Score the held-out units.
    alpha : float
        Accuracy bound of the α–λ accuracy and prognostic horizon.
    progress : bool
        A progress bar while diagnosing.

    Returns
    -------
    model : RULModel
        Fitted; save it with :func:`~prsm_health.prognostics.save_prognostics_model`.
    report : FitReport

    Raises
    ------
    PRSMHealthError
        Not a fleet dataset; a diagnosis model of another design; histories of another
        design; fewer than 3 training units (a :class:`ParameterError`).
    """
    from prsm_health.datasets import Dataset

    dataset = fleet if isinstance(fleet, Dataset) else Dataset(fleet)
    design = dataset.design
    name = design.name if design is not None else str(dataset.runs["design"].iloc[0])
    if histories is None:
        if bundle is None:
            from prsm_health.diagnostics.diagnosis import load_bundle

            bundle = load_bundle()
        if _differs(getattr(bundle, "design", None), design):
            raise PRSMHealthError(
                f"the diagnosis model is for design {bundle.design.name!r}, the fleet "
                f"{dataset.path} is of design {name!r}: pass bundle= a model trained on the "
                "fleet's design (prsm-health train on a dataset of it)"
            )
        histories = fleet_histories(dataset, bundle, progress=progress)
    require(
        isinstance(histories, pd.DataFrame)
        and {"unit_id", "split", "failure_age_hours"} <= set(histories.columns),
        "histories",
        type(histories).__name__,
        "must be the table fleet_histories returns (unit_id, split, failure_age_hours, …)",
    )
    failure = histories.groupby("unit_id")["failure_age_hours"].first().to_dict()
    train = histories[histories["split"] == "train"]
    test = histories[histories["split"] == "test"]
    spec = _life_spec(dataset)
    learnt = threshold is None
    model = _fitted_model(
        train,
        failure,
        design=design,
        name=name,
        spec=spec,
        threshold=threshold,
        method=method,
        n_samples=n_samples,
        random_state=random_state,
    )
    methods = _methods(model)
    predictions, summary = None, {}
    if evaluate and not test.empty:
        predictions, summary = evaluate_units(
            test,
            {u: failure[u] for u in test["unit_id"].unique()},
            model,
            alpha=alpha,
            methods=methods,
            progress=progress,
        )
    report = FitReport(
        design=name,
        design_fingerprint=model.design_fingerprint,  # computed once, by _fitted_model
        threshold=float(model.threshold),
        threshold_learnt=learnt,
        true_failure_clearance=None if spec is None else spec.failure_clearance,
        train_units=sorted(train["unit_id"].unique().tolist()),
        test_units=sorted(test["unit_id"].unique().tolist()),
        histories=histories,
        predictions=predictions,
        summary=summary,
    )
    return model, report


def _methods(model: RULModel) -> tuple[str, ...]:
    """The methods a fitted model can score: the physics one where it was fitted."""
    return ("degradation", "similarity") + (("physics",) if model.ageing_ is not None else ())


def _life_spec(dataset):
    """The fleet's ``[life]`` (:class:`~prsm_health.physics.life_spec.LifeSpec`); None for a
    dataset of no known design or without one (no physics method then)."""
    life = dataset.manifest.get("recipe", {}).get("life")
    if not life or dataset.design is None:
        return None
    from prsm_health.physics.life_spec import LifeSpec

    return LifeSpec.from_dict(life)


def _fitted_model(
    train, failure, *, design, name, spec, threshold, method, n_samples, random_state
) -> RULModel:
    """A :class:`RULModel` fitted on the training units' histories (the threshold learnt from
    them when None; the physics method where the fleet's ``spec`` is known)."""
    limit = None if spec is None else spec.failure_clearance
    if threshold is None:
        threshold = diagnosed_threshold(train, failure_clearance=limit)
    model = RULModel(
        method=method,
        threshold=threshold,
        design=name,
        design_fingerprint=None if design is None else design_fingerprint(design),
        n_samples=n_samples,
        random_state=random_state,
    )
    physics = None
    if spec is not None:
        from .ageing_model import rate_tables  # progpy: imported only where the physics is

        seed = 0 if random_state is None else random_state
        physics = PhysicsRUL(rate_tables(design, spec), spec, seed=seed)
    # fit validates each unit's history against the model: histories of another design fail
    model.fit(train, {u: failure[u] for u in train["unit_id"].unique()}, physics=physics)
    return model


def cross_validate_units(
    fleet,
    histories: pd.DataFrame,
    *,
    folds: int = 4,
    seed: int = 0,
    methods=None,
    method: str = "degradation",
    n_samples: int = 4000,
    random_state: int | None = 0,
    alpha: float = ALPHA,
    progress: bool = False,
) -> tuple[pd.DataFrame, dict]:
    """Every unit of a fleet scored by a model that never saw it: the units split at random
    (``seed``) into ``folds`` groups, each group predicted (every history prefix) by a model
    fitted as :func:`fit_prognostics_model` fits one on all the other units — a score on
    every unit instead of the held-out few (the held-out split alone scores 6 units of the
    shipped fleet, whose α–λ accuracy moves by ±0.2 with the split).

    ``methods``: those to score (default every one the fleet allows: degradation, similarity
    and, with the fleet's ``[life]``, physics). Returns the predictions
    (:func:`~prsm_health.prognostics.metrics.evaluate_units`' columns and ``fold``) and per method the pooled scores
    (:func:`~prsm_health.prognostics.metrics.pooled_scores`) with the per-unit ones
    (prognostic horizons, CRA, monotonicity) averaged over all units.
    """
    from prsm_health.datasets import Dataset

    dataset = fleet if isinstance(fleet, Dataset) else Dataset(fleet)
    design = dataset.design
    name = design.name if design is not None else str(dataset.runs["design"].iloc[0])
    spec = _life_spec(dataset)
    failure = histories.groupby("unit_id")["failure_age_hours"].first().to_dict()
    units = np.random.default_rng(seed).permutation(sorted(failure))
    require(
        isinstance(folds, int)
        and 2 <= folds <= len(units)
        and len(units) - math.ceil(len(units) / folds) >= 3,
        "folds",
        folds,
        f"must be an integer in [2, {len(units)}] leaving ≥ 3 training units in each fold",
    )
    frames, per_unit = [], {}
    for fold in range(folds):
        held = set(units[fold::folds].tolist())
        inside = histories["unit_id"].isin(held)
        model = _fitted_model(
            histories[~inside],
            failure,
            design=design,
            name=name,
            spec=spec,
            threshold=None,
            method=method,
            n_samples=n_samples,
            random_state=random_state,
        )
        predictions, summary = evaluate_units(
            histories[inside],
            {u: failure[u] for u in held},
            model,
            alpha=alpha,
            methods=_methods(model) if methods is None else tuple(methods),
            progress=progress,
        )
        frames.append(predictions.assign(fold=fold))
        for m, entry in summary.items():
            per_unit.setdefault(m, []).append(entry)
    predictions = pd.concat(frames, ignore_index=True)
    summary = {}
    for m, entries in per_unit.items():
        weights = np.array([e["n_units"] for e in entries], dtype=float)
        summary[m] = pooled_scores(predictions[predictions["method"] == m], 0.5, alpha)
        for key in ("prognostic_horizon", "prognostic_horizon_first", "cra", "monotonicity"):
            values = np.array([e[key] for e in entries], dtype=float)
            ok = np.isfinite(values) & (weights > 0)
            summary[m][key] = (
                float(np.average(values[ok], weights=weights[ok])) if ok.any() else np.nan
            )
    return predictions, summary


def _differs(a, b) -> bool:
    """Two designs known and not the same mechanism."""
    return a is not None and b is not None and not same_design(a, b)
