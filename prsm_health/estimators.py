"""Health estimators: clearance regression with a prediction interval, fault classification.

Both estimators are scikit-learn compatible (``__init__`` stores its arguments, learned
attributes end in ``_``, ``fit`` returns ``self``; they pass
:func:`sklearn.utils.estimator_checks.parametrize_with_checks`) and accept feature tables with
missing values (NaN: a feature not computable for a window, e.g. lost motion without a
reversal), because gradient-boosted histogram trees route NaN to a learned side of each split.

- :class:`ClearanceEstimator`: conformalized quantile regression (CQR) of a clearance [m];
  the interval is wide where the operating regime hides the clearance and narrow where it
  reveals it.
- :class:`FaultClassifier`: gradient boosting with Platt-calibrated class probabilities.
- :func:`permutation_importance_table`: per-feature and per-group permutation importance.
- :func:`cross_validated_metrics`: out-of-fold metrics stored beside a trained model.
- :func:`save_model` / :func:`load_model`: skops persistence that only loads types from
  scikit-learn, numpy and this module, and checks the versions the model was saved with.

References
----------
.. [1] Y. Romano, E. Patterson, E. Candès, "Conformalized quantile regression", NeurIPS 2019
   (the CQR algorithm, conformity score eq. 6 and correction eq. 7 of the paper).
.. [2] A. Niculescu-Mizil, R. Caruana, "Predicting good probabilities with supervised
   learning", ICML 2005 (boosted trees need calibration; Platt scaling beats isotonic
   regression when the calibration set is small).
"""

from __future__ import annotations

