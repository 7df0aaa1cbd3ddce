"""The shipped default diagnosis model's recipe and its honesty checks (``models/default.skops``).

How the shipped model is built and judged, as functions a user can call to rebuild and check it
for their own actuator (another recipe file, another instrumentation):

1. :func:`default_recipe` — the domain-randomised reference recipe
   (``datasets/flight-ema-reference.toml``), or another one measured by another profile;
2. :func:`train_default_model` — generates it (resumable), trains the clearance estimator and
   the fault classifier (:func:`prsm_health.training.train.train`, 3-fold CV), evaluates
   them (:func:`evaluate_default_model`), measures what each indicator group adds
   (:func:`ablation`) and writes the metrics and the model card
   (:func:`~prsm_health.release.diagnosis_card.write_model_card`);
3. :func:`evaluate_default_model` — the model through the diagnosis (gates, OOD score,
   ``cannot_tell``) on an off-grid set (:func:`off_grid_recipe`: a fresh Latin hypercube over
   the same ranges, run seeds never used in training), a sensitivity table over every varied
   chain element, each class at its default severity (:func:`default_severity`) and the
   :func:`honesty_checks`: recordings of another design, another instrumentation, with no
   load reversal, or from the accelerometer alone, which the model must not answer confidently.

A model that learns nothing useful is reported as such by ``train`` (its ``warnings``); the
card prints the measured numbers whatever they are. Figures of the off-grid set are drawn by
the caller (``prsm_health.apps.plots.plot_evaluation``, a layer above this one) from the
records :func:`train_default_model` returns. ``tools/release/train_default_model.py`` is the
command line of this module.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError
from prsm_health.datasets import Dataset, Recipe, generate, load_recipe
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL, OOD_LIMIT, diagnose, load_bundle
from prsm_health.release.diagnosis_card import write_model_card
from prsm_health.training.evaluation import (
    clearance_report,
    evaluate_model,
    fault_report,
    sensitivity_table,
)
from prsm_health.training.train import CLEARANCE_PARAMS, FAULT_PARAMS, clearance_target, train

#: The reference recipe of the shipped model (repository layout, like :data:`DEFAULT_MODEL`).
REFERENCE_RECIPE = DEFAULT_MODEL.parents[1] / "datasets" / "flight-ema-reference.toml"
#: The instrumentation the shipped model was trained for.
SHIPPED_INSTRUMENTATION = "flight-ema"
#: Name recorded in the shipped model file.
SHIPPED_NAME = "prsm-default-flight-ema"
#: Cross-validation folds of the shipped model's training.
CV_FOLDS = 3

#: Each class of the taxonomy at its default severity, on an otherwise healthy unit (clearance
#: below the wear threshold, lubricant fine) unless the class is about clearance or lubricant.
DEFAULT_SEVERITY = {
    "healthy": {},
    "wear": {"clearance": [17e-6, 28e-6]},
    "severe_wear": {"clearance": [32e-6, 40e-6]},
    "lubrication": {"lubricant_degradation": [0.6, 1.0]},
    "spall": {"fault_case": ["spall_screw", "spall_nut", "spall_roller"]},
    "tooth_damage": {"fault_case": ["crack_ring_gear", "crack_roller_gear", "tooth_pit"]},
    "preload_loss": {"fault_case": ["preload_loss"], "preload": [3e-6, 5e-6]},
}

#: Recordings the model must not answer confidently, as changes to a reference point: its
#: recipe source (design, instrumentation, load profile) or the channels kept.
HONESTY_CASES = {
    "another design (paper02)": {"design": "paper02"},
    "another instrumentation (lab-rig)": {"instrumentation": "lab-rig"},
    "steady load (no reversal)": {"profile": {"load_profile": "constant"}},
    "accelerometer only": {"channels": ("nut_axial_accel",)},
}

#: A named class with a top probability above this, and wrong, is a *confident wrong* answer.
CONFIDENT = 0.6


# --------------------------------------------------------------------------------------------
# Recipes
# --------------------------------------------------------------------------------------------


def default_recipe(
    path: str | Path = REFERENCE_RECIPE, *, instrumentation: str | None = None
) -> Recipe:
    """The reference recipe of the default model, optionally measured by another profile.

    Parameters
    ----------
    path : path
        Recipe TOML (default: ``datasets/flight-ema-reference.toml``, the shipped model's).
    instrumentation : str or None
        Another instrumentation profile (e.g. ``"lab-rig"``): the recipe is renamed
        ``<name>-<profile>`` and its sensor sweeps (``instrumentation.*``, which name the
        original profile's sensors) are dropped, so the profile keeps its own figures.

    Returns
    -------
    Recipe

    Raises
    ------
    PRSMHealthError
        An unreadable or invalid recipe.
    """
    reference = load_recipe(path)
    if instrumentation is None or instrumentation == reference.instrumentation:
        return reference
    return recipe_for_instrumentation(reference, instrumentation)


def off_grid_recipe(reference: Recipe, samples: int = 300) -> Recipe:
    """The reference ranges, a fresh hypercube of ``samples`` runs and fresh run seeds (recipe
    seed + 1), all in one split."""
    source = dict(reference.source)
    source.update(
        name=f"{reference.name}-off-grid",
        seed=reference.seed + 1,
        test_fraction=0.0,
        sweep=dict(reference.sweep, samples=samples),
    )
    return Recipe.from_dict(source)


def default_severity_recipes(reference: Recipe, per_class: int = 30) -> dict[str, Recipe]:
    """One recipe per class of :data:`DEFAULT_SEVERITY`: the reference's ranges, the class's
    faults at severity 1, fresh seeds (recipe seed + 2 + class index)."""
    out = {}
    for k, (cls, change) in enumerate(DEFAULT_SEVERITY.items()):
        sweep = dict(
            reference.sweep,
            samples=per_class,
            severity=[1.0, 1.0],
            clearance=[0.0, 12e-6],
            lubricant_degradation=[0.0, 0.4],
            fault_case=["none"],
        )
        sweep.update(change)
        source = dict(
            reference.source,
            name=f"{reference.name}-{cls}",
            seed=reference.seed + 2 + k,
            test_fraction=0.0,
            sweep=sweep,
        )
        out[cls] = Recipe.from_dict(source)
    return out


def point_recipe(reference: Recipe, point: dict, **changes) -> Recipe:
    """A recipe of one run: ``point`` (a run's swept values, ``RunSpec.point``) on the
    reference's source with ``changes`` (e.g. ``design="paper02"``, ``seed=…``, ``profile=…``)."""
    sweep = {"mode": "grid", **{key: [value] for key, value in point.items()}}
    return Recipe.from_dict(
        dict(reference.source, **changes, name="check", test_fraction=0.0, sweep=sweep)
    )


# --------------------------------------------------------------------------------------------
# Evaluation through the diagnosis
# --------------------------------------------------------------------------------------------


def default_severity(
    bundle, reference: Recipe, work: str | Path, *, per_class: int = 30, workers: int | None = None
) -> dict:
    """Each class at its default severity (:func:`default_severity_recipes`, generated into
    ``work``) through the diagnosis, pooled.

    Returns
    -------
    dict
        ``per_class``, ``fault`` (:func:`~prsm_health.training.evaluation.fault_report`) and
        ``clearance`` (:func:`~prsm_health.training.evaluation.clearance_report`).
    """
    import pandas as pd

    work = Path(work)
    parts = []
    for recipe in default_severity_recipes(reference, per_class).values():
        generate(recipe, work / recipe.name, workers=workers)
        parts.append(evaluate_model(bundle, Dataset(work / recipe.name), split="all")[1])
    pooled = pd.concat(parts, ignore_index=True)
    return {
        "per_class": per_class,
        "fault": fault_report(pooled),
        "clearance": clearance_report(pooled),
    }


def honesty_checks(bundle, reference: Recipe, *, n: int = 6) -> dict:
    """Recordings the model must not answer confidently (:data:`HONESTY_CASES`): another
    design (its recordings stripped of the design they say, which the model would refuse),
    another instrumentation, no load reversal, the accelerometer alone.

    Each case simulates the first ``n`` test-split points of ``reference`` (points the model
    was not trained on) with new seeds (recipe seed + 1000 + k) and diagnoses them.

    Parameters
    ----------
    bundle : ModelBundle
    reference : Recipe
        The model's training recipe.
    n : int
        Recordings per case.

    Returns
    -------
    dict
        Per case: ``n``, ``ood_flagged`` (OOD score above ``OOD_LIMIT``), ``cannot_tell``,
        ``confident_wrong`` (a class named, wrong, top probability > :data:`CONFIDENT`),
        ``warned`` and ``median_ood_score``.
    """
    specs = [s for s in reference.runs() if s.split == "test"][:n]
    out = {}
    for label, change in HONESTY_CASES.items():
        rows = []
        for k, spec in enumerate(specs):
            source_changes = {key: v for key, v in change.items() if key != "channels"}
            if "profile" in source_changes:
                source_changes["profile"] = dict(
                    reference.source["profile"], **source_changes["profile"]
                )
            one = point_recipe(
                reference, spec.point, seed=reference.seed + 1000 + k, **source_changes
            ).runs()[0]
            run = one.scenario().simulate()
            if "channels" in change:
                run.channels = {c: run.channels[c] for c in change["channels"]}
            if "design" in change:
                # A recording that says its design is refused (ModelBundle.refuses); what is
                # checked here is one that does not say it — a rig's file of unknown origin.
                run.operating = replace(run.operating, design=None, design_fingerprint=None)
            d = diagnose(run, bundle)
            top = max(d.class_probabilities.values())
            true_class = one.labels()["fault_class"]
            rows.append(
                {
                    "fault_class": d.fault_class,
                    "true_class": true_class,
                    "top_probability": top,
                    "ood_score": d.ood_score,
                    "warned": bool(d.warnings),
                    "confident_wrong": d.fault_class != "cannot_tell"
                    and d.fault_class != true_class
                    and top > CONFIDENT,
                }
            )
        out[label] = {
            "n": len(rows),
            "ood_flagged": sum((r["ood_score"] or 0) > OOD_LIMIT for r in rows),
            "cannot_tell": sum(r["fault_class"] == "cannot_tell" for r in rows),
            "confident_wrong": sum(r["confident_wrong"] for r in rows),
            "warned": sum(r["warned"] for r in rows),
            "median_ood_score": float(np.median([r["ood_score"] or np.nan for r in rows])),
        }
    return out


def ablation(dataset_dir: str | Path, features: list[str]) -> list[dict]:
    """Held-out metrics with each indicator group left out (both models retrained), and with
    all: what each group adds that the others do not.

    Returns
    -------
    list of dict
        Per feature set: ``features`` (label), ``n_features``, clearance ``mae`` [m],
        ``coverage`` and ``width`` [m] of the interval, fault ``macro_f1`` (argmax).
    """
    from sklearn.metrics import f1_score

    from prsm_health.diagnostics.estimators import ClearanceEstimator, FaultClassifier
    from prsm_health.signals.features import GROUPS, dataset_features

    table = dataset_features(Dataset(dataset_dir))
    train_rows, test_rows = table[table["split"] == "train"], table[table["split"] == "test"]
    y_train, y_test = clearance_target(train_rows), clearance_target(test_rows)
    subsets = {"all indicators": features}
    for group, members in GROUPS.items():
        kept = [c for c in features if c not in members]
        if len(kept) < len(features):
            subsets[f"without {group}"] = kept
    rows = []
    for label, cols in subsets.items():
        model = ClearanceEstimator(**CLEARANCE_PARAMS).fit(train_rows[cols], y_train)
        pred = model.predict(test_rows[cols])
        lo, hi = model.predict_interval(test_rows[cols])
        classifier = FaultClassifier(**FAULT_PARAMS).fit(
            train_rows[cols], train_rows["fault_class"].astype(str)
        )
        predicted = classifier.predict(test_rows[cols])
        rows.append(
            {
                "features": label,
                "n_features": len(cols),
                "mae": float(np.mean(np.abs(pred - y_test))),
                "coverage": float(np.mean((y_test >= lo) & (y_test <= hi))),
                "width": float(np.mean(hi - lo)),
                "macro_f1": float(
                    f1_score(test_rows["fault_class"].astype(str), predicted, average="macro")
                ),
            }
        )
    return rows


def evaluate_default_model(
    bundle,
    reference: Recipe,
    work: str | Path,
    *,
    off_grid: int = 300,
    per_class: int = 30,
    honesty_n: int = 6,
    workers: int | None = None,
    progress: bool = True,
) -> tuple[dict, object]:
    """The model through the diagnosis: off-grid set, sensitivity table, each class at default
    severity, honesty checks. Datasets are generated (resumably) into ``work``.

    Returns
    -------
    metrics : dict
        ``off_grid`` (:func:`~prsm_health.training.evaluation.evaluate_model`'s report),
        ``sensitivity``, ``default_severity`` and ``honesty``.
    records : pandas.DataFrame
        The off-grid set's per-run records (for ``plot_evaluation``).
    """
    work = Path(work)
    out = {}
    off = off_grid_recipe(reference, off_grid)
    generate(off, work / off.name, workers=workers)
    report, records = evaluate_model(
        bundle, Dataset(work / off.name), split="all", progress=progress
    )
    out["off_grid"] = report
    varied = [k for k in off.sweep if k not in ("mode", "samples", "repeats", "fault_case")]
    label_of = {"clearance": "clearance", "speed": "screw_speed", "load": "axial_load"}
    out["sensitivity"] = sensitivity_table(records, [label_of.get(k, k) for k in varied])
    out["default_severity"] = default_severity(
        bundle, reference, work, per_class=per_class, workers=workers
    )
    out["honesty"] = honesty_checks(bundle, reference, n=honesty_n)
    return out, records


# --------------------------------------------------------------------------------------------
# Training
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DefaultModelResult:
    """What :func:`train_default_model` wrote, and the off-grid records for the figures."""

    metrics: dict
    model_path: Path
    metrics_path: Path
    card_path: Path
    off_grid_records: object


def train_default_model(
    out_dir: str | Path,
    reference: Recipe | None = None,
    *,
    work: str | Path,
    workers: int | None = None,
    off_grid: int = 300,
    per_class: int = 30,
    honesty_n: int = 6,
    evaluate_only: bool = False,
    name: str = SHIPPED_NAME,
) -> DefaultModelResult:
    """Build the default model from its recipe, evaluate it and write its card.

    Writes ``out_dir/default.skops``, ``out_dir/default.metrics.json`` (training metrics,
    :func:`evaluate_default_model`'s, :func:`ablation`, feature names, channels, sample rate)
    and ``out_dir/MODEL_CARD.md`` (:func:`~prsm_health.release.diagnosis_card.model_card`).

    Parameters
    ----------
    out_dir : path
        Where the model, its metrics and its card go (the shipped ones: ``models/``).
    reference : Recipe or None
        The training recipe (default: :func:`default_recipe`).
    work : path
        Where the datasets are generated (resumable: an existing complete dataset is kept).
    workers : int or None
        Generation processes.
    off_grid, per_class, honesty_n : int
        Runs of the off-grid set, per class at default severity, per honesty case.
    evaluate_only : bool
        Re-score the model already in ``out_dir`` (its training metrics kept, no ablation)
        without training.
    name : str
        Model name recorded in the file.

    Returns
    -------
    DefaultModelResult

    Raises
    ------
    PRSMHealthError
        ``evaluate_only`` without a model and its metrics in ``out_dir``; the errors of
        :func:`~prsm_health.training.train.train` and of generation.
    """
    out_dir, work = Path(out_dir), Path(work)
    reference = default_recipe() if reference is None else reference
    out_dir.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    model_path = out_dir / "default.skops"
    metrics_path = out_dir / "default.metrics.json"
    dataset_dir = work / reference.name
    if evaluate_only:  # the model as it is; its training metrics kept
        if not (model_path.exists() and metrics_path.exists()):
            raise PRSMHealthError(
                f"evaluate_only: {model_path} and {metrics_path} must exist (train first)"
            )
        metrics = json.loads(metrics_path.read_text())
    else:
        generate(reference, dataset_dir, workers=workers)
        metrics = train(dataset_dir, model_path, name=name, cv=CV_FOLDS)
    bundle = load_bundle(model_path)
    evaluation, records = evaluate_default_model(
        bundle,
        reference,
        work,
        off_grid=off_grid,
        per_class=per_class,
        honesty_n=honesty_n,
        workers=workers,
    )
    metrics.update(evaluation)
    metrics["feature_names"] = bundle.feature_names
    metrics["channels"] = list(bundle.channels)
    if not evaluate_only:
        metrics["ablation"] = ablation(dataset_dir, bundle.feature_names)
    metrics["sample_rate"] = bundle.metadata["sample_rate"]
    metrics_path.write_text(json.dumps(metrics, indent=2, default=float))
    card_path = write_model_card(metrics, model_path)
    return DefaultModelResult(metrics, model_path, metrics_path, card_path, records)


def instrumentation_experiment(
    reference: Recipe,
    instrumentation: str,
    work: str | Path,
    *,
    per_class: int = 30,
    workers: int | None = None,
) -> dict:
    """The reference recipe measured by another instrumentation profile: what that profile can
    see. Trains on it, then scores the held-out split and each class at default severity
    through the diagnosis.

    Writes ``work/<profile>.skops`` and ``work/<profile>.metrics.json``; no card, the shipped
    model is not touched.

    Returns
    -------
    dict
        ``instrumentation``, ``channels``, ``indicators`` (count), ``held_out``,
        ``default_severity``, ``fault_importance`` and ``metrics_path``.
    """
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    other = recipe_for_instrumentation(reference, instrumentation)
    generate(other, work / other.name, workers=workers)
    model_path = work / f"{instrumentation}.skops"
    metrics = train(work / other.name, model_path, name=f"prsm-{instrumentation}", cv=CV_FOLDS)
    bundle = load_bundle(model_path)
    held_out, _ = evaluate_model(bundle, Dataset(work / other.name))
    result = {
        "instrumentation": instrumentation,
        "channels": list(bundle.channels),
        "indicators": len(bundle.feature_names),
        "held_out": held_out,
        "default_severity": default_severity(
            bundle, other, work, per_class=per_class, workers=workers
        ),
        "fault_importance": metrics.get("fault_importance"),
    }
    path = work / f"{instrumentation}.metrics.json"
    path.write_text(json.dumps(result, indent=2, default=float))
    return {**result, "metrics_path": str(path)}


def recipe_for_instrumentation(reference: Recipe, instrumentation: str) -> Recipe:
    """``reference`` measured by another instrumentation profile: renamed
    ``<name>-<profile>``, its sensor sweeps (``instrumentation.*``) dropped."""
    source = dict(reference.source, instrumentation=instrumentation)
    source["name"] = f"{reference.name}-{instrumentation}"
    # the sensor sweeps name the reference profile's sensors; this profile keeps its own figures
    source["sweep"] = {
        k: v for k, v in reference.sweep.items() if not k.startswith("instrumentation.")
    }
    return Recipe.from_dict(source)
