"""Offline metrics of prognostic performance, and the evaluation of a model on a fleet.

After Saxena et al. [1]_: the RMSE of RUL, the alpha-lambda accuracy, the prognostic horizon,
the coverage of the prediction intervals and the cumulative relative accuracy, plus the
monotonicity of the predictions [2]_; :func:`evaluate_units` predicts every history prefix of
a set of units run to failure and summarizes each method.

The two accuracy criteria differ, as in [1]_:

- alpha-lambda accuracy uses a **cone** shrinking with the true RUL ``r*``: a prediction
  ``r`` is accurate when ``(1 - alpha) r* <= r <= (1 + alpha) r*`` ([1]_ section 6.2;
  here evaluated at every prediction instant and reported as the fraction accurate);
- the prognostic horizon uses **constant** bounds ``r* +- alpha * EoL`` around the true RUL
  line, ``EoL`` the failure age ([1]_ section 6.1, with the beta criterion of a point
  prediction being "inside").

What goes through NASA's progpy (imported lazily, inside the functions: its import costs
about 2 s):

- :func:`cumulative_relative_accuracy` (each RA by ``UncertainData.relative_accuracy``) and
  :func:`monotonicity` (``progpy.metrics.monotonicity``): progpy has them, the project had not;
- :func:`prognostic_horizon_first`: ``progpy.metrics.prognostic_horizon``, the horizon
  from the first prediction inside the bounds, beside :func:`prognostic_horizon`, which asks
  the later ones to stay inside (its docstring says why both);
- ``progpy.metrics.alpha_lambda`` tests the same cone as :func:`alpha_lambda_accuracy` at one
  instant and answers a bool (its docstring); tests/prognostics/test_metrics_progpy.py
  cross-checks the two on the same inputs.

:func:`rmse` and :func:`interval_coverage` have no progpy counterpart and stay hand-written.

Summary keys of :func:`evaluate_units` per method: ``rmse``, ``coverage``, ``rmse_after``,
``alpha_lambda``, ``coverage_after``, ``prognostic_horizon`` (mean over units [h]),
``n_predictions``, ``n_units``, and from progpy:

- ``prognostic_horizon_first``: :func:`prognostic_horizon_first`, mean over units [h];
- ``cra``: cumulative relative accuracy of each unit's predictions (those with true RUL > 0),
  averaged over units [-], at most 1, negative when errors exceed the true RUL;
- ``monotonicity``: monotonicity of each unit's predicted RUL, averaged over the units with
  >= 2 predictions [-], in [0, 1] (1: the predicted RUL moves one way only).

References
----------
.. [1] A. Saxena, J. Celaya, B. Saha, S. Saha, K. Goebel, "Metrics for offline evaluation of
   prognostic performance", International Journal of Prognostics and Health Management 1
   (2010) 4-23.
.. [2] J. Coble, J. W. Hines, "Identifying optimal prognostic parameters from data: a genetic
   algorithms approach", Annual Conference of the PHM Society (2009); the monotonicity of
   ``progpy.metrics.monotonicity``.
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
    "cumulative_relative_accuracy",
    "evaluate_units",
    "interval_coverage",
    "monotonicity",
    "prognostic_horizon",
    "prognostic_horizon_first",
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

#: The one event of the profiles handed to progpy: the end of life.
_EVENT = "EOL"

#: Grid [h] (2^-20 h, about 3.4 ms) of the ages and RULs handed to progpy. progpy stores a
#: time of event ``t + r`` and subtracts ``t`` again; on a dyadic grid that round trip is
#: exact (below 2^33 h), so two equal RULs (e.g. capped at the model's horizon) stay equal
#: instead of differing by an ulp, which would flip the monotonicity's signs.
#: (The ages move by <= 2^-21 h, so does the PH of :func:`prognostic_horizon_first`.)
_GRID_H = 2.0**-20


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


def _check_increasing(ages: np.ndarray) -> None:
    """ParameterError naming the first age that does not increase."""
    steps = np.flatnonzero(np.diff(ages) <= 0)
    if steps.size:
        raise ParameterError(f"ages[{steps[0] + 1}]", float(ages[steps[0] + 1]), "must increase")


def _check_failure_age(failure_age) -> None:
    require(
        isinstance(failure_age, (int, float, np.number))
        and math.isfinite(failure_age)
        and failure_age > 0,
        "failure_age",
        failure_age,
        "must be a finite age > 0 [h]",
    )


def _rul_predictions(pred, n: int) -> np.ndarray:
    """RUL predictions [h]: ``(n,)`` point predictions or ``(n, S)`` samples, finite."""
    a = np.asarray(pred, dtype=np.float64)
    require(
        a.ndim in (1, 2) and a.shape[0] == n and a.size > 0,
        "pred",
        f"shape {a.shape}",
        f"must be ({n},) point predictions or ({n}, S) samples",
    )
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        where = ", ".join(str(int(i)) for i in bad[0])
        raise ParameterError(f"pred[{where}]", float(a[tuple(bad[0])]), "must be finite")
    return a


def _snap(values: np.ndarray) -> np.ndarray:
    return np.round(values / _GRID_H) * _GRID_H


def _uncertain(values):
    """progpy UncertainData of the event: ScalarData of a point, UnweightedSamples of samples."""
    from progpy.uncertain_data import ScalarData, UnweightedSamples

    if np.ndim(values) == 0:
        return ScalarData({_EVENT: float(values)})
    return UnweightedSamples([{_EVENT: float(v)} for v in values])


def _toe_profile(ages: np.ndarray, pred: np.ndarray):
    """progpy ToEPredictionProfile: prediction age [h] -> time of event ``age + RUL`` [h].

    Ages and RULs are snapped to :data:`_GRID_H` first (see there); ages closer than that
    would merge, and are refused.
    """
    from progpy.predictors import ToEPredictionProfile

    ages, pred = _snap(ages), _snap(pred)
    steps = np.flatnonzero(np.diff(ages) <= 0)
    if steps.size:
        raise ParameterError(
            f"ages[{steps[0] + 1}]", float(ages[steps[0] + 1]), f"must be >= {_GRID_H:g} h apart"
        )
    profile = ToEPredictionProfile()
    for t, rul in zip(ages, pred):
        profile.add_prediction(float(t), _uncertain(rul + t))
    return profile


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

    Notes
    -----
    Hand-written: progpy has no RMSE over predictions (``progpy.metrics.calc_metrics`` scores
    the samples of one distribution against one ground truth).

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

    Notes
    -----
    Kept instead of ``progpy.metrics.alpha_lambda``: progpy tests the same cone, but only at
    the first prediction at or after one time lambda, answers a bool (share of the
    distribution strictly inside >= beta), and so counts neither a prediction on the bound nor
    an exact 0 at ``r* = 0``; tests/prognostics/test_metrics_progpy.py shows both on the same inputs.

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

    Notes
    -----
    Kept instead of ``progpy.metrics.prognostic_horizon``: progpy starts PH at the first
    prediction meeting the criterion ([1]_'s ``i = min{j ...}``) even if later predictions
    leave the bounds, while this one requires them to stay inside (a stricter variant);
    :func:`prognostic_horizon_first` exposes progpy's.

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 6.1 (prognostic horizon; point predictions:
       the beta criterion is "inside the bounds").
    """
    require_range("alpha", alpha, 0.0, 1.0, inclusive=False)
    _check_failure_age(failure_age)
    ages, true, pred = _vectors(ages=ages, true_rul=true_rul, pred=pred)
    _check_increasing(ages)
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

    Notes
    -----
    Hand-written: progpy has no coverage (``UncertainData.percentage_in_bounds`` is the share
    of one distribution inside given bounds, the converse question).

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 5 (precision-based metrics; here the
       empirical coverage of the intervals).
    """
    true, lower, upper = _vectors(true=true, lower=lower, upper=upper)
    return float(np.mean((lower <= true) & (true <= upper)))


def cumulative_relative_accuracy(true_rul, pred) -> float:
    """Cumulative relative accuracy (CRA) of RUL predictions [-], by progpy.

    ``CRA = mean_i RA_i`` with ``RA_i = 1 - |r*_i - r_i| / r*_i`` at each prediction instant
    (``r_i`` the point prediction, or the mean of its samples), uniform weights; each ``RA_i``
    by progpy's ``UncertainData.relative_accuracy``. Instants with ``r* = 0`` are skipped (RA
    is undefined there).

    Parameters
    ----------
    true_rul : array_like
        True RULs [h], >= 0, finite.
    pred : array_like
        Predicted RULs [h]: ``(N,)`` point predictions or ``(N, S)`` samples, finite.

    Returns
    -------
    float
        At most 1 (exact predictions), negative when an error exceeds the true RUL; NaN when
        every true RUL is 0.

    Notes
    -----
    ``progpy.metrics.cumulative_relative_accuracy`` itself is not used: on a time-of-event
    profile it divides every error by the true time of event, giving ``1 - mean|r - r*| /
    EoL``, not the RA of [1]_ relative to the true RUL at each instant.

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 6.3 (relative accuracy; CRA with uniform
       weights over the prediction instants).
    """
    (true,) = _vectors(true_rul=true_rul)
    negative = np.flatnonzero(true < 0)
    if negative.size:
        raise ParameterError(f"true_rul[{negative[0]}]", float(true[negative[0]]), "must be >= 0")
    pred = _rul_predictions(pred, true.size)
    ra = [
        _uncertain(r).relative_accuracy({_EVENT: float(t)})[_EVENT]
        for t, r in zip(true, pred)
        if t > 0
    ]
    return float(np.mean(ra)) if ra else math.nan


def monotonicity(ages, pred) -> float:
    """Monotonicity of a unit's RUL predictions [-], by ``progpy.metrics.monotonicity``.

    ``|sum_i sign(r_{i+1} - r_i)| / (N - 1)`` over the predictions in order of age (``r`` the
    point prediction, or the mean of its samples): 1 when the predicted RUL never rises (or
    never falls), near 0 when it zigzags; equal consecutive predictions count 0.

    Parameters
    ----------
    ages : array_like
        Ages of the predictions [h], strictly increasing, >= 2 of them.
    pred : array_like
        Predicted RULs [h]: ``(N,)`` point predictions or ``(N, S)`` samples, finite.

    Returns
    -------
    float
        In [0, 1].

    References
    ----------
    .. [1] Coble & Hines, PHM Society conference (2009), the monotonicity of a prognostic
       parameter, as implemented by ``progpy.metrics.monotonicity``; not one of Saxena et
       al. (2010)'s metrics.
    """
    from progpy.metrics import monotonicity as progpy_monotonicity

    (ages,) = _vectors(ages=ages)
    require(ages.size >= 2, "ages", f"{ages.size} value", "must hold >= 2 predictions")
    _check_increasing(ages)
    pred = _rul_predictions(pred, ages.size)
    return float(progpy_monotonicity(_toe_profile(ages, pred))[_EVENT])


def prognostic_horizon_first(
    ages, pred, failure_age: float, alpha: float = 0.2, beta: float = 0.5
) -> float:
    """Prognostic horizon [h] from the first prediction meeting the criterion, by progpy.

    ``PH = EoL - t_i`` with ``t_i`` the earliest prediction age whose RUL distribution has a
    share >= ``beta`` strictly inside ``r* +- alpha * EoL``, whatever the later predictions do
    (``progpy.metrics.prognostic_horizon``); 0 when no prediction before EoL meets it. Never
    shorter than :func:`prognostic_horizon`, which requires the later predictions to stay
    inside: the gap shows predictions that enter the bounds and leave them again.

    Parameters
    ----------
    ages : array_like
        Ages of the predictions [h], strictly increasing.
    pred : array_like
        Predicted RULs [h]: ``(N,)`` point predictions or ``(N, S)`` samples, finite.
    failure_age : float
        End of life ``EoL`` [h], > 0.
    alpha : float, default 0.2
        Half-width of the bounds as a fraction of ``EoL``, in (0, 1).
    beta : float, default 0.5
        Share of the distribution required inside, in (0, 1].

    Returns
    -------
    float
        PH [h], in [0, failure_age - ages[0]].

    References
    ----------
    .. [1] Saxena et al., IJPHM 1 (2010), section 6.1 (prognostic horizon,
       ``i = min{j | pi[r(j)] >= beta}``).
    """
    from progpy.metrics import prognostic_horizon as progpy_horizon

    require_range("alpha", alpha, 0.0, 1.0, inclusive=False)
    require(
        isinstance(beta, (int, float)) and 0.0 < beta <= 1.0, "beta", beta, "must lie in (0, 1]"
    )
    _check_failure_age(failure_age)
    (ages,) = _vectors(ages=ages)
    _check_increasing(ages)
    pred = _rul_predictions(pred, ages.size)
    half = alpha * float(failure_age)

    def inside(tte, truth):
        # tte: the predicted RUL (progpy's ToE - prediction time); truth: the true RUL
        r = truth[_EVENT]
        share = tte.percentage_in_bounds({_EVENT: [r - half, r + half]})[_EVENT]
        return {_EVENT: share >= beta}

    ph = progpy_horizon(_toe_profile(ages, pred), inside, {_EVENT: float(failure_age)})
    return 0.0 if ph[_EVENT] is None else float(ph[_EVENT])


def evaluate_units(
    histories: pd.DataFrame,
    failure_ages: Mapping,
    model: RULModel,
    after_fraction: float = 0.5,
    methods=("degradation", "similarity"),
    alpha: float = 0.2,
    progress: bool = False,
):
    """Predict every history prefix of units run to failure and score each method (a
    progress bar over units and methods on stderr with ``progress``).

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
        ``prognostic_horizon`` (mean over units [h]), ``n_predictions``, ``n_units``, and
        through progpy ``cra`` (:func:`cumulative_relative_accuracy` of each unit's
        predictions, mean over units) and ``monotonicity`` (:func:`monotonicity` of each
        unit's predicted RUL, mean over the units with >= 2 predictions); NaN when no unit
        has one.

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
    # per-unit scores, averaged over units in the summary
    horizons = {m: [] for m in methods}
    first_horizons = {m: [] for m in methods}
    cras = {m: [] for m in methods}
    monotonic = {m: [] for m in methods}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=histories["unit_id"].nunique() * len(methods), desc="predicting", unit="unit"
        )
    for uid, unit in histories.groupby("unit_id", sort=True):
        uid = uid.item() if isinstance(uid, np.generic) else uid
        require(uid in failure_ages, "failure_ages", uid, "has no failure age for this unit")
        life = float(failure_ages[uid])
        for method in methods:
            prognoses = model.predict_prefixes(unit, method=method)
            if bar is not None:
                bar.update(1)
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
                first_horizons[method].append(
                    prognostic_horizon_first(block[:, 0], block[:, 2], life, alpha, beta=1.0)
                )
                cras[method].append(cumulative_relative_accuracy(block[:, 1], block[:, 2]))
                if len(block) >= 2:
                    monotonic[method].append(monotonicity(block[:, 0], block[:, 2]))
            rows.extend(unit_rows)
    predictions = pd.DataFrame(rows, columns=list(PREDICTION_COLUMNS))
    summary = {}
    for method in methods:
        part = predictions[predictions["method"] == method]
        if part.empty:
            summary[method] = {"n_predictions": 0, "n_units": 0}
            continue
        summary[method] = {
            **pooled_scores(part, after_fraction, alpha),
            "prognostic_horizon": float(np.mean(horizons[method])),
            "prognostic_horizon_first": float(np.mean(first_horizons[method])),
            "cra": _mean_finite(cras[method]),
            "monotonicity": _mean_finite(monotonic[method]),
        }
    if bar is not None:
        bar.close()
    return predictions, summary


