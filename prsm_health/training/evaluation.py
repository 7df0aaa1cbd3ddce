"""Evaluation of trained estimators: permutation importance and cross-validated metrics.

- :func:`permutation_importance_table`: per-feature and per-group permutation importance.
- :func:`cross_validated_metrics`: out-of-fold metrics stored beside a trained model.

Both work with any scikit-learn estimator; interval regressors (an estimator with
``predict_interval`` and ``alpha``, e.g. :class:`prsm_health.diagnostics.estimators.ClearanceEstimator`)
also get interval coverage and width.
"""

from __future__ import annotations

import contextlib
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

from prsm_health.core.errors import PRSMHealthError, require
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.monitoring.asset import OBSERVABLE_SHARE

__all__ = [
    "SparseFeatureError",
    "clearance_report",
    "cross_validated_metrics",
    "evaluate_model",
    "fault_report",
    "permutation_importance_table",
    "sensitivity_table",
    "sparse_feature_errors",
]


# --------------------------------------------------------------------------------------------
# Feature importance
# --------------------------------------------------------------------------------------------


def _takes_groups(estimator, groups) -> bool:
    import inspect

    return groups is not None and "groups" in inspect.signature(estimator.fit).parameters


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


#: What scikit-learn's histogram binning (HistGradientBoosting*, 1.9) raises when one fit gets a
#: column without a single finite value — a fold of sparse data. The only error translated.
_NO_FINITE_VALUE = "window shape cannot be larger than input array shape"


class SparseFeatureError(PRSMHealthError):
    """A model fit got a feature without a finite value: the data are too sparse for the folds."""


def _sparse_feature_message(X, context: str, minimum: int | None, words: tuple) -> str:
    """One line naming the sparsest features of ``X`` (finite in some rows, not all) and what
    a fit needs; ``minimum`` is the finite rows a feature needs for every fit to see one."""
    feature, rows = words
    frame = X if isinstance(X, pd.DataFrame) else pd.DataFrame(np.asarray(X, float))
    n = len(frame)
    counts = np.isfinite(frame.to_numpy(float)).sum(axis=0)
    partial = sorted((int(c), str(name)) for name, c in zip(frame.columns, counts) if 0 < c < n)
    named = ", ".join(f"{name} finite in {c} of {n} {rows}" for c, name in partial[:3])
    need = (
        f"needs each {feature} finite in ≥ {minimum} of the {n} {rows} (or in none)"
        if minimum is not None
        else f"needs a finite value of each {feature} in every fit"
    )
    return (
        f"{context} {need}, and a fit got none of a sparse one"
        + (f" ({named})" if named else "")
        + f": add {rows} where these are measured, leave out the {rows} that lack them, or use "
        "fewer folds"
    )


@contextlib.contextmanager
def sparse_feature_errors(
    X, context: str, minimum: int | None = None, *, words: tuple = ("feature", "rows")
):
    """Turn a fit's failure on a feature without a finite value (sparse data split into folds)
    into a one-line :class:`SparseFeatureError` naming the sparsest features of ``X``.

    Parameters
    ----------
    X : DataFrame or array of shape (n_samples, n_features)
        The rows the fits draw their folds from.
    context : str
        The start of the message (e.g. ``"--cv 3"``).
    minimum : int, optional
        Finite rows a feature needs for every fit to be sure to see one.
    words : (str, str)
        What a feature and the rows are called in the message (``("indicator", "training
        runs")``).
    """
    try:
        yield
    except SparseFeatureError:  # an inner guard's: this one knows the wider context
        raise SparseFeatureError(_sparse_feature_message(X, context, minimum, words)) from None
    except ValueError as exc:
        if _NO_FINITE_VALUE not in str(exc):
            raise
        raise SparseFeatureError(_sparse_feature_message(X, context, minimum, words)) from None


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

    Raises
    ------
    SparseFeatureError
        A fold's training part has no finite value of a feature (data too sparse for ``cv``).
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
        with sparse_feature_errors(X, f"{len(splits)}-fold cross-validation"):
            est = make()
            # an estimator that calibrates by group (FaultClassifier) keeps the folds' groups
            fit_groups = {"groups": np.asarray(groups)[train]} if _takes_groups(est, groups) else {}
            est = est.fit(_take(X, train), y[train], **fit_groups)
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
# A trained model on a dataset, through the diagnosis (gates, OOD, cannot_tell)
# --------------------------------------------------------------------------------------------


