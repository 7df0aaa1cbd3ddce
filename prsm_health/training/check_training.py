"""Training the check model of a bundle (:class:`~prsm_health.diagnostics.check_model.CheckModel`)
from health-check recordings of units and their baselines.

Two datasets of one recipe family (``datasets/flight-ema-check.toml`` and
``datasets/flight-ema-check-baseline.toml``: the same ``[units]``): check recordings of units
in every health state, and each unit recorded new and healthy. From them:

* the **repeatability** of each check indicator — its within-unit scatter between two check
  recordings of the same healthy unit (the pooled within-group standard deviation), the prior
  scale of a unit's baseline (:meth:`prsm_health.diagnostics.baseline.Baseline.fit`);
* each recording's **change** against its unit's baseline (robust z-scores);
* a clearance estimator and a fault classifier on the indicators alone (one recording), and a
  fault classifier on the indicators and their change (a unit with a baseline) — the package's
  estimators (:mod:`prsm_health.diagnostics.estimators`, conformal intervals and class sets),
  cross-validated by unit (a unit's recordings never straddle folds) and scored on the held-out
  units.

Classes no check shows (``not_observable``: class → measured reason) are left out of the
classifiers' training — a class the classifier cannot learn only blurs the ones it can — and
named in every check diagnosis instead.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError
from prsm_health.diagnostics.check_model import CHANGE_PREFIX, change_row, check_reading

from .train import CLEARANCE_PARAMS, FAULT_PARAMS, clearance_target

#: Cross-validation folds (by unit).
CHECK_CV = 3
#: The check classifiers: the window model's settings, classes weighted to equal total weight.
#: The training checks are mostly faulty (a recipe draws every state) while a fleet is mostly
#: healthy: with equal weights the probabilities are those of a uniform class prior — the
#: training recipes' mix is no one's prior — and each class is learnt with the same care; the
#: evidence accumulation then divides out a uniform prior (the part's ``training_prior``).
#: Trees of 15 leaves, not 31: the check part stays under 5 MB with six change classes (on the
#: fresh units as good within their scatter: one check alone macro-F1 0.943 vs 0.941).
CHECK_FAULT_PARAMS = dict(FAULT_PARAMS, class_weight="balanced", max_leaf_nodes=15)
#: Classes no health check of the flight-ema instrumentation shows, and why (measured:
#: tools/studies/duty_signatures.py and docs/faults.md "At realistic duty").
NOT_OBSERVABLE = {
    "tooth_damage": "a cracked or pitted ring- or roller-gear tooth changes the mesh force by "
    "≤ 1.6 N and the nut acceleration by ≈ 0.0007 m/s² RMS at 20–40 % of C_a, far below the "
    "accelerometer's noise and the healthy units' scatter (docs/faults.md)",
}
#: Classes a check shows against the unit's own baseline only, and why one check alone cannot:
#: left out of the classifier that reads a check alone, learnt by the one that reads its change.
BASELINE_ONLY = {
    "preload_loss": "60 % of a 2–5 µm preload lost widens the slow reversal's lost motion by "
    "≈ 8 µm, against the unit's baseline a change of many times its repeatability, but the "
    "lost motion of units as built spreads over tens of µm (the linkage's and the bearing's "
    "compliance, the play as built): one check alone cannot tell the lost preload from a "
    "unit built so (docs/diagnostics.md)",
}
#: The fault cases of the classes no check shows, left out of both classifiers' training.
UNSEEN_CASES = ("crack_ring_gear", "crack_roller_gear", "tooth_pit")
#: The fault cases of :data:`BASELINE_ONLY`, left out of the alone classifier's training.
BASELINE_ONLY_CASES = ("preload_loss",)


def check_table(dataset, progress: bool = False):
    """The check indicators of every run of a dataset of check recordings, with the run
    labels and its reversals (``reversals``: what the clearance gauge reads), as a DataFrame
    (one row per run)."""
    import pandas as pd

    design = getattr(dataset, "design", None)
    ids = list(dataset.runs["run_id"])
    iterator = ids
    if progress:
        from tqdm import tqdm

        iterator = tqdm(ids, unit="run", desc="check indicators")
    rows = []
    for run_id in iterator:
        run = dataset.run(int(run_id), truth=False)
        if run.check_phase is None:
            raise PRSMHealthError(f"{dataset.path}: run {run_id} is no health-check recording")
        reading = check_reading(run, design)
        row = dict(reading.indicators)
        row.update(run.labels)
        row["reversals"] = reading.reversals
        rows.append(row)
    return pd.DataFrame(rows)


def two_states(table) -> np.ndarray:
    """Recordings in two states at once: a degraded lubricant (the ``lubrication`` class's
    thresholds, :class:`~prsm_health.actuator.faults.FaultThresholds`) under another class
    (a spall, wear, a preload loss take precedence in the run's label).

    The training recipe draws the lubricant independently of the fault case, so a quarter of
    the training checks were such; labelled with the other class, they teach the classifiers that a degraded
    lubricant's signature is evidence of a spall or a preload loss (measured: against the
    baseline, lubrication units then read preload loss 0.2–0.5 at every check). They train the
    clearance estimator, not the classifiers, whose classes are single states."""
    from prsm_health.actuator.faults import FaultThresholds

    def column(name, default):
        if name not in table:
            return np.full(len(table), default)
        return table[name].fillna(default).to_numpy(float)

    degraded = FaultThresholds().lubricant_degraded(
        column("friction_scale", 1.0),
        column("lubricant_degradation", 0.0),
        column("lubricant_starvation", 0.0),
    )
    return degraded & (table["fault_class"].astype(str).to_numpy() != "lubrication")


def repeatability(baseline_table, names: list[str]) -> dict[str, float]:
    """Within-unit scatter of each indicator: the pooled standard deviation of the units'
    baseline recordings around their unit's mean (each unit with ≥ 2 recordings), NaN where no
    unit has two finite values."""
    out = {}
    for name in names:
        squares, dof = 0.0, 0
        for _, group in baseline_table.groupby("unit_id"):
            values = group[name].to_numpy(float)
            values = values[np.isfinite(values)]
            if len(values) >= 2:
                squares += float(np.sum((values - values.mean()) ** 2))
                dof += len(values) - 1
        out[name] = math.sqrt(squares / dof) if dof else math.nan
    return out


def unit_baselines(baseline_table, names: list[str], prior_scale: dict) -> dict:
    """Unit id → its :class:`~prsm_health.diagnostics.baseline.Baseline` (all its baseline
    recordings)."""
    from prsm_health.diagnostics.baseline import Baseline

    out = {}
    for unit, group in baseline_table.groupby("unit_id"):
        rows = group[names].to_dict("records")
        ids = [str(r) for r in group["run_id"]]
        out[int(unit)] = Baseline.fit(rows, prior_scale=prior_scale, names=names, recordings=ids)
    return out


def change_table(table, baselines: dict, names: list[str]):
    """Each recording's indicators and their change against its unit's baseline
    (:func:`~prsm_health.diagnostics.check_model.change_row`)."""
    import pandas as pd

    rows = [
        change_row(row, baselines.get(int(row["unit_id"])), names)
        for row in table.to_dict("records")
    ]
    return pd.DataFrame(rows, index=table.index)


def train_check_model(
    check_dir,
    baseline_dir,
    *,
    not_observable: dict | None = None,
    unseen_cases: tuple[str, ...] = (),
    baseline_only: dict | None = None,
    baseline_only_cases: tuple[str, ...] = (),
    random_state: int = 0,
    cv: int = CHECK_CV,
    progress: bool = False,
) -> tuple[dict, dict]:
    """Train the check part of a model bundle.

    Parameters
    ----------
    check_dir : path or list of paths
        Datasets of check recordings (``[units]`` recipes of the same units; several are
        pooled, e.g. a supplement of a rare class).
    baseline_dir : path
        The same units' baselines.
    not_observable : dict or None
        Class → why no check shows it (measured), named in every check diagnosis.
    unseen_cases : tuple of str
        Fault cases (``fault_case`` label) of those classes, left out of the classifiers'
        training (they are still scored in ``metrics["held_out"]`` for what the model says of them).
    baseline_only : dict or None
        Class → why one check alone cannot show it (measured), though its change against the
        unit's baseline does: named in every check diagnosis read alone.
    baseline_only_cases : tuple of str
        Fault cases of those classes, left out of the alone classifier's training only.
    random_state : int
    cv : int
        Cross-validation folds (by unit: at most the training units).

    Returns
    -------
    (part, metrics)
        ``part``: the bundle's ``check`` dict (:meth:`CheckModel.from_part`); ``metrics``: the
        cross-validated and held-out numbers.
    """
    from threadpoolctl import threadpool_limits

    # one OpenMP thread per booster, as train_model: small models, and spin-waiting threads
    # on busy cores made a 2 s fit take minutes
    with threadpool_limits(limits=1, user_api="openmp"):
        return _train_check_model(
            check_dir,
            baseline_dir,
            not_observable=not_observable,
            unseen_cases=unseen_cases,
            baseline_only=baseline_only,
            baseline_only_cases=baseline_only_cases,
            random_state=random_state,
            cv=cv,
            progress=progress,
        )


def _train_check_model(
    check_dir,
    baseline_dir,
    *,
    not_observable,
    unseen_cases,
    baseline_only,
    baseline_only_cases,
    random_state,
    cv,
    progress,
) -> tuple[dict, dict]:
    import pandas as pd

    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.clearance_gauge import gauge_for
    from prsm_health.diagnostics.estimators import ClearanceEstimator, FaultClassifier

    from .evaluation import cross_validated_metrics
    from .gauge_calibration import calibrate_gauge

    dirs = [check_dir] if isinstance(check_dir, (str, Path)) else list(check_dir)
    checks, base = [Dataset(d) for d in dirs], Dataset(baseline_dir)
    for ds in (*checks, base):
        if "unit_id" not in ds.runs:
            raise PRSMHealthError(f"{ds.path}: runs without unit_id: a recipe with [units]")
    table = pd.concat([check_table(ds, progress) for ds in checks], ignore_index=True)
    base_table = check_table(base, progress)
    from prsm_health.signals.check_indicators import CHECK_INDICATORS

    # an indicator this instrumentation cannot give (all NaN: no load cell) carries nothing
    names = [n for n in CHECK_INDICATORS if n in table and table[n].notna().any()]
    healthy_base = base_table[base_table["split"] == "train"]
    scatter = repeatability(healthy_base, names)
    baselines = unit_baselines(base_table, names, scatter)
    changes = change_table(table, baselines, names)
    relative_names = [*names, *(CHANGE_PREFIX + n for n in names)]

    train = table["split"] == "train"
    seen = ~table["fault_case"].isin(list(unseen_cases))
    single = ~two_states(table)
    fit_rows = train & seen & single  # the change classifier's rows
    alone_rows = train & seen & ~table["fault_case"].isin(list(baseline_only_cases))
    units = table.loc[fit_rows, "unit_id"].to_numpy()
    y_class = table.loc[fit_rows, "fault_class"].astype(str).to_numpy()
    alone_units = table.loc[alone_rows, "unit_id"].to_numpy()
    y_alone = table.loc[alone_rows, "fault_class"].astype(str).to_numpy()
    y_clearance = clearance_target(table.loc[train])
    classes, counts = np.unique(y_class, return_counts=True)
    metrics: dict = {
        "runs": {"train": int(train.sum()), "test": int((~train).sum())},
        "two_states_left_out": int((train & ~single).sum()),
        "class_counts": {str(c): int(k) for c, k in zip(classes, counts)},
        "baseline_runs": len(base_table),
        "indicators": names,
        "unseen_cases": list(unseen_cases),
        "not_observable": dict(not_observable or {}),
        "baseline_only": dict(baseline_only or {}),
    }

    def clearance_model():
        return ClearanceEstimator(**CLEARANCE_PARAMS, random_state=random_state)

    def classifier():
        return FaultClassifier(**CHECK_FAULT_PARAMS, random_state=random_state)

    x_train = table.loc[train, names]
    metrics["clearance_cv"] = cross_validated_metrics(
        clearance_model, x_train, y_clearance, groups=table.loc[train, "unit_id"], cv=cv
    )
    clearance = clearance_model().fit(x_train, y_clearance, groups=table.loc[train, "unit_id"])
    metrics["fault_cv"] = cross_validated_metrics(
        classifier, table.loc[alone_rows, names], y_alone, groups=alone_units, cv=cv
    )
    fault = classifier().fit(table.loc[alone_rows, names], y_alone, groups=alone_units)
    metrics["fault_relative_cv"] = cross_validated_metrics(
        classifier, changes.loc[fit_rows, relative_names], y_class, groups=units, cv=cv
    )
    fault_relative = classifier().fit(changes.loc[fit_rows, relative_names], y_class, groups=units)
    part = {
        "feature_names": names,
        "clearance": clearance,
        "fault": fault,
        "fault_relative": fault_relative,
        "repeatability": scatter,
        # balanced class weights: the change classifier's prior is uniform, whatever the counts
        "training_prior": {str(c): 1.0 / len(classes) for c in classes},
        "not_observable": dict(not_observable or {}),
        "baseline_only": dict(baseline_only or {}),
        "clearance_range": [float(np.min(y_clearance)), float(np.max(y_clearance))],
    }
    metrics["held_out"] = _held_out(part, table[~train], changes[~train], names, relative_names)
    gauge = gauge_for(checks[0].design, {"trained_on": {"recipe": checks[0].manifest["recipe"]}})
    if gauge is not None:
        part["gauge"], metrics["gauge"] = calibrate_gauge(gauge, table, base_table)
    return part, metrics


def _held_out(part, table, changes, names, relative_names) -> dict:
    """The held-out units' recordings: clearance MAE and coverage, class F1 alone and against
    the baseline (every fault case, unseen ones included, with its true class)."""
    from sklearn.metrics import f1_score

    if table.empty:
        return {}
    y = clearance_target(table)
    est = part["clearance"].predict(table[names])
    lo, hi = part["clearance"].predict_interval(table[names])
    truth = table["fault_class"].astype(str).to_numpy()
    out = {
        "n": len(table),
        "clearance_mae": float(np.mean(np.abs(est - y))),
        "clearance_coverage": float(np.mean((y >= lo) & (y <= hi))),
    }
    for key, model, x in (
        ("alone", part["fault"], table[names]),
        ("against_baseline", part["fault_relative"], changes[relative_names]),
    ):
        predicted = np.asarray(model.predict(x)).astype(str)
        labels = sorted(set(truth) & set(model.classes_))
        out[f"macro_f1_{key}"] = float(
            f1_score(truth, predicted, labels=labels, average="macro", zero_division=0)
        )
    return out


def add_check_model(model_path, part: dict) -> Path:
    """Save the check part of the bundle ``model_path`` beside it
    (:func:`~prsm_health.diagnostics.diagnosis.check_part_path`, written atomically), where
    :func:`~prsm_health.diagnostics.diagnosis.load_bundle` finds it; returns its path."""
    from prsm_health.diagnostics.diagnosis import check_part_path
    from prsm_health.diagnostics.model_files import load_model, save_model

    model, _ = load_model(model_path)
    if not isinstance(model, dict) or "feature_names" not in model:
        raise PRSMHealthError(f"{model_path}: not a prsm_health diagnosis bundle")
    return save_model(check_part_path(model_path), part, metadata={"part": "check"})