def pooled_scores(predictions: pd.DataFrame, after_fraction: float = 0.5, alpha: float = 0.2):
    """The scores over a pool of predictions (one method's, :data:`PREDICTION_COLUMNS`):
    ``rmse``, ``coverage`` and ``alpha_lambda_all`` over all, ``rmse_after``, ``alpha_lambda`` and
    ``coverage_after`` over those made at ages >= ``after_fraction`` × the unit's life (NaN
    when there is none), ``n_predictions``, ``n_units``."""
    life = predictions["age_hours"] + predictions["true_rul"]
    late = predictions[predictions["age_hours"] >= after_fraction * life]
    entry = {
        "rmse": rmse(predictions["true_rul"], predictions["estimate"]),
        "coverage": interval_coverage(
            predictions["true_rul"], predictions["lower"], predictions["upper"]
        ),
        "alpha_lambda_all": alpha_lambda_accuracy(
            predictions["true_rul"], predictions["estimate"], alpha
        ),
        "n_predictions": len(predictions),
        "n_units": int(predictions["unit_id"].nunique()),
        "rmse_after": math.nan,
        "alpha_lambda": math.nan,
        "coverage_after": math.nan,
    }
    if not late.empty:
        entry.update(
            rmse_after=rmse(late["true_rul"], late["estimate"]),
            alpha_lambda=alpha_lambda_accuracy(late["true_rul"], late["estimate"], alpha),
            coverage_after=interval_coverage(late["true_rul"], late["lower"], late["upper"]),
        )
    return entry


def _mean_finite(values) -> float:
    """Mean of the finite values; NaN when there is none (without numpy's warning)."""
    a = np.asarray(values, dtype=np.float64)
    a = a[np.isfinite(a)]
    return float(a.mean()) if a.size else math.nan