import importlib
import io
import json
import math
import os
import re
import tempfile
import warnings
import zipfile
from collections.abc import Callable, Mapping
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import sklearn
from sklearn.base import BaseEstimator, ClassifierMixin, RegressorMixin, clone, is_classifier
from sklearn.calibration import CalibratedClassifierCV
from sklearn.ensemble import HistGradientBoostingClassifier, HistGradientBoostingRegressor
from sklearn.inspection import permutation_importance
from sklearn.metrics import (
    accuracy_score,
    check_scoring,
    f1_score,
    log_loss,
    mean_absolute_error,
    mean_squared_error,
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

from .errors import ModelVersionError, ParameterError, PRSMHealthError, require, require_range
from .jsonable import json_ready

__all__ = [
    "ClearanceEstimator",
    "FaultClassifier",
    "ModelVersionError",
    "cross_validated_metrics",
    "load_model",
    "permutation_importance_table",
    "save_model",
]

_SEED_MAX = np.iinfo(np.int32).max


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

    def fit(self, X, y):
        """Fit the quantile and point models and calibrate the interval.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed (missing feature), inf not.
        y : array-like of shape (n_samples,)
            Target, e.g. a clearance [m].

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
        order = rng.permutation(n)
        n_cal = min(max(int(round(self.calibration_fraction * n)), 1), n - 1)
        cal, train = order[:n_cal], order[n_cal:]
        seed = int(rng.randint(_SEED_MAX))
        ys = np.asarray(y, dtype=np.float64) * self.scale

        common = dict(_hgb_params(self), random_state=seed)
        target = ys[train]
        self.residual_point_model_ = None
        if self.quantiles_of == "residual":
            # Out-of-fold residuals: in-sample boosting residuals would be optimistic.
            folds = min(5, len(train))
            if folds >= 2:
                oof = cross_val_predict(
                    HistGradientBoostingRegressor(loss=self.point_loss, **common),
                    X[train],
                    ys[train],
                    cv=KFold(folds, shuffle=True, random_state=seed),
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
        scores = np.sort(scores)
        # Finite-sample quantile of [1] eq. 7; the tolerance keeps (n+1)(1-alpha) = 90.000…1
        # from rounding up to the next order statistic.
        k = math.ceil((n_cal + 1) * (1 - self.alpha) - 1e-9)
        self.coverage_guaranteed_ = k <= n_cal
        if not self.coverage_guaranteed_:
            needed = math.ceil(1 / self.alpha - 1 - 1e-9)
            warnings.warn(
                f"ClearanceEstimator: {n_cal} calibration samples are too few for "
                f"alpha={self.alpha:g} (need >= {needed}); the interval uses the largest "
                "calibration score and has no coverage guarantee",
                UserWarning,
                stacklevel=2,
            )
        correction = float(scores[min(k, n_cal) - 1])
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
        lo = self.lower_model_.predict(X)
        hi = self.upper_model_.predict(X)
        if self.residual_point_model_ is not None:
            centre = self.residual_point_model_.predict(X)
            lo, hi = centre + lo, centre + hi
        # Crossing quantile estimates are reordered, in calibration and prediction alike, so
        # the score remains one fixed function of (x, y) and the guarantee holds.
        return np.minimum(lo, hi), np.maximum(lo, hi)

    def _raw_width(self, lo, hi):
        return np.maximum(hi - lo, self.width_floor_)

    def _validated(self, X):
        check_is_fitted(self)
        return validate_data(self, X, reset=False, ensure_all_finite="allow-nan", dtype=np.float64)

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
        return self._clip(self.point_model_.predict(X) / self.scale)

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
        point = self.point_model_.predict(X) / self.scale
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

    On small data the number of calibration folds drops to the size of the smallest class;
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
    random_state : int, RandomState or None, default 0
        Seeds the folds and the boosting models.

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

    References
    ----------
    .. [1] A. Niculescu-Mizil, R. Caruana, "Predicting good probabilities with supervised
       learning", ICML 2005, sections 3-4 and figure 6.
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
        random_state=0,
    ):
        self.max_iter = max_iter
        self.learning_rate = learning_rate
        self.max_leaf_nodes = max_leaf_nodes
        self.min_samples_leaf = min_samples_leaf
        self.l2_regularization = l2_regularization
        self.class_weight = class_weight
        self.calibration_method = calibration_method
        self.calibration_cv = calibration_cv
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        return tags

    def _check_params(self) -> None:
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
        _check_hgb_params(self)

    def fit(self, X, y):
        """Fit the booster and its probability calibration.

        Parameters
        ----------
        X : array-like or DataFrame of shape (n_samples, n_features)
            Features; NaN allowed (missing feature), inf not.
        y : array-like of shape (n_samples,)
            Class labels (at least 2 distinct).

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
        booster = HistGradientBoostingClassifier(**_hgb_params(self), random_state=seed)
        folds = int(min(self.calibration_cv, np.bincount(y_idx).min()))
        if folds >= 2:
            cv = StratifiedKFold(n_splits=folds, shuffle=True, random_state=seed)
            self.model_ = CalibratedClassifierCV(
                booster, method=self.calibration_method, cv=cv
            ).fit(X, y_idx, sample_weight=sample_weight)
            self.calibration_folds_ = folds
            boosters = [c.estimator for c in self.model_.calibrated_classifiers_]
        else:
            warnings.warn(
                "FaultClassifier: a class has a single sample, so probabilities are not calibrated",
                UserWarning,
                stacklevel=2,
            )
            self.model_ = booster.fit(X, y_idx, sample_weight=sample_weight)
            self.calibration_folds_ = 0
            boosters = [self.model_]
        self.n_iter_ = max(int(b.n_iter_) for b in boosters)
        return self

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
        X = validate_data(self, X, reset=False, ensure_all_finite="allow-nan", dtype=np.float64)
        proba = np.clip(self.model_.predict_proba(X), 0.0, 1.0)
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


# --------------------------------------------------------------------------------------------
# Feature importance
# --------------------------------------------------------------------------------------------


def _feature_names(estimator, X) -> list[str]:
    if isinstance(X, pd.DataFrame):
        return [str(c) for c in X.columns]
    names = getattr(estimator, "feature_names_in_", None)
    if names is not None and len(names) == np.shape(X)[1]:
        return [str(c) for c in names]
    return [f"x{i}" for i in range(np.shape(X)[1])]


def permutation_importance_table(
    estimator,
    X,
    y,
    *,
    n_repeats: int = 5,
    random_state: int = 0,
    groups: dict[str, list[str]] | None = None,
    scoring=None,
) -> pd.DataFrame:
    """Permutation importance of each feature and of named feature groups.

    A feature's (group's) importance is the drop of the score when its column (all its
    columns, with one shared row permutation, so correlations inside the group are kept)
    is shuffled. Groups answer questions single features cannot when features are
    correlated, e.g. "how much do the mesh-frequency indicators matter together?".

    Parameters
    ----------
    estimator : fitted estimator
        Model to explain.
    X : DataFrame or array-like of shape (n_samples, n_features)
        Evaluation features (held-out data gives the honest answer).
    y : array-like of shape (n_samples,)
        Evaluation targets.
    n_repeats : int, default 5
        Permutations per feature or group.
    random_state : int, default 0
        Seed: the result is deterministic.
    groups : dict of str to list of str, optional
        Named groups of column names, e.g. ``{"mesh": [...], "axial_frequency": [...]}``.
        Without a DataFrame, column names are ``estimator.feature_names_in_`` or ``x0, x1 …``.
    scoring : str, callable or None, default None
        Score to use; None uses ``estimator.score`` (R² or accuracy).

    Returns
    -------
    DataFrame
        One row per group (``kind="group"``, first) and per feature (``kind="feature"``),
        each sorted by decreasing importance, with columns ``name``, ``kind``, ``columns``
        (comma-separated member columns), ``importance_mean``, ``importance_std`` [score
        units] and ``rank`` (1 = most important, within the kind). ``DataFrame.attrs``
        holds ``baseline_score``.
    """
    require(
        isinstance(n_repeats, (int, np.integer)) and n_repeats >= 1,
        "n_repeats",
        n_repeats,
        "must be an integer >= 1",
    )
    names = _feature_names(estimator, X)
    column_of = {name: i for i, name in enumerate(names)}
    groups = dict(groups or {})
    for group, members in groups.items():
        require(
            isinstance(members, (list, tuple)) and len(members) > 0,
            f"groups[{group!r}]",
            members,
            "must be a non-empty list of column names",
        )
        unknown = [m for m in members if m not in column_of]
        require(
            not unknown,
            f"groups[{group!r}]",
            unknown,
            f"unknown column(s); columns are {', '.join(names)}",
        )

    per_feature = permutation_importance(
        estimator, X, y, scoring=scoring, n_repeats=n_repeats, random_state=random_state
    )
    rows = [
        {
            "name": name,
            "kind": "feature",
            "columns": name,
            "importance_mean": float(per_feature.importances_mean[i]),
            "importance_std": float(per_feature.importances_std[i]),
        }
        for i, name in enumerate(names)
    ]

    scorer = check_scoring(estimator, scoring=scoring)
    baseline = float(scorer(estimator, X, y))
    n = np.shape(X)[0]
    rng = check_random_state(random_state)
    # Every group sees the same permutations, which makes groups directly comparable.
    permutations = [rng.permutation(n) for _ in range(n_repeats)]
    frame = isinstance(X, pd.DataFrame)
    X_values = X if frame else np.asarray(X)
    for group, members in groups.items():
        idx = [column_of[m] for m in members]
        drops = []
        for perm in permutations:
            Xp = X_values.copy()
            if frame:
                Xp.iloc[:, idx] = X_values.iloc[perm, idx].to_numpy()
            else:
                Xp[:, idx] = X_values[perm][:, idx]
            drops.append(baseline - float(scorer(estimator, Xp, y)))
        rows.append(
            {
                "name": group,
                "kind": "group",
                "columns": ", ".join(members),
                "importance_mean": float(np.mean(drops)),
                "importance_std": float(np.std(drops)),
            }
        )

    table = pd.DataFrame(
        rows, columns=["name", "kind", "columns", "importance_mean", "importance_std"]
    )
    table["kind_order"] = (table["kind"] == "feature").astype(int)
    table = table.sort_values(
        ["kind_order", "importance_mean"], ascending=[True, False], kind="stable"
    ).drop(columns="kind_order")
    table["rank"] = table.groupby("kind").cumcount() + 1
    table = table.reset_index(drop=True)
    table.attrs["baseline_score"] = baseline
    return table


# --------------------------------------------------------------------------------------------
# Cross-validated metrics
# --------------------------------------------------------------------------------------------


def _take(X, idx):
    return X.iloc[idx] if isinstance(X, (pd.DataFrame, pd.Series)) else X[idx]


def cross_validated_metrics(
    estimator_factory: Callable[[], Any] | BaseEstimator,
    X,
    y,
    groups=None,
    cv=5,
) -> dict:
    """Out-of-fold metrics of an estimator, for the model card beside a trained model.

    Metrics are computed once on the pooled out-of-fold predictions (every sample predicted
    by a model that did not see it) and also per fold.

    Parameters
    ----------
    estimator_factory : callable or estimator
        Returns a fresh unfitted estimator (an estimator instance is cloned per fold).
    X : DataFrame or array-like of shape (n_samples, n_features)
        Features.
    y : array-like of shape (n_samples,)
        Targets: clearances [m] or class labels.
    groups : array-like of shape (n_samples,), optional
        Group of each sample (e.g. the run or operating point it comes from): samples of one
        group never straddle training and test folds, so windows of the same run cannot leak.
        Uses :class:`~sklearn.model_selection.GroupKFold` (regression) or its stratified
        variant :class:`~sklearn.model_selection.StratifiedGroupKFold` (classification,
        which also balances the classes across folds).
    cv : int or CV splitter, default 5
        Number of folds (shuffled with seed 0 when there are no groups), or a splitter.

    Returns
    -------
    dict
        JSON-serialisable. Always ``task``, ``n_samples``, ``n_splits``, ``splitter`` and
        ``folds`` (per-fold metrics). Interval regression (:class:`ClearanceEstimator`):
        ``mae``, ``rmse`` [units of y], ``interval_coverage`` (fraction of targets inside
        the interval), ``nominal_coverage`` (``1 - alpha``), ``mean_interval_width``
        [units of y]. Plain regression: ``mae``, ``rmse``. Classification: ``accuracy``,
        ``macro_f1``, ``log_loss`` [nat], ``classes``.
    """
    make = (
        estimator_factory
        if callable(estimator_factory) and not isinstance(estimator_factory, BaseEstimator)
        else (lambda: clone(estimator_factory))
    )
    probe = make()
    classification = is_classifier(probe)
    interval = hasattr(probe, "predict_interval")
    y = np.asarray(y)
    n = len(y)
    require(np.shape(X)[0] == n, "y", f"{n} samples", f"must match X ({np.shape(X)[0]} rows)")

    if isinstance(cv, (int, np.integer)):
        require(cv >= 2, "cv", cv, "must be an integer >= 2 or a CV splitter")
        if groups is not None:
            n_groups = len(np.unique(np.asarray(groups)))
            require(n_groups >= cv, "cv", cv, f"must not exceed the number of groups ({n_groups})")
            splitter = StratifiedGroupKFold(n_splits=cv) if classification else GroupKFold(cv)
        elif classification:
            splitter = StratifiedKFold(n_splits=cv, shuffle=True, random_state=0)
        else:
            splitter = KFold(n_splits=cv, shuffle=True, random_state=0)
    else:
        splitter = cv
    splits = list(splitter.split(X, y, groups))

    if classification:
        classes = np.unique(y)
        oof_proba = np.zeros((n, len(classes)))
    else:
        oof = np.zeros(n)
        oof_lo, oof_hi = np.zeros(n), np.zeros(n)
    folds = []
    for train, test in splits:
        est = make().fit(_take(X, train), y[train])
        X_test, y_test = _take(X, test), y[test]
        if classification:
            cols = np.searchsorted(classes, est.classes_)
            oof_proba[np.ix_(test, cols)] = est.predict_proba(X_test)
            pred = classes[np.argmax(oof_proba[test], axis=1)]
            folds.append(
                {
                    "n_test": len(test),
                    "accuracy": float(accuracy_score(y_test, pred)),
                    "macro_f1": float(f1_score(y_test, pred, average="macro", zero_division=0)),
                }
            )
        else:
            oof[test] = pred = est.predict(X_test)
            fold = {"n_test": len(test), "mae": float(mean_absolute_error(y_test, pred))}
            if interval:
                oof_lo[test], oof_hi[test] = est.predict_interval(X_test)
                inside = (oof_lo[test] <= y_test) & (y_test <= oof_hi[test])
                fold["interval_coverage"] = float(inside.mean())
                fold["mean_interval_width"] = float(np.mean(oof_hi[test] - oof_lo[test]))
            folds.append(fold)

    result: dict[str, Any] = {
        "n_samples": n,
        "n_splits": len(splits),
        "splitter": type(splitter).__name__,
    }
    if classification:
        pred = classes[np.argmax(oof_proba, axis=1)]
        result.update(
            task="classification",
            classes=classes.tolist(),
            accuracy=float(accuracy_score(y, pred)),
            macro_f1=float(f1_score(y, pred, average="macro", zero_division=0)),
            log_loss=float(log_loss(y, oof_proba, labels=classes)),
        )
    else:
        result.update(
            task="interval_regression" if interval else "regression",
            mae=float(mean_absolute_error(y, oof)),
            rmse=float(np.sqrt(mean_squared_error(y, oof))),
        )
        if interval:
            result.update(
                interval_coverage=float(np.mean((oof_lo <= y) & (y <= oof_hi))),
                nominal_coverage=float(1 - probe.alpha),
                mean_interval_width=float(np.mean(oof_hi - oof_lo)),
            )
    result["folds"] = folds
    return result


# --------------------------------------------------------------------------------------------
# Persistence
# --------------------------------------------------------------------------------------------


_HEADER_NAME = "prsm_health.json"
_FORMAT = "prsm_health-model"
_FORMAT_VERSION = 1
_RESERVED_METADATA = ("versions", "saved_at")
# Module roots whose classes a model file may instantiate; anything else is refused.
_TRUSTED_ROOTS = ("sklearn", "numpy", "prsm_health.estimators")


def _package_version() -> str:
    # Imported lazily: prsm_health/__init__ may import this module before defining it.
    from prsm_health import __version__

    return __version__


def _current_versions() -> dict[str, str]:
    import skops

    return {
        "prsm_health": _package_version(),
        "scikit-learn": sklearn.__version__,
        "numpy": np.__version__,
        "skops": skops.__version__,
    }


def _major_minor(version: str) -> tuple[int, int] | None:
    match = re.match(r"\s*(\d+)\.(\d+)", str(version))
    return (int(match[1]), int(match[2])) if match else None


def _in_trusted_root(name: str) -> bool:
    return any(name == root or name.startswith(root + ".") for root in _TRUSTED_ROOTS)


def _resolve(name: str):
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr, None)
            if obj is None:
                return None
        return obj
    return None


