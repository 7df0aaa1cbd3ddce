"""Train the diagnosis model bundle from a generated dataset (``prsm-health train``).

Indicators of every run (:func:`prsm_health.signals.features.dataset_features`) → the clearance
estimator (target: the thread clearance, mean of screw and nut sides [m]) and the fault
classifier (the dataset's taxonomy) on the ``train`` split; cross-validated metrics grouped by
operating point (repeats of a point never straddle folds), held-out metrics on the ``test``
split, and group permutation importance of the indicator families. The bundle and a metrics
JSON are written side by side.

A dataset too small to train on is refused before any fitting, with sentences from
:func:`training_problems` that state each minimum and how to reach it. A model that trains but
is no better than a constant answer is reported in ``metrics["warnings"]``.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError, require
from prsm_health.core.jsonable import dumps
from prsm_health.signals.features import FEATURES, GROUPS, dataset_features
from prsm_health.signals.indicator_table import NOT_INDICATORS

from .fault_candidates import BY_NAME, choose, cross_validate_candidates, make_classifier

#: The operating indicators the out-of-distribution guard interpolates between (continuous
#: factors a dataset may sweep on a grid; ``reversal`` is a yes/no, not a level).
GUARD_FACTORS = tuple(n for n in GROUPS["operating"] if n != "reversal")

TARGETS = ("clearance", "fault", "both")
MODEL_SUFFIX = ".skops"
#: Indicator whose absence means the window has no load/motion reversal, i.e. the clearance is
#: not observable (docs/validation.md: steady preload keeps every roller on one flank).
OBSERVABILITY_FEATURE = "lost_motion"
#: Operating indicators whose training range a model records (diagnosis warns outside it).
REGIME_FEATURES = ("speed_mean", "load_mean", "load_range", "drive_torque_mean")

#: Clearance estimator settings. A few hundred runs: small leaves. Quantiles of the out-of-fold
#: residual, because the clearance is nearly a deterministic function of lost motion
#: (prsm_health/diagnostics/estimators.py, ``quantiles_of``).
CLEARANCE_PARAMS = dict(
    alpha=0.1,
    calibration_fraction=0.25,
    lower_limit=0.0,
    min_samples_leaf=10,
    max_iter=200,
    learning_rate=0.05,
    quantiles_of="residual",
)
#: Fault classifier settings: 3 calibration folds × 40 iterations (at a higher rate) keep the
#: shipped bundle under 5 MB with the ~60 indicators of flight-ema (100 iterations: 7 MB).
FAULT_PARAMS = dict(min_samples_leaf=5, max_iter=40, learning_rate=0.15, calibration_cv=3)


def clearance_target(table) -> np.ndarray:
    """Thread clearance [m]: mean of the screw- and nut-side half-clearances (NaN where a run
    has no clearance label)."""
    import pandas as pd

    def side(name):  # an empty label column is object-typed (None): read it as NaN
        return pd.to_numeric(table[name], errors="coerce").to_numpy(float)

    return 0.5 * (side("clearance_screw") + side("clearance_nut"))


def operating_point(table) -> np.ndarray:
    """Group id of runs that share every swept value (repeats differ only by seed).

    A runs table with none of the swept columns filled in (a rig's recordings labelled with
    faults only) makes each run its own group: recordings are independent."""
    keys = [
        "clearance_screw",
        "clearance_nut",
        "clearance_gear",
        "screw_speed",
        "axial_load",
        "friction_scale",
        "wear_spread",
        "load_amplitude",
    ]
    keys = [k for k in keys if k in table and table[k].notna().any()]
    if not keys:
        return np.arange(len(table)).astype(str)
    # element-wise str: a missing label (None/NaN) becomes its text rather than staying missing
    return table[keys].map(str).agg("|".join, axis=1).to_numpy()


# --------------------------------------------------------------------------------------------
# Is the dataset large enough?
# --------------------------------------------------------------------------------------------


def _n_calibration(n: int, fraction: float) -> int:
    """Calibration runs the clearance estimator holds out of ``n`` (ClearanceEstimator.fit)."""
    return min(max(int(round(fraction * n)), 1), n - 1)


def calibration_minimums(alpha: float, calibration_fraction: float) -> tuple[int, int]:
    """Fewest training runs for a usable and for a guaranteed conformal clearance interval.

    The clearance estimator calibrates on ``round(calibration_fraction · n)`` held-out runs.
    Its finite-sample quantile, the ``ceil((n_cal + 1)(1 - alpha))``-th score, exists when
    ``n_cal ≥ 1/alpha - 1`` (coverage ≥ ``1 - alpha`` guaranteed). Below that it falls back to
    the largest score, whose coverage is only ≥ ``n_cal / (n_cal + 1)``; requiring that to
    reach ``1 - 2 alpha`` (80 % for a 90 % interval) gives ``n_cal ≥ 1/(2 alpha) - 1``.

    Returns
    -------
    usable, guaranteed : int
        Training runs for ``n_cal ≥ 1/(2 alpha) - 1`` and for ``n_cal ≥ 1/alpha - 1``.
    """

    def fewest(needed: int) -> int:
        n = 2
        while _n_calibration(n, calibration_fraction) < needed:
            n += 1
        return n

    usable = fewest(max(math.ceil(1 / (2 * alpha) - 1 - 1e-9), 1))
    return usable, fewest(math.ceil(1 / alpha - 1 - 1e-9))


def training_problems(labels, *, target: str = "both", cv: int = 5) -> list[str]:
    """Why a dataset cannot train a model with ``prsm-health train``, as plain sentences.

    Only the labels are read (no signals, no fitting), so this is cheap enough to call right
    after generating a dataset, e.g. to warn that it is too small.

    Parameters
    ----------
    labels : pandas.DataFrame
        The dataset's runs table (``Dataset(path).runs``, i.e. ``runs.parquet``): one row per
        run with at least ``split`` ("train"/"test") and the labels of ``target``:
        ``fault_class`` (fault), ``clearance_screw`` and ``clearance_nut`` [m] (clearance); the
        other swept columns (``screw_speed``, ``axial_load``, ``friction_scale`` …) define the
        operating points that cross-validation groups by (none: each run is its own).
    target : {"clearance", "fault", "both"}, default "both"
        What will be trained.
    cv : int, default 5
        Cross-validation folds (``--cv``).

    Returns
    -------
    list of str
        One sentence per problem, each naming the minimum and the fix, e.g. ``"fault target:
        class 'lubrication' has 2 training runs, 5-fold CV needs ≥ 5 per class: add runs
        (sweep.repeats) or lower --cv to 2"``. Empty when training can proceed. ``train``
        joins them with "; " into one error message.

    Raises
    ------
    ParameterError
        An unknown ``target``.
    """
    require(target in TARGETS, "target", target, f"must be one of {', '.join(TARGETS)}")
    if "split" not in labels:
        return [
            "the runs table has no split column, so it is not from prsm-health generate or "
            "import: regenerate or re-import the dataset"
        ]
    # each target needs its own labels only: a rig labelled with faults alone trains --target fault
    if target in ("fault", "both") and "fault_class" not in labels:
        return [
            f"--target {target} needs fault labels, and the runs table has no fault_class "
            "column: add a fault_class column to the labels table, or use --target clearance"
        ]
    if target in ("clearance", "both"):
        absent = [c for c in ("clearance_screw", "clearance_nut") if c not in labels]
        labelled = (
            np.isfinite(clearance_target(labels)) if not absent else np.zeros(len(labels), bool)
        )
        if not labelled.any():
            where = (
                f"no {', '.join(absent)} column(s)"
                if absent
                else "empty clearance_screw, clearance_nut columns"
            )
            return [
                f"--target {target} needs clearance labels, and this dataset has none ({where}):"
                " use --target fault, or give each recording a clearance [m] in the labels table"
            ]
        if not labelled.all():
            return [
                f"--target {target} needs a clearance label for every run, and "
                f"{int((~labelled).sum())} of {len(labels)} runs have none: label them, or use "
                "--target fault"
            ]
    problems = []
    if not (isinstance(cv, (int, np.integer)) and not isinstance(cv, bool) and cv >= 2):
        problems.append(
            f"--cv {cv}: cross-validation needs an integer ≥ 2 folds: use --cv 2 or more"
        )
        cv = 2  # judge the rest as if the smallest valid value had been given
    train = labels[labels["split"] == "train"]
    n_train, n_test = len(train), int((labels["split"] == "test").sum())
    if n_train == 0:
        return problems + [
            f"the dataset has no training runs (split 'train', {len(labels)} runs in all): "
            "set test_fraction < 1 and add runs"
        ]
    if n_test == 0:
        problems.append(
            "the dataset has no held-out runs (split 'test' is empty), so the model cannot be "
            "evaluated: set test_fraction > 0 in the recipe (e.g. 0.2)"
        )
    n_points = len(set(operating_point(train)))
    if n_points < cv:
        problems.append(
            f"the train split has {n_points} distinct operating point(s), {cv}-fold CV keeps "
            f"the repeats of a point in one fold and needs ≥ {cv}: add sweep values"
            + (f" or lower --cv to {n_points}" if n_points >= 2 else "")
        )

    if target in ("clearance", "both"):
        usable, guaranteed = calibration_minimums(
            CLEARANCE_PARAMS["alpha"], CLEARANCE_PARAMS["calibration_fraction"]
        )
        if n_train < usable:
            coverage = round(100 * (1 - CLEARANCE_PARAMS["alpha"]))
            problems.append(
                f"clearance target: {n_train} training runs, a calibrated {coverage} % interval "
                f"needs ≥ {usable} (≥ {guaranteed} for its coverage guarantee): add runs "
                "(sweep.repeats or more sweep values)"
            )
        clearances = np.unique(clearance_target(train))
        if len(clearances) < 2:
            problems.append(
                f"clearance target: every training run has the same clearance "
                f"({1e6 * clearances[0]:.3g} µm), there is nothing to learn: sweep clearance "
                "over ≥ 2 values"
            )

    if target in ("fault", "both"):
        counts = train["fault_class"].astype(str).value_counts().sort_index()
        if len(counts) < 2:
            problems.append(
                f"fault target: every training run has class {counts.index[0]!r}, a classifier "
                "needs ≥ 2 classes: widen the sweep (clearance, friction_scale) across the fault "
                "thresholds or use --target clearance"
            )
        else:
            short = [(str(cls), int(n)) for cls, n in counts.items() if n < cv]
            fewest = int(counts.min())
            fix = "add runs (sweep.repeats)" + (
                f" or lower --cv to {fewest}" if fewest >= 2 else ""
            )
            if len(short) == 1:
                ((cls, n),) = short
                problems.append(
                    f"fault target: class {cls!r} has {n} training run{'' if n == 1 else 's'}, "
                    f"{cv}-fold CV needs ≥ {cv} per class: {fix}"
                )
            elif short:
                listed = ", ".join(f"{cls!r} ({n})" for cls, n in short)
                problems.append(
                    f"fault target: classes {listed} have too few training runs, {cv}-fold CV "
                    f"needs ≥ {cv} per class: {fix}"
                )
    return problems


def fit_minimum(labels, *, cv: int, target: str = "both") -> int:
    """Training runs an indicator must be finite in for every fit of ``train`` to see a value of
    it (an indicator finite in none is left out; in fewer than this, one fit may get none).

    The smallest fit is a CV fold's training part, ``m = n - ceil(n / cv)`` of the ``n``
    training runs, less what an estimator holds out inside it: the fault classifier one of its
    ``FAULT_PARAMS["calibration_cv"]`` calibration folds (fewer folds when a class has fewer
    runs), the clearance estimator its calibration runs and one of the 5 folds of its residual
    model (:class:`~prsm_health.diagnostics.estimators.ClearanceEstimator`). An indicator
    finite in ``n - smallest + 1`` runs keeps one in every fit, wherever the folds fall.

    Parameters
    ----------
    labels : pandas.DataFrame
        The runs table (``split``; ``fault_class`` for the fault target).
    cv : int
        Cross-validation folds.
    target : {"clearance", "fault", "both"}
    """
    train = labels[labels["split"] == "train"]
    n = len(train)
    outer = n - math.ceil(n / cv)
    fits = [outer]
    if target in ("fault", "both") and "fault_class" in train and n:
        fewest = int(train["fault_class"].astype(str).value_counts().min())
        # FaultClassifier.fit: min(calibration_cv, the fewest runs of a class) folds
        folds = min(FAULT_PARAMS["calibration_cv"], max(2, fewest - math.ceil(fewest / cv)))
        fits.append(outer - math.ceil(outer / folds))
    if target in ("clearance", "both") and outer >= 2:
        fit = outer - _n_calibration(outer, CLEARANCE_PARAMS["calibration_fraction"])
        folds = min(5, fit)  # ClearanceEstimator.fit: its residual model's out-of-fold folds
        fits.append(fit - math.ceil(fit / folds) if folds >= 2 else fit)
    return n - max(min(fits), 0) + 1


# --------------------------------------------------------------------------------------------
# Metrics and their warnings
# --------------------------------------------------------------------------------------------


def _interval_metrics(estimator, x, y) -> dict:
    """Held-out clearance metrics; None (not 0) for every metric when there are no runs."""
    if len(y) == 0:
        keys = ("mae", "rmse", "interval_coverage", "mean_interval_width")
        return {"n": 0, **dict.fromkeys(keys)}
    pred = estimator.predict(x)
    lo, hi = estimator.predict_interval(x)
    return {
        "n": int(len(y)),
        "mae": float(np.mean(np.abs(pred - y))),
        "rmse": float(np.sqrt(np.mean((pred - y) ** 2))),
        "interval_coverage": float(np.mean((y >= lo) & (y <= hi))),
        "mean_interval_width": float(np.mean(hi - lo)),
    }


def _class_metrics(classifier, x, y) -> dict:
    """Held-out fault metrics of the classifier alone; None (not 0) for every metric when there
    are no runs.

    ``macro_f1_classifier``: the classifier's answer for every run — no observability gates, no
    OOD score, never ``cannot_tell`` — so it is not the ``macro_f1_all`` (``cannot_tell``
    counted as a miss) nor the ``macro_f1_named`` (runs given a class) of ``prsm-health
    evaluate``, which go through the diagnosis (:func:`~.evaluation.fault_report`)."""
    from sklearn.metrics import accuracy_score, confusion_matrix, f1_score

    labels = list(classifier.classes_)
    if len(y) == 0:
        return {
            "n": 0,
            "macro_f1_classifier": None,
            "accuracy": None,
            "classes": [str(c) for c in labels],
            "confusion_matrix": None,
        }
    pred = classifier.predict(x)
    return {
        "n": int(len(y)),
        "macro_f1_classifier": float(f1_score(y, pred, average="macro", zero_division=0)),
        "accuracy": float(accuracy_score(y, pred)),
        "classes": [str(c) for c in labels],
        "confusion_matrix": confusion_matrix(y, pred, labels=labels).tolist(),
    }


def _classifier_alone(cv_metrics: dict) -> dict:
    """Cross-validated fault metrics with their macro-F1 named as the classifier's alone
    (``macro_f1_classifier``, as :func:`_class_metrics`), in the folds too."""
    for part in (cv_metrics, *cv_metrics.get("folds", ())):
        if "macro_f1" in part:
            part["macro_f1_classifier"] = part.pop("macro_f1")
    return cv_metrics


def _best_constant_f1(y_true, candidates) -> tuple[float, str]:
    """Macro-F1 of the best constant answer: what a classifier that learned nothing scores."""
    from sklearn.metrics import f1_score

    y_true = np.asarray(y_true).astype(str)
    best = (-1.0, "")
    for cls in sorted({str(c) for c in candidates}):
        score = float(f1_score(y_true, np.full(len(y_true), cls), average="macro", zero_division=0))
        best = max(best, (score, cls), key=lambda t: t[0])
    return best


def constant_baseline_mae(y_true, y_train) -> tuple[float | None, str]:
    """MAE of the better constant answer (training mean or median) on ``y_true`` [m].

    What an estimator that learned nothing scores; None when ``y_true`` is empty.
    """
    y_true, y_train = np.asarray(y_true, float), np.asarray(y_train, float)
    if len(y_true) == 0 or len(y_train) == 0:
        return None, ""
    candidates = {"mean": float(np.mean(y_train)), "median": float(np.median(y_train))}
    maes = {k: float(np.mean(np.abs(y_true - v))) for k, v in candidates.items()}
    best = min(maes, key=maes.get)
    return maes[best], best


def clearance_warnings(where: str, mae, y_true, y_train) -> list[str]:
    """Sentences for clearance metrics that say nothing or show a useless estimator.

    ``where`` names the evaluated runs ("held-out", "cross-validated"); ``mae`` [m] is the
    estimator's on ``y_true``, None when there are none.
    """
    if len(y_true) == 0 or mae is None:
        return [f"{where} split has 0 runs: no {where} clearance metrics"]
    baseline, constant = constant_baseline_mae(y_true, y_train)
    if mae >= baseline * (1 - 1e-9):
        return [
            f"clearance MAE {1e6 * mae:.3g} µm on {where} runs is no better than always "
            f"answering the training {constant} ({1e6 * baseline:.3g} µm): the estimator has "
            "learned nothing useful"
        ]
    return []


def fault_warnings(where: str, macro_f1, y_true, train_classes) -> list[str]:
    """Sentences for fault metrics that say nothing or show a chance-level classifier."""
    if len(y_true) == 0 or macro_f1 is None:
        return [f"{where} split has 0 runs: no {where} fault metrics"]
    out = []
    unseen = sorted({str(c) for c in y_true} - {str(c) for c in train_classes})
    if unseen:
        out.append(
            f"{where} class(es) {', '.join(map(repr, unseen))} have no training runs: the "
            "classifier cannot predict them"
        )
    baseline, constant = _best_constant_f1(y_true, train_classes)
    if macro_f1 <= baseline + 1e-12:
        out.append(
            f"fault macro-F1 {macro_f1:.2f} on {where} runs is no better than always answering "
            f"{constant!r} ({baseline:.2f}): the classifier is no better than chance"
        )
    return out


# Warnings scikit-learn and the estimators raise on tiny data; during training they become
# sentences in metrics["warnings"] instead of leaking to the terminal.
_EXPECTED = re.compile(
    r"least populated class|calibration samples are too few|single sample|not calibrated"
    r"|ill-defined|no predicted samples|only one label|y_pred values do not sum|n_splits"
)


@contextlib.contextmanager
def _collect_warnings(stage: str, sentences: list[str]):
    """Turn the expected small-data warnings of one training stage into sentences."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    seen = {re.sub(r"\d+", "#", s) for s in sentences}
    for w in caught:
        message = " ".join(str(w.message).split())
        if _EXPECTED.search(message):
            sentence = f"{stage}: {message}"
            # once per stage: the folds of one CV repeat the same warning with other counts
            if re.sub(r"\d+", "#", sentence) not in seen:
                seen.add(re.sub(r"\d+", "#", sentence))
                sentences.append(sentence)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


