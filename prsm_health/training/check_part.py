"""``prsm-health train`` on a dataset of health checks: the check part of a model bundle for the
dataset's design (:func:`~.check_training.train_check_model`), saved beside a window model or
as a bundle of its own (docs/diagnostics.md, "A health check for your own actuator").

A check part reads each check against its unit's own baseline, so it is trained from two
datasets of one ``[units]`` family: the checks (units in the states to tell apart) and the same
units' healthy checks (``--baseline``). Without a window model the bundle holds the check part
only: it reads health-check recordings and refuses others
(:attr:`~prsm_health.diagnostics.diagnosis.ModelBundle.check_only`).
"""

from __future__ import annotations

import math
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps

from .check_training import CHECK_CV, add_check_model, train_check_model
from .train import MODEL_SUFFIX, _collect_warnings, _instrumentation_name

#: Where the docs say how to record and train a check part.
CHECK_DOCS = 'docs/diagnostics.md, "A health check for your own actuator"'


def is_check_dataset(dataset) -> bool:
    """Whether a dataset's runs are health-check recordings: the generator stores each check
    run's phases in its ``check_phases`` label (docs/formats.md, runs table)."""
    phases = dataset.runs.get("check_phases")
    return phases is not None and bool(phases.notna().any())


def train_check_part(
    dataset_dir,
    baseline_dir,
    out,
    *,
    window_model=None,
    cv: int = CHECK_CV,
    name: str | None = None,
    random_state: int = 0,
    progress: bool = True,
) -> dict:
    """Train the check part on a dataset of health checks and save a bundle that has it.

    Parameters
    ----------
    dataset_dir : path
        Health checks of units (a recipe with ``[units]`` and ``[profile] check``) in the
        states the part is to tell apart.
    baseline_dir : path or None
        The same units' checks when new and healthy (the same ``[units]``); None is refused
        with a sentence naming ``--baseline``: the part reads a check against its unit's
        baseline and learns the indicators' repeatability from these.
    out : path
        The bundle (``.skops``); the check part goes beside it (``<stem>.check.skops``), the
        metrics to ``<stem>.check.metrics.json``.
    window_model : path or None
        A window model of the same design: ``out`` is then a copy of it (or itself) with the
        check part beside it. None: ``out`` holds the check part only.
    cv : int
        Cross-validation folds by unit.

    Returns
    -------
    dict
        ``model`` (path, check part path, kind, design), ``metrics_path``, ``check`` (the
        training metrics of :func:`train_check_model`) and ``warnings``.
    """
    from prsm_health.actuator.design_files import design_fingerprint
    from prsm_health.core.atomic import write_atomic
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.diagnosis import load_bundle
    from prsm_health.diagnostics.model_files import save_model

    out = Path(out)
    if out.suffix != MODEL_SUFFIX:
        raise PRSMHealthError(f"{out}: a model file must end in {MODEL_SUFFIX}")
    if not out.parent.exists():
        raise PRSMHealthError(f"{out}: directory {out.parent} does not exist")
    if baseline_dir is None:
        raise PRSMHealthError(
            f"{dataset_dir}: a dataset of health checks trains a model's check part, which reads "
            "each check against its unit's healthy checks: give --baseline DATASET, the same "
            f"units' checks when new and healthy ({CHECK_DOCS})"
        )
    ds, base = Dataset(dataset_dir), Dataset(baseline_dir)
    if not is_check_dataset(base):
        raise PRSMHealthError(f"--baseline {baseline_dir}: its runs are no health checks")

    def fingerprint_of(d):
        return None if d.design is None else design_fingerprint(d.design)

    fingerprint = fingerprint_of(ds)
    if fingerprint_of(base) != fingerprint:
        raise PRSMHealthError(
            f"--baseline {baseline_dir}: of another design than {dataset_dir}: record the "
            "same units' baselines"
        )
    window = None if window_model is None else load_bundle(window_model)
    if window is not None and window.design_fingerprint != fingerprint:
        raise PRSMHealthError(
            f"--window-model {window_model}: trained on design {window.design_name!r}, the "
            f"checks are of another design: train a window model for it, or leave it out"
        )
    notes = _unit_problems(ds, base, cv)
    with _collect_warnings("check part", notes):  # tiny data: sentences, not tracebacks
        part, metrics = train_check_model(
            ds.path, base.path, cv=cv, random_state=random_state, progress=progress
        )
    if window is None:
        recipe = ds.manifest["recipe"]
        metadata = {
            "name": name or f"{ds.manifest['name']}-model",
            "model_version": "1",
            "design": recipe["design"],
            "sample_rate": float(ds.manifest["sample_rate"]),
            "channels": list(ds.channels),
            "instrumentation": _instrumentation_name(recipe),
            "trained_on": {"dataset": str(dataset_dir), "baseline": str(baseline_dir)},
            "target": "check",
        }
        # no window estimators: load_bundle reads it, diagnose reads checks only
        empty = {"feature_names": [], "clearance": None, "fault": None, "guard": None}
        save_model(out, empty, metadata=metadata)
    elif Path(window_model).resolve() != out.resolve():
        write_atomic(out, Path(window_model).read_bytes(), "model file")
    check_path = add_check_model(out, part)
    result = {
        "dataset": str(dataset_dir),
        "baseline": str(baseline_dir),
        "model": {
            "path": str(out),
            "check_part": str(check_path),
            "kind": "check part only" if window is None else f"window model {window_model}",
            "design": ds.design.name if ds.design is not None else None,
        },
        "check": metrics,
        "warnings": notes,
    }
    metrics_path = out.with_name(f"{out.stem}.check.metrics.json")
    metrics_path.write_text(dumps(result, indent=2))
    result["metrics_path"] = str(metrics_path)
    return result


def _unit_problems(ds, base, cv: int) -> list[str]:
    """Refuse (one line) what cannot train — runs without units, too few training units for
    ``cv`` folds, one class — before any indicator is computed; warn of units without a
    baseline."""
    runs = ds.runs
    for d in (ds, base):
        if "unit_id" not in d.runs:
            raise PRSMHealthError(
                f"{d.path}: runs without unit_id: the check part reads each unit against its "
                f"own baseline, so record units — a recipe with [units] ({CHECK_DOCS})"
            )
    train = runs[runs["split"] == "train"]
    n_units = train["unit_id"].nunique()
    # each fold's fit calibrates the clearance interval on units apart from those it fits on
    if n_units < cv or n_units - math.ceil(n_units / cv) < 2:
        fewest = next(n for n in range(cv, 10 * cv) if n - math.ceil(n / cv) >= 2)
        raise PRSMHealthError(
            f"{ds.path}: cannot train the check part: {n_units} training units, {cv}-fold "
            f"cross-validation by unit needs ≥ {fewest} (each fold fits on two units or more): "
            "add units ([units] count) or change --cv"
        )
    classes = train["fault_class"].astype(str).unique()
    if len(classes) < 2:
        raise PRSMHealthError(
            f"{ds.path}: cannot train the check part: every training check is {classes[0]!r}; "
            "a classifier needs ≥ 2 classes: add fault cases ([fault_cases], sweep.fault_case)"
        )
    missing = sorted(set(runs["unit_id"]) - set(base.runs["unit_id"]))
    if not missing:
        return []
    return [
        f"{len(missing)} unit(s) of {ds.path} have no checks in the baseline dataset "
        f"(unit_id {', '.join(map(str, missing[:5]))}{' …' if len(missing) > 5 else ''}): "
        "their checks are not read against a baseline in training"
    ]