def _is_trusted(name: str) -> bool:
    """Trust only classes defined in scikit-learn, numpy or this module.

    Functions are refused even from those packages: skops may call a loaded callable with
    arguments from the file (numpy alone has functions that execute strings).
    """
    if not _in_trusted_root(name):
        return False
    obj = _resolve(name)
    return isinstance(obj, type) and _in_trusted_root(f"{obj.__module__}.{obj.__qualname__}")


def _refused_types(payload: bytes) -> tuple[list[str], list[str]]:
    import skops.io as sio

    untrusted = sio.get_untrusted_types(data=payload)
    return untrusted, [t for t in untrusted if not _is_trusted(t)]


def _bundle_bytes(model, header: dict) -> bytes:
    """skops payload of ``model`` with the JSON header as an extra zip member."""
    import skops.io as sio

    buffer = io.BytesIO(sio.dumps(model, compression=zipfile.ZIP_DEFLATED))
    # skops ignores members it does not know, so the file stays loadable by skops itself;
    # the header is plain JSON, readable before anything is instantiated.
    with zipfile.ZipFile(buffer, "a", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(_HEADER_NAME, json.dumps(json_ready(header), indent=1))
    return buffer.getvalue()


def _write_atomic(path: Path, data: bytes) -> None:
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as err:
        raise PRSMHealthError(f"{path}: cannot write model file ({err.strerror})") from err
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def save_model(path, model, *, metadata: dict) -> Path:
    """Save a model (an estimator or a dict of them) with versions and metadata.

    The file is a skops archive of ``model`` plus a JSON member ``prsm_health.json`` with the
    prsm_health, scikit-learn, numpy and skops versions, the save time and ``metadata``.
    It is written to a temporary file in the target directory and renamed, so a reader never
    sees a partial file.

    Parameters
    ----------
    path : str or Path
        Destination file (conventionally ``*.skops``); replaced if it exists.
    model : estimator or dict
        E.g. ``{"clearance": ClearanceEstimator, "fault_class": FaultClassifier}``. Must
        contain only types :func:`load_model` trusts (classes from scikit-learn, numpy and
        :mod:`prsm_health.estimators`, plus builtins).
    metadata : dict
        JSON-serialisable user metadata: feature names, training data description, metrics…
        The keys ``versions`` and ``saved_at`` are reserved.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        Metadata that is not a JSON-serialisable dict or uses a reserved key.
    PRSMHealthError
        A model holding types that :func:`load_model` would refuse; an unwritable path.
    """
    path = Path(path)
    require(isinstance(metadata, dict), "metadata", type(metadata).__name__, "must be a dict")
    reserved = [k for k in _RESERVED_METADATA if k in metadata]
    require(not reserved, "metadata", reserved, "keys 'versions' and 'saved_at' are reserved")
    try:
        json.dumps(json_ready(metadata))
    except (TypeError, ValueError) as err:
        raise ParameterError("metadata", "…", f"must be JSON-serialisable ({err})") from err
    header = {
        "format": _FORMAT,
        "format_version": _FORMAT_VERSION,
        "versions": _current_versions(),
        "saved_at": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "metadata": metadata,
    }
    data = _bundle_bytes(model, header)
    _, refused = _refused_types(data)
    if refused:
        raise PRSMHealthError(
            f"{path}: cannot save a model holding types load_model would refuse: "
            + ", ".join(refused)
        )
    _write_atomic(path, data)
    return path


def _not_a_model(path, reason) -> PRSMHealthError:
    return PRSMHealthError(f"{path}: not a prsm_health model file ({reason})")


def load_model(path, *, allow_version_mismatch: bool = False) -> tuple[Any, dict]:
    """Load a model saved by :func:`save_model`, safely.

    The JSON header is read and checked before anything is instantiated; only classes from
    scikit-learn, numpy and :mod:`prsm_health.estimators` (and skops' default-trusted
    builtins) are loaded.

    Parameters
    ----------
    path : str or Path
        Model file.
    allow_version_mismatch : bool, default False
        Load (with a warning) a model saved by another prsm_health or scikit-learn
        major.minor version. Predictions of such a model are not guaranteed to be right.

    Returns
    -------
    model : estimator or dict
        What was saved.
    metadata : dict
        The user metadata plus ``versions`` (dict of package versions at save time) and
        ``saved_at`` (ISO 8601 UTC).

    Raises
    ------
    ModelVersionError
        Saved with another major.minor version of prsm_health or scikit-learn (the numpy
        version is recorded but not checked: its array format is stable).
    PRSMHealthError
        Unreadable, corrupt or foreign file; untrusted types in the file.
    """
    import skops.io as sio

    try:
        data = Path(path).read_bytes()
    except OSError as err:
        raise PRSMHealthError(f"{path}: cannot read model file ({err.strerror})") from err
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            header = json.loads(zf.read(_HEADER_NAME))
    except zipfile.BadZipFile as err:
        raise _not_a_model(path, "not a zip archive") from err
    except KeyError as err:
        raise _not_a_model(path, f"no {_HEADER_NAME} header") from err
    except (ValueError, OSError, RuntimeError, zipfile.LargeZipFile) as err:
        raise _not_a_model(path, f"unreadable header: {err}") from err
    if not isinstance(header, dict) or header.get("format") != _FORMAT:
        raise _not_a_model(path, "unknown header format")
    if header.get("format_version") != _FORMAT_VERSION:
        raise _not_a_model(path, f"unsupported format version {header.get('format_version')}")
    versions = header.get("versions")
    metadata = header.get("metadata")
    if not isinstance(versions, dict) or not isinstance(metadata, dict):
        raise _not_a_model(path, "header without versions or metadata")

    current = _current_versions()
    mismatched = [
        package
        for package in ("prsm_health", "scikit-learn")
        if _major_minor(versions.get(package, "")) is None
        or _major_minor(versions[package]) != _major_minor(current[package])
    ]
    if mismatched:
        saved = " and ".join(f"{p} {versions.get(p, '(unknown)')}" for p in mismatched)
        running = " and ".join(f"{p} {current[p]}" for p in mismatched)
        message = (
            f"{path}: model saved with {saved}, running {running}; retrain it or pass "
            "allow_version_mismatch=True"
        )
        if not allow_version_mismatch:
            raise ModelVersionError(message)
        warnings.warn(message, UserWarning, stacklevel=2)

    try:
        untrusted, refused = _refused_types(data)
    except Exception as err:  # a corrupt skops schema can fail in many ways
        raise _not_a_model(path, f"corrupt model payload: {err}") from err
    if refused:
        raise PRSMHealthError(f"{path}: refusing to load untrusted types: {', '.join(refused)}")
    try:
        model = sio.loads(data, trusted=untrusted)
    except Exception as err:  # corrupt arrays or schema: any exception means "unreadable"
        raise _not_a_model(path, f"corrupt model payload: {type(err).__name__}: {err}") from err
    return model, {**metadata, "versions": versions, "saved_at": header.get("saved_at")}