# --------------------------------------------------------------------------------------------
# Training
# --------------------------------------------------------------------------------------------


def train(
    dataset_dir: str | Path,
    out: str | Path,
    *,
    target: str = "both",
    name: str | None = None,
    cv: int = 5,
    progress: bool = True,
    random_state: int = 0,
) -> dict:
    """Train, evaluate and save a model bundle; returns the metrics (also written as JSON).

    Parameters
    ----------
    dataset_dir : path
        A dataset from ``prsm-health generate``.
    out : path
        Model file, must end in ``.skops``; metrics go to ``<out stem>.metrics.json`` beside it.
    target : {"clearance", "fault", "both"}
    name : str or None
        Model name (default: "<recipe>-model").
    cv : int
        Cross-validation folds on the train split.

    Returns
    -------
    dict
        The metrics: ``runs``, ``clearance_cv`` / ``clearance_test`` / ``fault_cv`` /
        ``fault_test`` (per target), importances, ``model``, ``metrics_path`` and
        ``warnings``: sentences on what the metrics do not show (e.g. a held-out split of 0
        runs, whose metrics are None, never 0) or a model no better than a constant answer.
        The fault macro-F1 is ``macro_f1_classifier``: the classifier alone, which names a
        class for every run (no gates, never ``cannot_tell``); ``prsm-health evaluate`` reports
        ``macro_f1_all`` and ``macro_f1_named`` through the diagnosis instead.

    Raises
    ------
    PRSMHealthError
        ``out`` without the ``.skops`` suffix or in a missing directory; an unreadable
        dataset; a dataset too small to train on or without the target's labels (the
        sentences of :func:`training_problems`, on one line). All raised before any fitting.
    SparseFeatureError
        An indicator finite in so few training runs that a fit got none of its values (one
        line naming it and :func:`fit_minimum`).
    """
    out = Path(out)
    if out.suffix != MODEL_SUFFIX:
        raise PRSMHealthError(
            f"{out}: a model file must end in {MODEL_SUFFIX} (it is a skops archive), "
            f"e.g. {out.with_suffix(MODEL_SUFFIX)}"
        )
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="openmp"):
        return _train(
            dataset_dir,
            out,
            target=target,
            name=name,
            cv=cv,
            progress=progress,
            random_state=random_state,
        )