def evaluate_model(
    bundle, dataset, *, split: str = "test", progress: bool = False, batch: int = 32
) -> tuple:
    """Diagnose every run of a dataset split as ``diagnose`` diagnoses a recording, and score
    it against its labels.

    Each run goes through :func:`prsm_health.diagnostics.diagnosis.diagnose_runs` — the one
    diagnosis path of ``diagnose``, the service and replay: cut into the model's windows (a
    health check read phase by phase), observability gates, the OOD score, ``cannot_tell``,
    the windows combined. Clearance metrics are computed over all runs and over those whose
    clearance the diagnosis called observable. Fault metrics are ``macro_f1_all`` (every run;
    ``cannot_tell`` counted as a miss) and ``macro_f1_named`` (only the runs the diagnosis named
    a class for). Neither is the ``macro_f1_classifier`` of ``prsm-health train`` — the
    classifier alone on every window, no gates, never ``cannot_tell`` — so on one split the
    three differ.

    Parameters
    ----------
    bundle : ModelBundle
    dataset : Dataset (generated or imported)
    split : {"test", "train", "all"}
    batch : int
        Runs diagnosed per call.

    Returns
    -------
    (report, records)
        ``report``: JSON-serialisable metrics; ``records``: one row per run (its labels, the
        estimate, bounds, class, top probability, observability, OOD score, windows) for plots
        and sensitivity tables.
    """
    from prsm_health.diagnostics.diagnosis import diagnose_runs

    require(split in ("test", "train", "all"), "split", split, "must be test, train or all")
    runs = dataset.runs if split == "all" else dataset.runs[dataset.runs["split"] == split]
    require(len(runs) > 0, "split", split, f"has no runs in {dataset.path}")
    # a model of another design reads these indicators wrongly: refused before any work
    identity = [c for c in ("design", "design_fingerprint") if c in runs]
    for labels in runs[identity].drop_duplicates().to_dict("records") if identity else []:
        reason = bundle.refuses(OperatingPoint.from_labels(labels))
        if reason is not None:
            raise PRSMHealthError(f"{dataset.path}: {reason}")
    ids = [int(i) for i in runs["run_id"]]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(ids), unit="run", desc="diagnosing")
    results = []
    for start in range(0, len(ids), batch):
        chunk = [dataset.run(i, truth=False) for i in ids[start : start + batch]]
        results.extend(diagnose_runs(chunk, bundle))
        if bar is not None:
            bar.update(len(chunk))
    if bar is not None:
        bar.close()
    records = runs.reset_index(drop=True).copy()
    records["estimate"] = [_num(r.clearance["estimate"]) for r in results]
    records["lower"] = [_num(r.clearance["lower"]) for r in results]
    records["upper"] = [_num(r.clearance["upper"]) for r in results]
    records["predicted_class"] = [r.fault_class for r in results]
    records["class_set"] = [list(r.class_set) for r in results]
    records["top_probability"] = [
        max(r.class_probabilities.values()) if r.class_probabilities else np.nan for r in results
    ]
    # a recording's observability is the share of its windows that saw the target: observable
    # when most did, the rule the asset's evidence reads it by
    for target in ("clearance", "fault"):
        records[f"{target}_observable"] = [
            float(r.observability[target]) >= OBSERVABLE_SHARE for r in results
        ]
    records["ood_score"] = [_num(r.ood_score) for r in results]
    records["windows"] = [max(len(r.windows), 1) for r in results]
    report = {
        "dataset": str(dataset.path),
        "model": bundle.reference(),
        "split": split,
        "runs": len(records),
        "ood": {
            "median_score": _num(np.nanmedian(records["ood_score"])),
            "flagged_fraction": float(np.mean(records["ood_score"] > _ood_limit())),
        },
    }
    if bundle.clearance is not None and {"clearance_screw", "clearance_nut"} <= set(records):
        records["clearance"] = 0.5 * (records["clearance_screw"] + records["clearance_nut"])
        report["clearance"] = clearance_report(records)
    if bundle.fault is not None and "fault_class" in records:
        report["fault"] = fault_report(records)
    return report, records


def _num(value) -> float:
    return float("nan") if value is None else float(value)


def _ood_limit() -> float:
    from prsm_health.diagnostics.diagnosis import OOD_LIMIT

    return OOD_LIMIT


