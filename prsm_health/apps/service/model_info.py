"""``GET /v1/model``: what the loaded model bundle is, and a summary of its training metrics."""

from __future__ import annotations

import json
from pathlib import Path

from prsm_health.core.jsonable import json_ready


def model_info(bundle, model_file: Path | None) -> dict:
    """The JSON answer of ``GET /v1/model`` for ``bundle`` (loaded from ``model_file``, when
    known: its metrics may lie beside it)."""
    return json_ready(
        {
            "name": bundle.name,
            "version": bundle.version,
            "window": bundle.window,
            "design": bundle.design_name,
            "sample_rate": bundle.metadata.get("sample_rate"),
            "feature_names": list(bundle.feature_names),
            "classes": [str(c) for c in getattr(bundle.fault, "classes_", [])],
            "clearance_range": bundle.metadata.get("clearance_range"),
            "saved_at": bundle.metadata.get("saved_at"),
            "versions": bundle.metadata.get("versions", {}),
            "metrics": metrics_summary(model_file, bundle.metadata),
        }
    )


def metrics_summary(model_path: Path | None, metadata: dict) -> dict | None:
    """Training metrics: from the bundle metadata, else the ``<stem>.metrics.json`` that
    :func:`prsm_health.training.train.train` writes beside the model."""
    metrics = metadata.get("metrics")
    if metrics is None and model_path is not None:
        side = model_path.with_name(model_path.stem + ".metrics.json")
        if side.is_file():
            try:
                metrics = json.loads(side.read_text())
            except (OSError, ValueError):
                metrics = None
    if not isinstance(metrics, dict):
        return None
    keep = {
        "clearance_cv": (
            "mae",
            "rmse",
            "interval_coverage",
            "nominal_coverage",
            "mean_interval_width",
            "n_samples",
            "n_splits",
        ),
        "clearance_test": ("n", "mae", "rmse", "interval_coverage", "mean_interval_width"),
        "fault_cv": (
            "accuracy",
            "macro_f1_classifier",
            "log_loss",
            "n_samples",
            "n_splits",
            "classes",
        ),
        "fault_test": ("n", "accuracy", "macro_f1_classifier", "classes"),
        "off_grid": (
            "n",
            "clearance_mae",
            "interval_coverage",
            "mean_interval_width",
            "fault_macro_f1",
        ),
        "runs": None,
        "recipe": None,
    }
    out = {}
    for key, fields in keep.items():
        if key not in metrics:
            continue
        value = metrics[key]
        if fields is not None and isinstance(value, dict):
            value = {k: value[k] for k in fields if k in value}
        out[key] = value
    return json_ready(out) or None
