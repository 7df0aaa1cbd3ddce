"""Health estimators: clearance regression with a prediction interval, fault classification.

Both estimators are scikit-learn compatible (``__init__`` stores its arguments, learned
attributes end in ``_``, ``fit`` returns ``self``; they pass
:func:`sklearn.utils.estimator_checks.parametrize_with_checks`) and accept feature tables with
missing values (NaN: a feature not computable for a window, e.g. lost motion without a
reversal), because gradient-boosted histogram trees route NaN to a learned side of each split.

- :class:`ClearanceEstimator`: conformalized quantile regression (CQR) of a clearance [m];
  the interval is wide where the operating regime hides the clearance and narrow where it
  reveals it.
- :class:`FaultClassifier`: gradient boosting with Platt-calibrated class probabilities and a
  conformal class set (every class the evidence cannot rule out at a set coverage).

Evaluation (permutation importance, cross-validated metrics) lives in
:mod:`prsm_health.training.evaluation`; saving and loading in :mod:`prsm_health.diagnostics.model_files`.

References
----------
.. [1] Y. Romano, E. Patterson, E. Candès, "Conformalized quantile regression", NeurIPS 2019
   (the CQR algorithm, conformity score eq. 6 and correction eq. 7 of the paper).
.. [2] A. Niculescu-Mizil, R. Caruana, "Predicting good probabilities with supervised
   learning", ICML 2005 (boosted trees need calibration; Platt scaling beats isotonic
   regression when the calibration set is small).
.. [4] M. Sadinle, J. Lei, L. Wasserman, "Least ambiguous set-valued classifiers with bounded
   error levels", JASA 114 (2019) 223-234 (the class set {y : p_y >= t_y}, t_y from the
   held-out probabilities of class y's own samples: class-specific coverage, sections 2 and
   4.1).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, RegressorMixin
from sklearn.calibration import CalibratedClassifierCV
from sklearn.ensemble import (
    HistGradientBoostingClassifier,
    HistGradientBoostingRegressor,
    RandomForestClassifier,
)
from sklearn.model_selection import (
    GroupKFold,
    KFold,
    StratifiedGroupKFold,
    StratifiedKFold,
    cross_val_predict,
)
from sklearn.utils import check_random_state
from sklearn.utils.class_weight import compute_sample_weight
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from prsm_health.core.errors import ParameterError, require, require_range

from .trees import calibrated_proba, regressor_predict

__all__ = ["ClearanceEstimator", "DistributionGuard", "FaultClassifier"]

_SEED_MAX = np.iinfo(np.int32).max
#: What :class:`FaultClassifier` can learn with.
LEARNERS = ("boosting", "forest")
#: Trees of the forest learner (scikit-learn's default count).
FOREST_TREES = 100


def _check_hgb_params(est) -> None:
    """Validate the gradient-boosting parameters shared by both estimators."""
    require(
        isinstance(est.max_iter, (int, np.integer)) and est.max_iter >= 1,
        "max_iter",
        est.max_iter,
        "must be an integer >= 1",
    )
    require_range("learning_rate", est.learning_rate, 0.0, math.inf, inclusive=False)
    require(
        est.max_leaf_nodes is None
        or (isinstance(est.max_leaf_nodes, (int, np.integer)) and est.max_leaf_nodes >= 2),
        "max_leaf_nodes",
        est.max_leaf_nodes,
        "must be None or an integer >= 2",
    )
    require(
        isinstance(est.min_samples_leaf, (int, np.integer)) and est.min_samples_leaf >= 1,
        "min_samples_leaf",
        est.min_samples_leaf,
        "must be an integer >= 1",
    )
    require_range("l2_regularization", est.l2_regularization, 0.0, math.inf)


def _predict_input(est, X) -> np.ndarray:
    """``validate_data(est, X, reset=False)`` for prediction (float64, NaN allowed, inf not),
    with a shortcut for the common case — a DataFrame whose columns are the fitted feature
    names — where scikit-learn's per-column dtype checks cost milliseconds per call."""
    names = getattr(est, "feature_names_in_", None)
    columns = getattr(X, "columns", None)
    if names is not None and columns is not None and list(columns) == list(names):
        try:
            matrix = X.to_numpy(dtype=np.float64)
        except (TypeError, ValueError):
            matrix = None  # a column that is not numeric: scikit-learn's check says which
        if matrix is not None and not np.isinf(matrix).any():
            return matrix
    return validate_data(est, X, reset=False, ensure_all_finite="allow-nan", dtype=np.float64)


def _hgb_params(est) -> dict:
    return {
        "max_iter": est.max_iter,
        "learning_rate": est.learning_rate,
        "max_leaf_nodes": est.max_leaf_nodes,
        "min_samples_leaf": est.min_samples_leaf,
        "l2_regularization": est.l2_regularization,
    }


# --------------------------------------------------------------------------------------------
# Clearance regression with a conformal prediction interval
# --------------------------------------------------------------------------------------------


