"""Train the diagnosis model bundle from a generated dataset (``prsm-health train``).

Indicators of every run (:func:`prsm_health.features.dataset_features`) → the clearance
estimator (target: the thread clearance, mean of screw and nut sides [m]) and the fault
classifier (the dataset's taxonomy) on the ``train`` split; cross-validated metrics grouped by
operating point (repeats of a point never straddle folds), held-out metrics on the ``test``
split, and group permutation importance of the indicator families. The bundle and a metrics
JSON are written side by side.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .errors import PRSMHealthError, require
from .features import FEATURES, GROUPS, dataset_features
from .jsonable import dumps

TARGETS = ("clearance", "fault", "both")
#: Indicator whose absence means the window has no load/motion reversal, i.e. the clearance is
#: not observable (docs/validation.md: steady preload keeps every roller on one flank).
OBSERVABILITY_FEATURE = "lost_motion"


def clearance_target(table) -> np.ndarray:
    """Thread clearance [m]: mean of the screw- and nut-side half-clearances."""
    return 0.5 * (table["clearance_screw"].to_numpy(float) + table["clearance_nut"].to_numpy(float))


def operating_point(table) -> np.ndarray:
    """Group id of runs that share every swept value (repeats differ only by seed)."""
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
    keys = [k for k in keys if k in table]
    return table[keys].astype(str).agg("|".join, axis=1).to_numpy()


def _interval_metrics(estimator, x, y) -> dict:
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
    from sklearn.metrics import accuracy_score, confusion_matrix, f1_score

    pred = classifier.predict(x)
    labels = list(classifier.classes_)
    return {
        "n": int(len(y)),
        "macro_f1": float(f1_score(y, pred, average="macro")),
        "accuracy": float(accuracy_score(y, pred)),
        "classes": [str(c) for c in labels],
        "confusion_matrix": confusion_matrix(y, pred, labels=labels).tolist(),
    }


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
        Model file (``.skops``); metrics go to ``<out stem>.metrics.json`` beside it.
    target : {"clearance", "fault", "both"}
    name : str or None
        Model name (default: "<recipe>-model").
    cv : int
        Cross-validation folds on the train split.
    """
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
    from .dataset import Dataset
    from .estimators import ClearanceEstimator, FaultClassifier
    from .evaluation import cross_validated_metrics, permutation_importance_table
    from .persistence import save_model

    require(target in TARGETS, "target", target, f"must be one of {', '.join(TARGETS)}")
    out = Path(out)
    if not out.parent.exists():
        raise PRSMHealthError(f"{out}: directory {out.parent} does not exist")
    ds = Dataset(dataset_dir)
    table = dataset_features(ds, progress=progress)
    features = list(FEATURES)
    train_rows = table[table["split"] == "train"]
    test_rows = table[table["split"] == "test"]
    if len(train_rows) < 10:
        raise PRSMHealthError(
            f"{dataset_dir}: only {len(train_rows)} training runs; need at least 10"
        )
    x_train, x_test = train_rows[features], test_rows[features]
    groups = operating_point(train_rows)
    metrics: dict = {
        "dataset": str(dataset_dir),
        "recipe": ds.manifest["name"],
        "runs": {"train": len(train_rows), "test": len(test_rows)},
    }
    bundle: dict = {"feature_names": features, "clearance": None, "fault": None}

    if target in ("clearance", "both"):
        y = clearance_target(train_rows)

        def make():
            # A few hundred runs: small leaves. Quantiles of the out-of-fold residual, because
            # the clearance is nearly a deterministic function of lost motion (estimators.py).
            return ClearanceEstimator(
                alpha=0.1,
                lower_limit=0.0,
                min_samples_leaf=10,
                max_iter=200,
                learning_rate=0.05,
                quantiles_of="residual",
                random_state=random_state,
            )

        metrics["clearance_cv"] = cross_validated_metrics(make, x_train, y, groups=groups, cv=cv)
        estimator = make().fit(x_train, y)
        bundle["clearance"] = estimator
        if len(test_rows):
            y_test = clearance_target(test_rows)
            metrics["clearance_test"] = _interval_metrics(estimator, x_test, y_test)
            importance = permutation_importance_table(
                estimator, x_test, y_test, n_repeats=5, random_state=random_state, groups=GROUPS
            )
            metrics["clearance_importance"] = _importance_records(importance)
        metrics["clearance_range"] = [float(y.min()), float(y.max())]

    if target in ("fault", "both"):
        labels = train_rows["fault_class"].astype(str).to_numpy()

        def make_classifier():
            # 3 calibration folds × 100 iterations keep the shipped bundle under 5 MB
            return FaultClassifier(
                min_samples_leaf=5,
                max_iter=100,
                learning_rate=0.1,
                calibration_cv=3,
                random_state=random_state,
            )

        metrics["fault_cv"] = cross_validated_metrics(
            make_classifier, x_train, labels, groups=groups, cv=cv
        )
        classifier = make_classifier().fit(x_train, labels)
        bundle["fault"] = classifier
        if len(test_rows):
            y_test = test_rows["fault_class"].astype(str).to_numpy()
            metrics["fault_test"] = _class_metrics(classifier, x_test, y_test)
            importance = permutation_importance_table(
                classifier, x_test, y_test, n_repeats=5, random_state=random_state, groups=GROUPS
            )
            metrics["fault_importance"] = _importance_records(importance)

    metadata = {
        "name": name or f"{ds.manifest['name']}-model",
        "model_version": "1",
        "design": ds.manifest["recipe"]["design"],
        "window": float(ds.manifest["duration"]),
        "sample_rate": float(ds.manifest["sample_rate"]),
        "trained_on": {
            "dataset": str(dataset_dir),
            "recipe": ds.manifest["recipe"],
            "runs": metrics["runs"],
        },
        "clearance_range": metrics.get("clearance_range"),
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


def _importance_records(frame) -> list[dict]:
    return json.loads(frame.to_json(orient="records"))