def _train(dataset_dir, out, *, target, name, cv, progress, random_state) -> dict:
    # One OpenMP thread: a few hundred samples gain nothing from threads, and spin-waiting
    # threads of two busy processes on 2 cores made training 50× slower (docs/performance.md).
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.estimators import (
        ClearanceEstimator,
        DistributionGuard,
    )
    from prsm_health.diagnostics.model_files import save_model

    from .evaluation import (
        cross_validated_metrics,
        permutation_importance_table,
        sparse_feature_errors,
    )

    require(target in TARGETS, "target", target, f"must be one of {', '.join(TARGETS)}")
    if not out.parent.exists():
        raise PRSMHealthError(f"{out}: directory {out.parent} does not exist")
    ds = Dataset(dataset_dir)
    problems = training_problems(ds.runs, target=target, cv=cv)
    if problems:
        raise PRSMHealthError(f"{dataset_dir}: cannot train: " + "; ".join(problems))
    table = dataset_features(ds, progress=progress)
    # Indicators the dataset's instrumentation cannot give (all NaN: a channel it does not fit,
    # a rate too low for the group) carry no information and are left out of the model;
    # diagnose() needs only the rest. The channel statistics are no indicators: the plain
    # baseline's alone.
    not_indicators = {name for group in NOT_INDICATORS for name in GROUPS[group]}
    finite = [name for name in FEATURES if table[name].notna().any()]
    features = [name for name in finite if name not in not_indicators]
    statistics = [name for name in finite if name in not_indicators]
    absent = [name for name in FEATURES if name not in finite]
    train_rows = table[table["split"] == "train"]
    test_rows = table[table["split"] == "test"]
    # an indicator finite in too few training runs for every fit to see one (envelope lines
    # whose band a run's kurtogram did not reach, …) cannot be cross-validated: left out, said
    fewest = fit_minimum(train_rows, cv=cv, target=target)
    finite_in = {name: int(train_rows[name].notna().sum()) for name in features}
    too_sparse = [name for name in features if 0 < finite_in[name] < fewest]
    features = [name for name in features if name not in too_sparse]
    present_groups = {
        group: kept
        for group, members in GROUPS.items()
        if (kept := [name for name in members if name in features])
    }
    x_train, x_test = train_rows[features], test_rows[features]
    groups = operating_point(train_rows)
    # an indicator finite in a few runs only can be absent from one fit's runs: one line, no
    # traceback, naming it and how many runs it needs
    sparse = functools.partial(
        sparse_feature_errors,
        x_train,
        f"{dataset_dir}: cannot train: --cv {cv}",
        fewest,
        words=("indicator", "training runs"),
    )
    notes: list[str] = []
    if too_sparse:
        shown = ", ".join(f"{name} ({finite_in[name]})" for name in too_sparse[:6])
        more = f" and {len(too_sparse) - 6} more" if len(too_sparse) > 6 else ""
        notes.append(
            f"indicator(s) finite in fewer than the {fewest} of {len(train_rows)} training runs "
            f"every --cv {cv} fit needs were left out: {shown}{more} (finite in that many runs); "
            "more runs, or fewer folds, keep them"
        )
    metrics: dict = {
        "dataset": str(dataset_dir),
        "recipe": ds.manifest["name"],
        "runs": {"train": len(train_rows), "test": len(test_rows)},
        "indicators_absent": absent,
        # finite in too few training runs for every cross-validation fit: left out
        "indicators_too_sparse": too_sparse,
        # what the dataset's channels and rate let each indicator group read
        "indicator_groups": ds.indicator_groups,
    }
    bundle: dict = {"feature_names": features, "clearance": None, "fault": None}
    # How far a window's indicators lie from the training windows (diagnosis: OOD score),
    # interpolated between the levels of the continuous operating factors
    factors = [i for i, name in enumerate(features) if name in GUARD_FACTORS]
    bundle["guard"] = DistributionGuard(factors=factors).fit(x_train)

    if target in ("clearance", "both"):
        y = clearance_target(train_rows)

        def make():
            return ClearanceEstimator(**CLEARANCE_PARAMS, random_state=random_state)

        with _collect_warnings("clearance CV", notes), sparse():
            metrics["clearance_cv"] = cross_validated_metrics(
                make, x_train, y, groups=groups, cv=cv
            )
        with _collect_warnings("clearance model", notes), sparse():
            # reported below, in terms of training runs
            warnings.filterwarnings("ignore", "ClearanceEstimator: .* calibration samples")
            estimator = make().fit(x_train, y)
        bundle["clearance"] = estimator
        if not estimator.coverage_guaranteed_:
            _, guaranteed = calibration_minimums(
                CLEARANCE_PARAMS["alpha"], CLEARANCE_PARAMS["calibration_fraction"]
            )
            notes.append(
                f"clearance model: {len(y)} training runs ({estimator.n_calibration_} calibrate "
                f"the interval) are too few for its coverage guarantee, which needs ≥ "
                f"{guaranteed}: the {round(100 * (1 - CLEARANCE_PARAMS['alpha']))} % interval is "
                "the widest calibration error and may cover less: add runs"
            )
        notes += clearance_warnings("cross-validated", metrics["clearance_cv"]["mae"], y, y)
        y_test = clearance_target(test_rows)
        with _collect_warnings("clearance held-out", notes):
            held_out = _interval_metrics(estimator, x_test, y_test)
            held_out["baseline_mae"] = constant_baseline_mae(y_test, y)[0]
            if len(y_test):
                importance = permutation_importance_table(
                    estimator,
                    x_test,
                    y_test,
                    n_repeats=5,
                    random_state=random_state,
                    groups=present_groups,
                )
                metrics["clearance_importance"] = _importance_records(importance)
        metrics["clearance_test"] = held_out
        notes += clearance_warnings("held-out", held_out["mae"], y_test, y)
        metrics["clearance_range"] = [float(y.min()), float(y.max())]

    if target in ("fault", "both"):
        labels = train_rows["fault_class"].astype(str).to_numpy()
        inputs = {"indicators": x_train, "statistics": train_rows[statistics]}
        with _collect_warnings("fault CV", notes), sparse():
            candidates = cross_validate_candidates(
                inputs, labels, groups, cv, FAULT_PARAMS, random_state
            )
        chosen, said = choose(candidates)
        candidate = BY_NAME[chosen]
        metrics["fault_candidates"] = candidates
        metrics["fault_model"] = {"candidate": chosen, "description": candidate.description}
        metrics["fault_cv"] = _classifier_alone(copy.deepcopy(candidates[chosen]))
        if "plain_baseline" in candidates:  # the same folds, plain statistics
            metrics["fault_plain_baseline_cv"] = candidates["plain_baseline"]
        notes += said
        reads = statistics if candidate.reads == "statistics" else features
        if candidate.reads == "statistics":
            bundle["fault_features"] = statistics
        with _collect_warnings("fault model", notes), sparse():
            classifier = make_classifier(candidate, FAULT_PARAMS, random_state)
            classifier.fit(train_rows[reads], labels)
        bundle["fault"] = classifier
        notes += fault_warnings(
            "cross-validated",
            metrics["fault_cv"]["macro_f1_classifier"],
            labels,
            classifier.classes_,
        )
        y_test = test_rows["fault_class"].astype(str).to_numpy()
        with _collect_warnings("fault held-out", notes):
            metrics["fault_test"] = _class_metrics(classifier, test_rows[reads], y_test)
            if len(y_test):
                importance = permutation_importance_table(
                    classifier,
                    test_rows[reads],
                    y_test,
                    n_repeats=5,
                    random_state=random_state,
                    groups=present_groups if candidate.reads == "indicators" else None,
                )
                metrics["fault_importance"] = _importance_records(importance)
        notes += fault_warnings(
            "held-out", metrics["fault_test"]["macro_f1_classifier"], y_test, classifier.classes_
        )
    metrics["warnings"] = notes

    metadata = {
        "name": name or f"{ds.manifest['name']}-model",
        "model_version": "1",
        "design": ds.manifest["recipe"]["design"],
        # a rig without a PRSM design: the lead its lost motion was read with
        "lead": (ds.manifest["recipe"].get("map") or {}).get("lead"),
        "window": float(ds.manifest["duration"]),
        "sample_rate": float(ds.manifest["sample_rate"]),
        "trained_on": {
            "dataset": str(dataset_dir),
            "recipe": ds.manifest["recipe"],
            "runs": metrics["runs"],
        },
        "clearance_range": metrics.get("clearance_range"),
        # what a recording must have to be diagnosed by this model (diagnosis.check_channels)
        "channels": list(ds.channels),
        "instrumentation": _instrumentation_name(ds.manifest["recipe"]),
        # the operating range of the training windows (diagnosis warns outside it)
        "regime": {
            name: [float(train_rows[name].min()), float(train_rows[name].max())]
            for name in REGIME_FEATURES
            if name in train_rows and train_rows[name].notna().any()
        },
        "observability_feature": OBSERVABILITY_FEATURE,
        "target": target,
    }
    save_model(out, bundle, metadata=metadata)
    metrics["model"] = {
        "path": str(out),
        **{k: metadata[k] for k in ("name", "model_version", "window", "design")},
    }
    metrics_path = out.with_name(out.stem + ".metrics.json")
    metrics_path.write_text(dumps(metrics, indent=2))
    metrics["metrics_path"] = str(metrics_path)
    return metrics


def _instrumentation_name(recipe: dict) -> str | None:
    """The instrumentation profile's name of a dataset's recipe (a name or a complete table)."""
    value = recipe.get("instrumentation")
    return value.get("name") if isinstance(value, dict) else value


def _importance_records(frame) -> list[dict]:
    return json.loads(frame.to_json(orient="records"))
