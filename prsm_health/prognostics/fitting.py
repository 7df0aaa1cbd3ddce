"""Fitting a prognostics model for a fleet of any design: the fleet's snapshots diagnosed into
histories, the model fitted on the training units, scored on the held-out ones.

A fleet is a dataset generated from a life recipe (``[life]``, docs/prognostics.md) of the
design the model is for — a preset or one's own design file. The model carries that design
(its name and fingerprint), so it refuses the histories of another design.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from prsm_health.actuator.design_files import design_fingerprint, same_design
from prsm_health.core.errors import PRSMHealthError, require

from .fleet import fleet_histories
from .metrics import evaluate_units
from .rul import RULModel

#: Diagnoses of a unit's last share of life used to read the indicator at failure.
LAST_SHARE = 0.25
#: Accuracy bound of the held-out score's α–λ accuracy and prognostic horizon.
ALPHA = 0.2


def diagnosed_threshold(train: pd.DataFrame, last_share: float = LAST_SHARE) -> float:
    """The diagnosed clearance at failure [m], learnt from the training units.

    A unit fails when its *true* clearance reaches the recipe's limit; the diagnosis reads
    the clearance with its own bias, so the model's threshold is on the diagnosed clearance:
    the median over the training units of a straight line through each unit's diagnoses in
    its last ``last_share`` of life (at least its last two), evaluated at its failure age.

    Parameters
    ----------
    train : pandas.DataFrame
        ``unit_id``, ``age_hours`` [h], ``clearance`` [m], ``failure_age_hours`` [h].
    last_share : float
        Share of a unit's life, at its end, whose diagnoses are used, in (0, 1].
    """
    values = []
    for _, unit in train.groupby("unit_id"):
        unit = unit.sort_values("age_hours")
        failure = float(unit["failure_age_hours"].iloc[0])
        late = unit["age_hours"] >= (1 - last_share) * failure
        late.iloc[-2:] = True  # a coarse history has few diagnoses in its last share
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
    fingerprint = None if design is None else design_fingerprint(design)
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
    learnt = threshold is None
    if learnt:
        threshold = diagnosed_threshold(train)
    model = RULModel(
        method=method,
        threshold=threshold,
        design=name,
        design_fingerprint=fingerprint,
        n_samples=n_samples,
        random_state=random_state,
    )
    # fit validates each unit's history against the model: histories of another design fail
    model.fit(train, {u: failure[u] for u in train["unit_id"].unique()})
    life = dataset.manifest.get("recipe", {}).get("life")
    limit = None
    methods = ("degradation", "similarity")
    if life and design is not None:
        from prsm_health.physics.life import LifeSpec

        from .ageing_model import rate_tables
        from .ageing_rul import AgeingRUL

        spec = LifeSpec.from_dict(life)
        limit = spec.failure_clearance
        model.ageing_ = AgeingRUL.fit(
            rate_tables(design, spec),
            spec,
            train,
            seed=0 if random_state is None else random_state,
            horizon=model.horizon_,
        )
        methods += ("physics",)
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
        design_fingerprint=fingerprint,
        threshold=float(threshold),
        threshold_learnt=learnt,
        true_failure_clearance=limit,
        train_units=sorted(train["unit_id"].unique().tolist()),
        test_units=sorted(test["unit_id"].unique().tolist()),
        histories=histories,
        predictions=predictions,
        summary=summary,
    )
    return model, report


def _differs(a, b) -> bool:
    """Two designs known and not the same mechanism."""
    return a is not None and b is not None and not same_design(a, b)
