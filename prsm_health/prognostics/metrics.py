"""Offline metrics of prognostic performance, and the evaluation of a model on a fleet.

After Saxena et al. [1]_: the RMSE of RUL, the alpha-lambda accuracy, the prognostic horizon
and the coverage of the prediction intervals; :func:`evaluate_units` predicts every history
prefix of a set of units run to failure and summarizes each method.

The two accuracy criteria differ, as in [1]_:

- alpha-lambda accuracy uses a **cone** shrinking with the true RUL ``r*``: a prediction
  ``r`` is accurate when ``(1 - alpha) r* <= r <= (1 + alpha) r*`` ([1]_ section 6.2;
  here evaluated at every prediction instant and reported as the fraction accurate);
- the prognostic horizon uses **constant** bounds ``r* +- alpha * EoL`` around the true RUL
  line, ``EoL`` the failure age ([1]_ section 6.1, with the beta criterion of a point
  prediction being "inside").

References
----------
.. [1] A. Saxena, J. Celaya, B. Saha, S. Saha, K. Goebel, "Metrics for offline evaluation of
   prognostic performance", International Journal of Prognostics and Health Management 1
   (2010) 4-23.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from prsm_health.core.errors import ParameterError, require, require_range

from .history import HISTORY_COLUMNS
from .rul import RULModel

__all__ = [
    "alpha_lambda_accuracy",
    "evaluate_units",
    "interval_coverage",
    "prognostic_horizon",
    "rmse",
]

#: Columns of the prediction table of :func:`evaluate_units`.
PREDICTION_COLUMNS = (
    "unit_id",
    "age_hours",
    "true_rul",
    "method",
    "model",
    "estimate",
    "lower",
    "upper",
)


def _vectors(**arrays) -> list[np.ndarray]:
    """Finite 1-D float arrays of one common, non-zero length (ParameterError otherwise)."""
    out = []
    length = None
    for name, values in arrays.items():
        a = np.asarray(values, dtype=np.float64).reshape(-1)
        require(a.size > 0, name, "[]", "must hold at least one value")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ParameterError(f"{name}[{bad[0]}]", float(a[bad[0]]), "must be finite")
        if length is not None and a.size != length:
            raise ParameterError(
                name, f"{a.size} values", f"must hold {length} values like the first"
            )
        length = a.size
        out.append(a)
    return out


def rmse(true, pred) -> float:
    """Root-mean-square error of RUL predictions [units of the input, e.g. h].

    Parameters
    ----------
    true, pred : array_like
        True and predicted RULs, same length, finite.

    Returns
    -------
    float
        ``sqrt(mean((pred - true)^2))``.

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 5 (accuracy-based metrics).
    """
    true, pred = _vectors(true=true, pred=pred)
    return float(np.sqrt(np.mean((pred - true) ** 2)))


def alpha_lambda_accuracy(true_rul, pred_rul, alpha: float = 0.2) -> float:
    """Fraction of predictions inside the alpha cone of the true RUL.

    A prediction ``r`` at an instant with true RUL ``r* >= 0`` is accurate when
    ``|r - r*| <= alpha r*`` (bounds ``(1 +- alpha) r*``, shrinking as the unit nears its end
    of life; a true RUL of 0 admits only an exact 0).

    Parameters
    ----------
    true_rul, pred_rul : array_like
        True (>= 0) and predicted RULs [h], same length, finite.
    alpha : float, default 0.2
        Half-width of the cone relative to the true RUL, in (0, 1).

    Returns
    -------
    float
        Accurate predictions / all predictions, in [0, 1].

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 6.2 (alpha-lambda accuracy, evaluated at
       every prediction instant instead of one lambda).
    """
    require_range("alpha", alpha, 0.0, 1.0, inclusive=False)
    true, pred = _vectors(true_rul=true_rul, pred_rul=pred_rul)
    negative = np.flatnonzero(true < 0)
    if negative.size:
        raise ParameterError(f"true_rul[{negative[0]}]", float(true[negative[0]]), "must be >= 0")
    return float(np.mean(np.abs(pred - true) <= alpha * true))


def prognostic_horizon(ages, true_rul, pred, failure_age: float, alpha: float = 0.2) -> float:
    """Prognostic horizon [h]: how long before failure the predictions become and stay accurate.

    ``PH = EoL - t_i`` with ``EoL = failure_age`` and ``t_i`` the earliest prediction age from
    which every later prediction lies within ``r* +- alpha * EoL``. When the last prediction
    is outside, the predictions never settle and PH is 0.

    Parameters
    ----------
    ages : array_like
        Ages of the predictions [h], strictly increasing.
    true_rul, pred : array_like
        True and predicted RUL at those ages [h], finite.
    failure_age : float
        End of life ``EoL`` [h], > 0.
    alpha : float, default 0.2
        Half-width of the bounds as a fraction of ``EoL``, in (0, 1).

    Returns
    -------
    float
        PH [h], in [0, failure_age - ages[0]].

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 6.1 (prognostic horizon; point predictions:
       the beta criterion is "inside the bounds").
    """
    require_range("alpha", alpha, 0.0, 1.0, inclusive=False)
    require(
        isinstance(failure_age, (int, float, np.number))
        and math.isfinite(failure_age)
        and failure_age > 0,
        "failure_age",
        failure_age,
        "must be a finite age > 0 [h]",
    )
    ages, true, pred = _vectors(ages=ages, true_rul=true_rul, pred=pred)
    steps = np.flatnonzero(np.diff(ages) <= 0)
    if steps.size:
        raise ParameterError(f"ages[{steps[0] + 1}]", float(ages[steps[0] + 1]), "must increase")
    inside = np.abs(pred - true) <= alpha * float(failure_age)
    if not inside[-1]:
        return 0.0
    outside = np.flatnonzero(~inside)
    first = 0 if outside.size == 0 else int(outside[-1]) + 1
    return float(failure_age - ages[first])


def interval_coverage(true, lower, upper) -> float:
    """Fraction of true values inside their prediction interval ``[lower, upper]``.

    Parameters
    ----------
    true, lower, upper : array_like
        True RULs and interval bounds [h], same length, finite.

    Returns
    -------
    float
        In [0, 1]; a 90 % interval should give about 0.9.

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 5 (precision-based metrics; here the
       empirical coverage of the intervals).
    """
    true, lower, upper = _vectors(true=true, lower=lower, upper=upper)
    return float(np.mean((lower <= true) & (true <= upper)))


def evaluate_units(
    histories: pd.DataFrame,
    failure_ages: Mapping,
    model: RULModel,
    after_fraction: float = 0.5,
    methods=("degradation", "similarity"),
    alpha: float = 0.2,
):
    """Predict every history prefix of units run to failure and score each method.

    Each unit's history is validated once; a prediction at age ``a`` uses only the rows with
    age <= ``a`` (prefixes of >= 2 diagnoses), and only prefixes ending at or before the
    unit's failure age are scored. Units should not be the model's training units (that
    would be an in-sample score).

    Parameters
    ----------
    histories : pandas.DataFrame
        Column ``unit_id`` plus the history columns
        (:data:`prsm_health.prognostics.HISTORY_COLUMNS`).
    failure_ages : Mapping
        Unit id -> true failure age [h].
    model : RULModel
        A fitted model.
    after_fraction : float, default 0.5
        The alpha-lambda accuracy and the ``*_after`` entries use the predictions made at
        ages >= ``after_fraction`` x the unit's failure age, in [0, 1).
    methods : sequence of str, default ("degradation", "similarity")
        Methods to evaluate (:data:`prsm_health.prognostics.METHODS`).
    alpha : float, default 0.2
        Accuracy bound of the alpha-lambda accuracy and of the prognostic horizon.

    Returns
    -------
    predictions : pandas.DataFrame
        One row per prediction: :data:`PREDICTION_COLUMNS` (``model`` is the prognosis'
        model name, e.g. ``degradation-exponential``; RULs in h).
    summary : dict
        Per method: ``rmse`` and ``coverage`` over all predictions, ``rmse_after``,
        ``alpha_lambda`` and ``coverage_after`` over those after ``after_fraction`` of life,
        ``prognostic_horizon`` (mean over units [h]), ``n_predictions``, ``n_units``.

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010).
    """
    require(
        isinstance(histories, pd.DataFrame) and "unit_id" in histories.columns,
        "histories",
        type(histories).__name__,
        "must be a pandas DataFrame with a unit_id column",
    )
    missing = [c for c in HISTORY_COLUMNS if c not in histories.columns]
    require(not missing, "histories", missing, "lacks these history columns")
    require(
        isinstance(model, RULModel),
        "model",
        type(model).__name__,
        "must be a RULModel",
    )
    require_range("after_fraction", after_fraction, 0.0, 1.0)
    require(after_fraction < 1.0, "after_fraction", after_fraction, "must be < 1")
    methods = tuple(methods)
    require(len(methods) > 0, "methods", methods, "must name at least one method")
    if isinstance(failure_ages, pd.Series):
        failure_ages = failure_ages.to_dict()
    rows = []
    horizons = {m: [] for m in methods}
    for uid, unit in histories.groupby("unit_id", sort=True):
        uid = uid.item() if isinstance(uid, np.generic) else uid
        require(uid in failure_ages, "failure_ages", uid, "has no failure age for this unit")
        life = float(failure_ages[uid])
        for method in methods:
            prognoses = model.predict_prefixes(unit, method=method)
            unit_rows = []
            for p in prognoses:
                age = float(p.health_indicator["ages_hours"][-1])
                if age > life:
                    continue
                rul = p.rul_hours
                unit_rows.append(
                    (
                        uid,
                        age,
                        life - age,
                        method,
                        p.model["name"],
                        rul["estimate"],
                        rul["lower"],
                        rul["upper"],
                    )
                )
            if unit_rows:
                block = np.array([r[1:3] + r[5:6] for r in unit_rows], dtype=np.float64)
                horizons[method].append(
                    prognostic_horizon(block[:, 0], block[:, 1], block[:, 2], life, alpha)
                )
            rows.extend(unit_rows)
    predictions = pd.DataFrame(rows, columns=list(PREDICTION_COLUMNS))
    summary = {}
    for method in methods:
        part = predictions[predictions["method"] == method]
        if part.empty:
            summary[method] = {"n_predictions": 0, "n_units": 0}
            continue
        life = part["age_hours"] + part["true_rul"]
        late = part[part["age_hours"] >= after_fraction * life]
        entry = {
            "rmse": rmse(part["true_rul"], part["estimate"]),
            "coverage": interval_coverage(part["true_rul"], part["lower"], part["upper"]),
            "n_predictions": len(part),
            "n_units": int(part["unit_id"].nunique()),
            "prognostic_horizon": float(np.mean(horizons[method])),
        }
        if late.empty:
            entry.update(
                {"rmse_after": math.nan, "alpha_lambda": math.nan, "coverage_after": math.nan}
            )
        else:
            entry.update(
                {
                    "rmse_after": rmse(late["true_rul"], late["estimate"]),
                    "alpha_lambda": alpha_lambda_accuracy(
                        late["true_rul"], late["estimate"], alpha
                    ),
                    "coverage_after": interval_coverage(
                        late["true_rul"], late["lower"], late["upper"]
                    ),
                }
            )
        summary[method] = entry
    return predictions, summary