def conformal_quantile(scores, alpha: float) -> tuple[float, bool]:
    """(the split-conformal quantile of ``scores``, whether it exists): the
    ⌈(n+1)(1−alpha)⌉-th smallest score (Romano et al. 2019, eq. 7); when n is too small for
    ``alpha`` the largest score, without a coverage guarantee (False). The tolerance keeps
    (n+1)(1−alpha) = 90.000…1 from rounding up to the next order statistic."""
    scores = np.sort(np.asarray(scores, dtype=float))
    n = len(scores)
    k = math.ceil((n + 1) * (1 - alpha) - 1e-9)
    return float(scores[min(k, n) - 1]), k <= n


def _calibration_units(groups: np.ndarray, n_cal: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """(calibration, training) sample indices: whole groups, drawn in random order until the
    calibration part holds about ``n_cal`` samples (at least one group on each side)."""
    units, sizes = np.unique(groups, return_counts=True)
    require(
        len(units) >= 2, "groups", len(units), "at least 2 units (one to fit, one to calibrate)"
    )
    order = rng.permutation(len(units))
    units, sizes = units[order], sizes[order]
    # the first k units whose samples come nearest to n_cal, 1 ≤ k ≤ len(units) − 1
    k = int(np.clip(np.argmin(np.abs(np.cumsum(sizes) - n_cal)) + 1, 1, len(units) - 1))
    held = np.isin(groups, units[:k])
    return np.flatnonzero(held), np.flatnonzero(~held)


class ClearanceEstimator(RegressorMixin, BaseEstimator):
    """Clearance regression with a conformalized quantile-regression interval.

    Three histogram gradient-boosting models are fitted: quantile models for the ``alpha/2``
    and ``1 - alpha/2`` conditional quantiles and a point model. A held-out calibration
    fraction of the training data (chosen at random, deterministic given ``random_state``)
    gives the conformity scores ``E_i = max(lo(x_i) - y_i, y_i - hi(x_i))`` [1]_ (eq. 6); the
    ``ceil((n_cal + 1)(1 - alpha))``-th smallest score is the correction ``Q`` (eq. 7) and
    the interval is ``[lo(x) - Q, hi(x) + Q]``. For exchangeable data its coverage is at
    least ``1 - alpha`` whatever the quantile models' quality; the quantile models make the
    width follow the operating regime (wide where the features do not reveal the clearance).

    Which models see which data: the quantile models are fitted on the proper training part
    only and are *not* refitted on all data, because the coverage guarantee needs the
    calibration scores to be exchangeable with the test scores of the very models used for
    prediction. The point model does not enter the conformity score, so it is fitted on all
    data (better point accuracy at no cost to the guarantee). The returned interval is
    widened, if needed, to contain the point estimate, which can only raise coverage.

    The target is multiplied by ``scale`` before fitting (clearances ~1e-6…4e-5 m become
    1…40 µm) so the boosting tolerances and leaf regularization act on numbers of order one;
    predictions are returned in the units of ``y``.

    Parameters
    ----------
    alpha : float, default 0.1
        Miscoverage rate: intervals aim at ``1 - alpha`` coverage, in (0, 1).
    calibration_fraction : float, default 0.25
        Fraction of the training samples held out for conformal calibration, in (0, 1).
        At least one sample goes to each part.
    max_iter : int, default 100
        Boosting iterations of each model.
    learning_rate : float, default 0.1
        Shrinkage of each tree, > 0.
    max_leaf_nodes : int or None, default 31
        Leaves per tree.
    min_samples_leaf : int, default 20
        Minimum samples per leaf.
    l2_regularization : float, default 0.0
        L2 penalty on leaf values [ (units of y · scale)^-2 ], >= 0.
    random_state : int, RandomState or None, default 0
        Seeds the calibration split and the boosting models.
    scale : float, default 1e6
        Factor applied to ``y`` before fitting [model units / units of y]; 1e6 fits
        clearances in µm.
    point_loss : {"squared_error", "absolute_error"}, default "squared_error"
        Loss of the point model: conditional mean or median.
    conformity : {"additive", "scaled"}, default "additive"
        Conformity score. ``"additive"``: ``E = max(lo - y, y - hi)`` and the same margin
        ``Q`` is added to every interval (CQR, [1]_). ``"scaled"``: ``E`` divided by the raw
        width ``hi - lo``, so the margin ``Q (hi - lo)`` is proportional to the raw
        interval (CQR-r, [2]_): the same marginal guarantee, and coverage more even across
        regimes when the quantile models are over- or under-confident by a similar factor
        everywhere (e.g. boosted quantile models fitted on a few thousand samples).
    lower_limit : float or None, default None
        Physical lower limit of the target [units of y] (``0.0`` for a clearance):
        predictions and interval bounds are clipped to it. None: no limit.
    quantiles_of : {"target", "residual"}, default "target"
        What the quantile models learn. ``"target"``: the conditional quantiles of y (CQR as
        in [1]_). ``"residual"``: the conditional quantiles of the out-of-fold residual of a
        point model fitted on the proper training part, so the raw interval is
        ``p(x) + [q_lo(x), q_hi(x)]``; the same conformal calibration follows. When the
        target is nearly a deterministic function of a few features (clearance from lost
        motion), boosted quantile models of y jump between neighbouring target values and
        give erratic widths, while the residual quantiles stay small and still widen where
        the features explain less.

    Attributes
    ----------
    n_features_in_ : int
        Number of features seen in ``fit``.
    feature_names_in_ : ndarray of str
        Feature names, when ``X`` had string column names.
    lower_model_, upper_model_ : HistGradientBoostingRegressor
        Quantile models (scaled target), fitted on the proper training part.
    point_model_ : HistGradientBoostingRegressor
        Point model (scaled target), fitted on all samples.
    conformal_correction_ : float
        Correction ``Q``: with ``conformity="additive"`` the margin added to both bounds
        [units of y], with ``"scaled"`` the margin as a fraction of the raw width [-];
        negative when the quantile models' raw intervals over-cover.
    width_floor_ : float
        Smallest raw width used by ``conformity="scaled"`` [units of y · scale].
    n_calibration_ : int
        Number of calibration samples.
    n_iter_ : int
        Largest number of boosting iterations run by the three models (below ``max_iter``
        only if early stopping, automatic above 10 000 samples, triggered).
    coverage_guaranteed_ : bool
        False when the calibration set is smaller than ``1/alpha - 1`` samples: the
        finite-sample quantile is then undefined and the largest score is used instead.

    References
    ----------
    .. [1] Y. Romano, E. Patterson, E. Candès, "Conformalized quantile regression",
       NeurIPS 2019, Algorithm 1, eqs. 6-7.
    .. [2] M. Sesia, E. Candès, "A comparison of some conformal quantile regression
       methods", Stat 9(1) e261, 2020 (CQR-r, the width-scaled score).
    """

    def __init__(
        self,
        alpha=0.1,
        calibration_fraction=0.25,
        max_iter=100,
        learning_rate=0.1,
        max_leaf_nodes=31,
        min_samples_leaf=20,
        l2_regularization=0.0,
        random_state=0,
        scale=1e6,
        point_loss="squared_error",
        conformity="additive",
        lower_limit=None,
        quantiles_of="target",
    ):
        self.quantiles_of = quantiles_of
        self.alpha = alpha
        self.calibration_fraction = calibration_fraction
        self.max_iter = max_iter
        self.learning_rate = learning_rate
        self.max_leaf_nodes = max_leaf_nodes
        self.min_samples_leaf = min_samples_leaf
        self.l2_regularization = l2_regularization
        self.random_state = random_state
        self.scale = scale
        self.point_loss = point_loss
        self.conformity = conformity
        self.lower_limit = lower_limit

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        return tags

    def _check_params(self) -> None:
        require_range("alpha", self.alpha, 0.0, 1.0, inclusive=False)
        require_range("calibration_fraction", self.calibration_fraction, 0.0, 1.0, inclusive=False)
        require_range("scale", self.scale, 0.0, math.inf, inclusive=False)
        require(
            self.point_loss in ("squared_error", "absolute_error"),
            "point_loss",
            self.point_loss,
            "must be 'squared_error' or 'absolute_error'",
        )
        require(
            self.conformity in ("additive", "scaled"),
            "conformity",
            self.conformity,
            "must be 'additive' or 'scaled'",
        )
        require(
            self.quantiles_of in ("target", "residual"),
            "quantiles_of",
            self.quantiles_of,
            "must be 'target' or 'residual'",
        )
        require(
            self.lower_limit is None
            or (isinstance(self.lower_limit, (int, float)) and math.isfinite(self.lower_limit)),
            "lower_limit",
            self.lower_limit,
            "must be None or a finite number [units of y]",
        )
        _check_hgb_params(self)

    def fit(self, X, y, groups=None):
        """Fit the quantile and point models and calibrate the interval.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed (missing feature), inf not.
        y : array-like of shape (n_samples,)
            Target, e.g. a clearance [m].
        groups : array-like of shape (n_samples,) or None
            The unit of each sample: the calibration part then holds whole units, and the
            out-of-fold residuals come from folds by unit. Recordings of one unit share its
            build and sensors, so their errors are alike: calibrated on units it was also
            fitted on, the interval is as narrow as for a unit it knows and too narrow for a
            new one (the conformal guarantee needs calibration samples exchangeable with the
            new unit's).

        Returns
        -------
        self : ClearanceEstimator
        """
        self._check_params()
        X, y = validate_data(
            self, X, y, ensure_all_finite="allow-nan", y_numeric=True, dtype=np.float64
        )
        n = X.shape[0]
        if n < 2:
            raise ParameterError(
                "n_samples",
                n,
                "ClearanceEstimator needs at least 2 samples (one to fit, one to calibrate)",
            )
        rng = check_random_state(self.random_state)
        n_cal = min(max(int(round(self.calibration_fraction * n)), 1), n - 1)
        if groups is None:
            order = rng.permutation(n)
            cal, train = order[:n_cal], order[n_cal:]
        else:
            groups = np.asarray(groups)
            require(len(groups) == n, "groups", len(groups), f"one per sample ({n})")
            cal, train = _calibration_units(groups, n_cal, rng)
            n_cal = len(cal)
        seed = int(rng.randint(_SEED_MAX))
        ys = np.asarray(y, dtype=np.float64) * self.scale

        common = dict(_hgb_params(self), random_state=seed)
        target = ys[train]
        self.residual_point_model_ = None
        if self.quantiles_of == "residual":
            # Out-of-fold residuals: in-sample boosting residuals would be optimistic.
            folds = min(5, len(train))
            if groups is not None:
                folds = min(folds, len(np.unique(groups[train])))
            if folds >= 2:
                oof = cross_val_predict(
                    HistGradientBoostingRegressor(loss=self.point_loss, **common),
                    X[train],
                    ys[train],
                    cv=KFold(folds, shuffle=True, random_state=seed)
                    if groups is None
                    else GroupKFold(folds),
                    groups=None if groups is None else groups[train],
                )
            else:
                oof = np.full(len(train), float(np.mean(ys[train])))
            self.residual_point_model_ = HistGradientBoostingRegressor(
                loss=self.point_loss, **common
            ).fit(X[train], ys[train])
            target = ys[train] - oof
        self.lower_model_ = HistGradientBoostingRegressor(
            loss="quantile", quantile=self.alpha / 2, **common
        ).fit(X[train], target)
        self.upper_model_ = HistGradientBoostingRegressor(
            loss="quantile", quantile=1 - self.alpha / 2, **common
        ).fit(X[train], target)

        lo, hi = self._raw_bounds(X[cal])
        scores = np.maximum(lo - ys[cal], ys[cal] - hi)
        # Floor on the raw width so a degenerate (zero-width) raw interval cannot make the
        # scaled score infinite: 1e-9 of the target's spread [model units].
        self.width_floor_ = 1e-9 * max(float(np.ptp(ys)), 1.0)
        if self.conformity == "scaled":
            scores = scores / self._raw_width(lo, hi)
        correction, self.coverage_guaranteed_ = conformal_quantile(scores, self.alpha)
        if not self.coverage_guaranteed_:
            needed = math.ceil(1 / self.alpha - 1 - 1e-9)
            warnings.warn(
                f"ClearanceEstimator: {n_cal} calibration samples are too few for "
                f"alpha={self.alpha:g} (need >= {needed}); the interval uses the largest "
                "calibration score and has no coverage guarantee",
                UserWarning,
                stacklevel=2,
            )
        self.conformal_correction_ = (
            correction / self.scale if self.conformity == "additive" else correction
        )
        self.n_calibration_ = n_cal

        self.point_model_ = HistGradientBoostingRegressor(loss=self.point_loss, **common).fit(X, ys)
        self.n_iter_ = max(
            int(m.n_iter_) for m in (self.lower_model_, self.upper_model_, self.point_model_)
        )
        return self

    def _raw_bounds(self, X):
        lo = regressor_predict(self.lower_model_, X)
        hi = regressor_predict(self.upper_model_, X)
        if self.residual_point_model_ is not None:
            centre = regressor_predict(self.residual_point_model_, X)
            lo, hi = centre + lo, centre + hi
        # Crossing quantile estimates are reordered, in calibration and prediction alike, so
        # the score remains one fixed function of (x, y) and the guarantee holds.
        return np.minimum(lo, hi), np.maximum(lo, hi)

    def _raw_width(self, lo, hi):
        return np.maximum(hi - lo, self.width_floor_)

    def _validated(self, X):
        check_is_fitted(self)
        return _predict_input(self, X)

    def _clip(self, values):
        if self.lower_limit is not None:
            values = np.maximum(values, self.lower_limit)
        return values

    def predict(self, X):
        """Point estimate of the target.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed.

        Returns
        -------
        ndarray of shape (n_samples,)
            Estimate [units of y].
        """
        X = self._validated(X)
        return self._clip(regressor_predict(self.point_model_, X) / self.scale)

    def predict_interval(self, X):
        """Conformal prediction interval of nominal coverage ``1 - alpha``.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed.

        Returns
        -------
        lower, upper : ndarray of shape (n_samples,)
            Interval bounds [units of y]; ``lower <= predict(X) <= upper``.
        """
        X = self._validated(X)
        lo, hi = self._raw_bounds(X)
        point = regressor_predict(self.point_model_, X) / self.scale
        if self.conformity == "additive":
            margin = self.conformal_correction_
        else:
            margin = self.conformal_correction_ * self._raw_width(lo, hi) / self.scale
        lower = lo / self.scale - margin
        upper = hi / self.scale + margin
        lower, upper = np.minimum(lower, point), np.maximum(upper, point)
        return self._clip(lower), self._clip(upper)


# --------------------------------------------------------------------------------------------
# Fault classification with calibrated probabilities
# --------------------------------------------------------------------------------------------


class FaultClassifier(ClassifierMixin, BaseEstimator):
    """Fault-class classifier: gradient boosting with calibrated class probabilities.

    A :class:`~sklearn.ensemble.HistGradientBoostingClassifier` is wrapped in
    :class:`~sklearn.calibration.CalibratedClassifierCV` with deterministic stratified,
    shuffled folds; ``predict_proba`` averages the fold models' calibrated probabilities.
    The class labels are whatever ``y`` holds (strings of the fault taxonomy, integers …);
    two or more classes are needed.

    Calibration defaults to the sigmoid (Platt) method: boosted trees are distorted in a
    sigmoid-shaped way and Platt scaling, with two parameters per class, is reliable on the
    few hundred samples per class a calibration fold typically holds, whereas isotonic
    regression overfits below roughly a thousand calibration samples [1]_. Choose
    ``"isotonic"`` for large training sets.

    On small data the number of calibration folds drops to the size of the smallest class (with
    ``groups``, to the fewest groups a class is seen in);
    with fewer than 2 samples in some class the booster is fitted uncalibrated
    (``calibration_folds_ = 0``) and a warning is issued.

    Parameters
    ----------
    max_iter : int, default 100
        Boosting iterations (trees per class).
    learning_rate : float, default 0.1
        Shrinkage of each tree, > 0.
    max_leaf_nodes : int or None, default 31
        Leaves per tree.
    min_samples_leaf : int, default 20
        Minimum samples per leaf.
    l2_regularization : float, default 0.0
        L2 penalty on leaf values, >= 0.
    class_weight : dict, "balanced" or None, default None
        Class weights (for imbalanced fault classes), keyed by label. Applied as sample
        weights to both the booster and the calibrator, so the probabilities are those of
        the reweighted class prior.
    calibration_method : {"sigmoid", "isotonic"}, default "sigmoid"
        Calibration method.
    calibration_cv : int, default 5
        Number of calibration folds (>= 2), reduced on small data.
    set_coverage : float, default 0.9
        Coverage of the class set (:meth:`predict_set`), in (0, 1): the share of held-out
        samples whose true class the set should hold.
    random_state : int, RandomState or None, default 0
        Seeds the folds and the boosting models.
    learner : {"boosting", "forest"}, default "boosting"
        What the calibration wraps: the gradient-boosted trees above, or a random forest of
        :data:`FOREST_TREES` trees (scikit-learn's defaults otherwise; of the boosting
        parameters only ``max_leaf_nodes`` applies). On a few dozen recordings the forest generalises better
        (2026-12-02, docs/import.md: cross-validated macro-F1 0.83–0.97 against 0.72–0.94 on
        the same indicators); ``train`` cross-validates both and ships the better. Its trees
        have at most ``max_leaf_nodes`` leaves, as the booster's.

    Attributes
    ----------
    classes_ : ndarray
        Class labels, sorted; column order of ``predict_proba``.
    n_features_in_ : int
        Number of features seen in ``fit``.
    feature_names_in_ : ndarray of str
        Feature names, when ``X`` had string column names.
    model_ : CalibratedClassifierCV or HistGradientBoostingClassifier
        Fitted model, trained on class indices ``0 … n_classes - 1``.
    calibration_folds_ : int
        Calibration folds used (0: uncalibrated).
    n_iter_ : int
        Largest number of boosting iterations run by the fold boosters.
    set_thresholds_ : ndarray of shape (n_classes,)
        Probability each class needs to enter the class set. From the calibration folds: each
        sample's calibrated probabilities come from the fold model that did not train on it,
        and a class's threshold is the conformal quantile of its own samples' probability of
        it [2]_ (least ambiguous set-valued classifier with class-specific coverage). 0
        without calibration folds (the set is then every class: nothing was held out to
        measure the ambiguity on).

    Notes
    -----
    The class set is what the evidence cannot rule out: where the features separate the
    classes it holds one; where an instrumentation cannot tell two classes apart (their
    held-out probabilities overlap) it mostly holds both, and a diagnosis should say "cannot
    tell" rather than pick one. By construction a share ``1 − set_coverage`` of each class's
    samples still gets a set without its class. The fold models are averaged in
    :meth:`predict_proba`, which is somewhat sharper than a single fold model, so the
    coverage is approximate (measured in the model card).

    References
    ----------
    .. [1] A. Niculescu-Mizil, R. Caruana, "Predicting good probabilities with supervised
       learning", ICML 2005, sections 3-4 and figure 6.
    .. [2] M. Sadinle, J. Lei, L. Wasserman, "Least ambiguous set-valued classifiers with
       bounded error levels", JASA 114 (2019), sections 2 and 4.1 (class-specific coverage).
    """

    def __init__(
        self,
        max_iter=100,
        learning_rate=0.1,
        max_leaf_nodes=31,
        min_samples_leaf=20,
        l2_regularization=0.0,
        class_weight=None,
        calibration_method="sigmoid",
        calibration_cv=5,
        set_coverage=0.9,
        random_state=0,
        learner="boosting",
    ):
        self.learner = learner
        self.max_iter = max_iter
        self.learning_rate = learning_rate
        self.max_leaf_nodes = max_leaf_nodes
        self.min_samples_leaf = min_samples_leaf
        self.l2_regularization = l2_regularization
        self.class_weight = class_weight
        self.calibration_method = calibration_method
        self.calibration_cv = calibration_cv
        self.set_coverage = set_coverage
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        return tags

    def __setstate__(self, state):
        # a model saved before the forest learner existed learnt with the booster
        state.setdefault("learner", "boosting")
        super().__setstate__(state)

    def _check_params(self) -> None:
        require_range("set_coverage", self.set_coverage, 0.0, 1.0, inclusive=False)
        require(
            self.calibration_method in ("sigmoid", "isotonic"),
            "calibration_method",
            self.calibration_method,
            "must be 'sigmoid' or 'isotonic'",
        )
        require(
            isinstance(self.calibration_cv, (int, np.integer)) and self.calibration_cv >= 2,
            "calibration_cv",
            self.calibration_cv,
            "must be an integer >= 2",
        )
        require(self.learner in LEARNERS, "learner", self.learner, f"must be one of {LEARNERS}")
        _check_hgb_params(self)

    def _learner(self, seed: int):
        """The unfitted model the calibration wraps: the booster, or the forest."""
        if self.learner == "forest":
            # trees no larger than the booster's (max_leaf_nodes): on a few dozen recordings
            # they grow fully anyway, on thousands a shipped forest stays as small as a booster
            return RandomForestClassifier(
                n_estimators=FOREST_TREES,
                max_leaf_nodes=self.max_leaf_nodes,
                random_state=seed,
                n_jobs=1,
            )
        return HistGradientBoostingClassifier(**_hgb_params(self), random_state=seed)

    def fit(self, X, y, groups=None):
        """Fit the booster and its probability calibration.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed (missing feature), inf not.
        y : array-like of shape (n_samples,)
            Class labels (at least 2 distinct).
        groups : array-like of shape (n_samples,) or None
            The unit (or recording) each sample comes from. Given, the calibration folds keep
            a group's samples together (stratified group k-fold), so the probabilities and the
            class-set thresholds are calibrated on units the fold model never saw — several
            recordings of one unit in both halves of a fold would make them as confident on a
            new unit as on a known one.

        Returns
        -------
        self : FaultClassifier
        """
        self._check_params()
        X, y = validate_data(self, X, y, ensure_all_finite="allow-nan", dtype=np.float64)
        check_classification_targets(y)
        self.classes_, y_idx = np.unique(y, return_inverse=True)
        if len(self.classes_) < 2:
            raise ParameterError(
                "n_classes", 1, "a classifier needs at least 2 classes in y, got 1 class"
            )
        # Class indices, not labels, go to the inner models: string labels then never meet
        # the calibration code, and predict_proba columns follow classes_ by construction.
        y_idx = y_idx.astype(np.int64)
        rng = check_random_state(self.random_state)
        seed = int(rng.randint(_SEED_MAX))
        # Class weights become sample weights seen by the booster *and* the calibrator:
        # weighting only the booster would be undone by calibrating on unweighted folds.
        sample_weight = None
        if self.class_weight is not None:
            class_weight = self.class_weight
            if isinstance(class_weight, Mapping):
                index = {label: i for i, label in enumerate(self.classes_.tolist())}
                unknown = [k for k in class_weight if k not in index]
                require(
                    not unknown,
                    "class_weight",
                    unknown,
                    f"labels not in y; classes are {self.classes_.tolist()}",
                )
                class_weight = {index[k]: w for k, w in class_weight.items()}
            sample_weight = compute_sample_weight(class_weight, y_idx)
        booster = self._learner(seed)
        folds = int(min(self.calibration_cv, np.bincount(y_idx).min()))
        if groups is not None:
            groups = np.asarray(groups)
            require(
                len(groups) == len(y_idx), "groups", len(groups), f"one per sample ({len(y_idx)})"
            )
            # a class seen in fewer groups than folds leaves some fold without it
            folds = min(folds, min(len(np.unique(groups[y_idx == k])) for k in np.unique(y_idx)))
        if folds >= 2:
            if groups is None:
                cv = StratifiedKFold(n_splits=folds, shuffle=True, random_state=seed)
            else:
                cv = StratifiedGroupKFold(n_splits=folds, shuffle=True, random_state=seed)
            splits = list(cv.split(X, y_idx, groups))
            self.model_ = CalibratedClassifierCV(
                booster, method=self.calibration_method, cv=splits
            ).fit(X, y_idx, sample_weight=sample_weight)
            self.calibration_folds_ = folds
            boosters = [c.estimator for c in self.model_.calibrated_classifiers_]
            self.set_thresholds_ = self._set_thresholds(X, y_idx, splits)
        else:
            warnings.warn(
                "FaultClassifier: a class has a single sample, so probabilities are not calibrated",
                UserWarning,
                stacklevel=2,
            )
            self.model_ = booster.fit(X, y_idx, sample_weight=sample_weight)
            self.calibration_folds_ = 0
            boosters = [self.model_]
            self.set_thresholds_ = np.zeros(len(self.classes_))
        # a forest has no boosting iterations: its trees
        self.n_iter_ = max(int(getattr(b, "n_iter_", FOREST_TREES)) for b in boosters)
        return self

    def _set_thresholds(self, X, y_idx, splits) -> np.ndarray:
        """Per-class conformal thresholds of the class set from the out-of-fold calibrated
        probabilities.

        ``calibrated_classifiers_`` follow ``splits`` in order, so fold ``k``'s model predicts
        exactly the samples it did not see."""
        held_out = np.empty(len(y_idx))
        for model, (_, test) in zip(self.model_.calibrated_classifiers_, splits):
            proba = np.clip(model.predict_proba(X[test]), 0.0, 1.0)
            proba /= proba.sum(axis=1, keepdims=True)
            held_out[test] = proba[np.arange(len(test)), y_idx[test]]
        # Sadinle et al. section 4.1 (class-specific coverage): per class, the
        # floor((n_y + 1)·α)-th smallest held-out probability of that class among its own
        # samples, so that a new sample of class y keeps y in its set with probability ≥
        # set_coverage, whatever the class — a rare class is not sacrificed to a common one
        thresholds = np.zeros(len(self.classes_))
        for k in range(len(self.classes_)):
            own = np.sort(held_out[y_idx == k])
            rank = int(np.floor((len(own) + 1) * (1.0 - self.set_coverage)))
            thresholds[k] = own[rank - 1] if rank >= 1 else 0.0
        return thresholds

    def predict_set(self, X):
        """The class set: every class whose probability reaches its ``set_thresholds_``.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed.

        Returns
        -------
        ndarray of bool, shape (n_samples, n_classes)
            True where the class is in the set (columns follow ``classes_``); the most probable
            class always is, so no set is empty.
        """
        proba = self.predict_proba(X)
        return class_sets(proba, self.set_thresholds_)

    def predict_proba(self, X):
        """Class probabilities.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed.

        Returns
        -------
        ndarray of shape (n_samples, n_classes)
            Probabilities in the order of ``classes_``; each row sums to 1.
        """
        check_is_fitted(self)
        X = _predict_input(self, X)
        if isinstance(self.model_, CalibratedClassifierCV):
            proba = calibrated_proba(self.model_, X)
        else:
            proba = self.model_.predict_proba(X)
        proba = np.clip(proba, 0.0, 1.0)
        return proba / proba.sum(axis=1, keepdims=True)

    def predict(self, X):
        """Most probable class.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed.

        Returns
        -------
        ndarray of shape (n_samples,)
            Labels from ``classes_``.
        """
        proba = self.predict_proba(X)
        return self.classes_[np.argmax(proba, axis=1)]


def class_sets(proba, thresholds) -> np.ndarray:
    """Boolean class sets of probability rows: ``p >= thresholds`` (one per class) plus each
    row's most probable class (:meth:`FaultClassifier.predict_set`; also for averaged window
    probabilities)."""
    proba = np.atleast_2d(np.asarray(proba, float))
    chosen = proba >= np.asarray(thresholds, float)
    chosen[np.arange(len(proba)), np.argmax(proba, axis=1)] = True
    return chosen


# --------------------------------------------------------------------------------------------
# Out-of-distribution score
# --------------------------------------------------------------------------------------------


#: Two training rows are at different levels of an operating factor when they differ by more
#: than this share of its training span (a grid's neighbouring speeds, 80 and 100 rad/s of a
#: 40–120 sweep, differ by a quarter; a random sweep's nearest windows by less, and their
#: midpoints then only fill in where windows already are).
LEVEL_GAP = 0.05


class DistributionGuard(BaseEstimator):
    """How far a row of indicators lies from the training rows: an out-of-distribution score.

    Indicators are put on a common scale (centred on the training median, divided by the
    training IQR/1.349, a robust standard deviation). The distance of two rows is the RMS of
    their differences over the indicators either has; an indicator one row has and the other
    lacks (NaN) counts as ``missing_penalty`` robust standard deviations, so a window that lacks
    what the training windows had (no reversal, a missing channel) is far from all of them. The
    raw score of a row is its mean distance to its ``n_neighbors`` nearest training rows
    (k-nearest-neighbour novelty detection [3]_); the score returned is the raw score divided by
    the ``quantile`` of the training rows' own raw scores (each left out of its own neighbours):
    ≤ 1 for all but a fraction ``1 − quantile`` of windows like the training ones, ≫ 1 for a
    window unlike any of them.

    **Between the levels of an operating factor** (``factors``: the columns of continuous
    factors such as speed and load) a dataset swept on a grid has no window, and its indicators
    (mesh frequency, band energies, torque) move with the factor: a window at 90 rad/s of a
    model trained at 80 and 100 would score as unlike both. So each training row is paired
    with its nearest row at another level of each factor (differing by more than
    :data:`LEVEL_GAP` of the factor's training span) and their midpoint joins the rows a window
    is compared with — a linear interpolation of the indicators between neighbouring levels.
    The threshold stays that of the training rows among themselves, so a window like them
    scores as before or lower, and a window outside the factors' span or unlike any pair as
    before.

    Parameters
    ----------
    n_neighbors : int, default 5
    quantile : float, default 0.99
        Training quantile that scores 1, in (0, 1).
    missing_penalty : float, default 5.0
        Distance [robust standard deviations] of a present to an absent indicator, ≥ 0.
    factors : sequence of int, default ()
        Columns of the continuous operating factors to interpolate between (none: no
        interpolation, the guard as it was).

    References
    ----------
    .. [3] S. Ramaswamy, R. Rastogi, K. Shim, "Efficient algorithms for mining outliers from
       large data sets", SIGMOD 2000 (distance to the k-th nearest neighbour as outlier score).
    """

    def __init__(self, n_neighbors=5, quantile=0.99, missing_penalty=5.0, factors=()):
        self.n_neighbors = n_neighbors
        self.quantile = quantile
        self.missing_penalty = missing_penalty
        self.factors = factors

    def fit(self, X, y=None):
        require(
            isinstance(self.n_neighbors, (int, np.integer)) and self.n_neighbors >= 1,
            "n_neighbors",
            self.n_neighbors,
            "must be an integer >= 1",
        )
        require_range("quantile", self.quantile, 0.0, 1.0, inclusive=False)
        require_range("missing_penalty", self.missing_penalty, 0.0, math.inf)
        X = validate_data(self, X, ensure_all_finite="allow-nan", dtype=np.float64)
        require(len(X) > self.n_neighbors, "X", len(X), f"needs more than {self.n_neighbors} rows")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN columns
            self.center_ = np.nan_to_num(np.nanmedian(X, axis=0))
            q75, q25 = np.nanpercentile(X, [75, 25], axis=0)
            spread = np.nan_to_num((q75 - q25) / 1.349)
            fallback = np.nan_to_num(np.nanstd(X, axis=0))
        # a constant column (IQR 0): its standard deviation; never below 0.1 % of its level, so
        # a column constant in training up to rounding does not make every change infinite
        spread = np.where(spread > 0, spread, fallback)
        self.scale_ = np.maximum(spread, 1e-3 * np.maximum(np.abs(self.center_), 1e-9))
        self.reference_ = self._scaled(X)
        raw = self._raw(self.reference_, leave_out_self=True)
        self.threshold_ = float(np.quantile(raw, self.quantile))
        between = self._between(X)
        self.n_between_ = len(between)
        self.reference_ = np.concatenate([self.reference_, between])
        return self

    def _between(self, X) -> np.ndarray:
        """The midpoints (scaled) of each training row and its nearest row at another level of
        each factor, each pair once; an indicator missing in either is missing in theirs."""
        from ._kernels import nearest_across

        Z = self.reference_
        columns = list(self.factors)
        for column in columns:
            require(
                isinstance(column, (int, np.integer)) and 0 <= column < X.shape[1],
                "factors",
                column,
                f"must be column indices below {X.shape[1]}",
            )
        values = X[:, columns].astype(np.float64)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN factor
            span = np.nanmax(values, axis=0) - np.nanmin(values, axis=0)
        spread = span > 0  # a factor at one level (or all NaN) has no other level
        if not spread.any():
            return np.empty((0, Z.shape[1]), np.float32)
        partner = np.empty((len(Z), int(spread.sum())), np.int64)
        nearest_across(
            np.ascontiguousarray(Z, np.float32),
            np.ascontiguousarray(values[:, spread]),
            np.ascontiguousarray(LEVEL_GAP * span[spread]),
            float(self.missing_penalty**2),
            partner,
        )
        rows, factor = np.nonzero(partner >= 0)
        mates = partner[rows, factor]
        pairs = set(zip(np.minimum(rows, mates).tolist(), np.maximum(rows, mates).tolist()))
        if not pairs:
            return np.empty((0, Z.shape[1]), np.float32)
        first, second = (np.array(side) for side in zip(*sorted(pairs)))
        return (0.5 * (Z[first] + Z[second])).astype(np.float32)  # NaN where either is

    def _scaled(self, X) -> np.ndarray:
        return ((X - self.center_) / self.scale_).astype(np.float32)

    def _raw(self, Z: np.ndarray, leave_out_self: bool = False) -> np.ndarray:
        """Mean distance of each row of Z (scaled) to its ``n_neighbors`` nearest training
        rows (itself left out with ``leave_out_self``: Z is then the training rows)."""
        from ._kernels import neighbour_distances

        out = np.empty(len(Z))
        neighbour_distances(
            np.ascontiguousarray(Z, np.float32),
            np.ascontiguousarray(self.reference_, np.float32),
            float(self.missing_penalty**2),
            int(self.n_neighbors),
            0 if leave_out_self else -1,
            out,
        )
        return out

    def score(self, X) -> np.ndarray:
        """Out-of-distribution score of each row (1 = the training rows' ``quantile``)."""
        check_is_fitted(self)
        X = _predict_input(self, X)
        return self._raw(self._scaled(X)) / max(self.threshold_, 1e-12)