def clearance_report(records: pd.DataFrame) -> dict:
    """MAE, bias, interval coverage and width [m] over all rows and the observable ones."""

    def stats(part: pd.DataFrame) -> dict:
        if part.empty:
            return {"n": 0, "mae": None, "bias": None, "coverage": None, "mean_width": None}
        y, est = part["clearance"].to_numpy(float), part["estimate"].to_numpy(float)
        lo, hi = part["lower"].to_numpy(float), part["upper"].to_numpy(float)
        return {
            "n": len(part),
            "mae": float(np.mean(np.abs(est - y))),
            "bias": float(np.mean(est - y)),
            "coverage": float(np.mean((y >= lo) & (y <= hi))),
            "mean_width": float(np.mean(hi - lo)),
        }

    observable = records[records["clearance_observable"]]
    return {
        **stats(records),
        "observable_fraction": float(records["clearance_observable"].mean()),
        "observable": stats(observable),
    }


def fault_report(records: pd.DataFrame) -> dict:
    """Fault metrics of diagnosed runs: ``macro_f1_all`` (every run, ``cannot_tell`` counted as
    a miss), ``macro_f1_named`` (the runs the diagnosis named a class for; None when none),
    per-class F1 (``cannot_tell`` a miss), the confusion matrix (rows: true, columns:
    predicted incl. ``cannot_tell``), the share of confident wrong answers (a class named,
    wrong, top probability > 0.6), and the class sets: how often they hold the true class,
    their mean size, and per true class the share of runs whose set holds each class."""
    from sklearn.metrics import confusion_matrix

    from prsm_health.diagnostics.diagnosis import CANNOT_TELL

    y = records["fault_class"].astype(str).to_numpy()
    pred = records["predicted_class"].astype(str).to_numpy()
    classes = sorted(set(y))
    columns = classes + sorted(set(pred) - set(classes))
    told = pred != CANNOT_TELL
    sets = list(records["class_set"]) if "class_set" in records else [[p] for p in pred]
    held = np.array([truth in s for truth, s in zip(y, sets)])
    per_class = f1_score(y, pred, labels=classes, average=None, zero_division=0)
    return {
        "n": len(y),
        "macro_f1_all": float(f1_score(y, pred, labels=classes, average="macro", zero_division=0)),
        "macro_f1_named": (
            float(f1_score(y[told], pred[told], labels=classes, average="macro", zero_division=0))
            if told.any()
            else None
        ),
        "accuracy": float(np.mean(y == pred)),
        "cannot_tell_fraction": float(np.mean(~told)),
        # a class named (not cannot_tell), wrong, with a top probability over 0.6
        "confident_wrong_fraction": float(
            np.mean(told & (pred != y) & (records["top_probability"].to_numpy(float) > 0.6))
        ),
        "set_coverage": float(np.mean(held)),
        "mean_set_size": float(np.mean([len(s) for s in sets])),
        "set_membership": {
            c: {
                k: float(np.mean([k in s for s, t in zip(sets, y) if t == c]))
                for k in sorted({k for s in sets for k in s})
            }
            for c in classes
        },
        "f1_by_class": {c: float(f) for c, f in zip(classes, per_class)},
        "confusion": {
            "true": classes,
            "predicted": columns,
            "matrix": confusion_matrix(y, pred, labels=columns)[: len(classes)].tolist(),
        },
    }


def sensitivity_table(records: pd.DataFrame, columns: list[str], bins: int = 3) -> list[dict]:
    """Clearance bias, MAE and coverage by thirds (``bins``) of each varied column's range:
    how the estimate shifts across a chain element's documented range."""
    out = []
    for name in columns:
        if name not in records or records[name].nunique() < bins:
            continue
        edges = np.linspace(records[name].min(), records[name].max(), bins + 1)
        which = np.clip(np.digitize(records[name], edges[1:-1]), 0, bins - 1)
        for b in range(bins):
            part = records[which == b]
            stats = clearance_report(part) if len(part) else {}
            out.append(
                {
                    "parameter": name,
                    "low": float(edges[b]),
                    "high": float(edges[b + 1]),
                    "n": len(part),
                    "bias": stats.get("bias"),
                    "mae": stats.get("mae"),
                    "coverage": stats.get("coverage"),
                }
            )
    return out
