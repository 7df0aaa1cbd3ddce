"""Evaluation of trained estimators: permutation importance and cross-validated metrics.

- :func:`permutation_importance_table`: per-feature and per-group permutation importance.
- :func:`cross_validated_metrics`: out-of-fold metrics stored beside a trained model.

Both work with any scikit-learn estimator; interval regressors (an estimator with
``predict_interval`` and ``alpha``, e.g. :class:`prsm_health.estimators.ClearanceEstimator`)
also get interval coverage and width.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd
from sklearn.base import BaseEstimator, clone, is_classifier
from sklearn.inspection import permutation_importance
from sklearn.metrics import (
    accuracy_score,
    check_scoring,
    f1_score,
    log_loss,
    mean_absolute_error,
    mean_squared_error,
)
from sklearn.model_selection import GroupKFold, KFold, StratifiedGroupKFold, StratifiedKFold
from sklearn.utils import check_random_state

from .errors import require

__all__ = ["cross_validated_metrics", "permutation_importance_table"]


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
