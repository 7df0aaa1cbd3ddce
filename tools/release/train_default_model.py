"""Train the shipped default model (flight-ema) from datasets/flight-ema-reference.toml and write
its model card.

    python tools/release/train_default_model.py [--workers 2] [--work build] [--evaluate-only]

1. generates the domain-randomised reference dataset (resumable) into WORK/flight-ema-reference;
2. trains the clearance estimator and fault classifier (prsm_health.diagnostics.training.train) →
   models/default.skops and models/default.metrics.json;
3. evaluates them through the diagnosis (gates, OOD score, cannot_tell) on an off-grid set: a
   fresh Latin hypercube over the same ranges with another recipe seed (run seeds never used in
   training), and a sensitivity table over every varied chain element;
4. checks the honesty gates: recordings of another design and another instrumentation (OOD
   flagged?), steady-load recordings and accelerometer-only recordings (no confident class?);
5. writes models/MODEL_CARD.md from the measured numbers.

``--instrumentation lab-rig`` (any other profile): the same recipe measured by that profile,
trained and evaluated (held-out split, each class at default severity) into WORK, as an
experiment on what an instrumentation can see; the shipped model is not touched.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from prsm_health.datasets import Dataset, Recipe, generate, load_recipe
from prsm_health.diagnostics.diagnosis import OOD_LIMIT, diagnose, load_bundle
from prsm_health.diagnostics.evaluation import evaluate_model, sensitivity_table
from prsm_health.diagnostics.training import CLEARANCE_PARAMS, FAULT_PARAMS, clearance_target, train
from prsm_health.signals.features import GROUPS, dataset_features

ROOT = Path(__file__).resolve().parents[2]

MODELS = ROOT / "models"
REFERENCE = "flight-ema-reference"


def off_grid_recipe(reference: Recipe, samples: int) -> Recipe:
    """The reference ranges, a fresh hypercube and fresh run seeds (recipe seed + 1)."""
    source = dict(reference.source)
    source.update(
        name=f"{reference.name}-off-grid",
        seed=reference.seed + 1,
        test_fraction=0.0,
        sweep=dict(reference.sweep, samples=samples),
    )
    return Recipe.from_dict(source)


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


def default_severity_recipes(reference: Recipe, per_class: int) -> dict[str, Recipe]:
    """One recipe per class: the reference's ranges, the class's faults at severity 1, fresh
    seeds (recipe seed + 2 + class index)."""
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


def default_severity(bundle, reference: Recipe, work: Path, args) -> dict:
    """Each class at its default severity (:func:`default_severity_recipes`) through the
    diagnosis, pooled: fault and clearance reports."""
    import pandas as pd

    from prsm_health.diagnostics.evaluation import clearance_report, fault_report

    parts = []
    for recipe in default_severity_recipes(reference, args.per_class).values():
        generate(recipe, work / recipe.name, workers=args.workers)
        parts.append(evaluate_model(bundle, Dataset(work / recipe.name), split="all")[1])
    pooled = pd.concat(parts, ignore_index=True)
    return {
        "per_class": args.per_class,
        "fault": fault_report(pooled),
        "clearance": clearance_report(pooled),
    }


def honesty_checks(bundle, reference: Recipe) -> dict:
    """Recordings the model must not answer confidently: another design, another
    instrumentation, no reversal, the accelerometer alone. Simulated from test-split points of
    the reference recipe with new seeds."""
    specs = [s for s in reference.runs() if s.split == "test"][:6]
    cases = {
        "another design (paper02)": {"design": "paper02"},
        "another instrumentation (lab-rig)": {"instrumentation": "lab-rig"},
        "steady load (no reversal)": {"steady": True},
        "accelerometer only": {"only": ("nut_axial_accel",)},
    }
    out = {}
    for label, change in cases.items():
        rows = []
        for k, spec in enumerate(specs):
            source = dict(reference.source, seed=reference.seed + 1000 + k)
            if "design" in change:
                source["design"] = change["design"]
            if "instrumentation" in change:
                source["instrumentation"] = change["instrumentation"]
            if change.get("steady"):
                source["profile"] = dict(source["profile"], load_profile="constant")
            sweep = {"mode": "grid", **{key: [value] for key, value in spec.point.items()}}
            one = Recipe.from_dict(dict(source, name="check", test_fraction=0.0, sweep=sweep))
            run = one.runs()[0].scenario().simulate()
            if "only" in change:
                run.channels = {c: run.channels[c] for c in change["only"]}
            d = diagnose(run, bundle)
            top = max(d.class_probabilities.values())
            rows.append(
                {
                    "fault_class": d.fault_class,
                    "true_class": one.runs()[0].labels()["fault_class"],
                    "top_probability": top,
                    "ood_score": d.ood_score,
                    "warned": bool(d.warnings),
                    "confident_wrong": d.fault_class not in ("cannot_tell",)
                    and d.fault_class != one.runs()[0].labels()["fault_class"]
                    and top > 0.6,
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


def ablation(dataset: Path, features: list[str]) -> list[dict]:
    """Held-out metrics with each indicator group left out (both models retrained), and with
    all: what each group adds that the others do not."""
    from sklearn.metrics import f1_score

    from prsm_health.diagnostics.estimators import ClearanceEstimator, FaultClassifier

    table = dataset_features(Dataset(dataset))
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


def _um(x) -> str:
    return "–" if x is None else f"{1e6 * x:.2f} µm"


def _f(x, digits: int = 3) -> str:
    return "–" if x is None else f"{x:.{digits}f}"


def card(metrics: dict, size: int) -> str:
    ct, cv, og = metrics["clearance_test"], metrics["clearance_cv"], metrics["off_grid"]
    ft, fcv = metrics["fault_test"], metrics["fault_cv"]
    ogc, ogf = og["clearance"], og["fault"]
    recipe = metrics["model"]
    per_class = "\n".join(
        f"| {c} | {_f(ogf['f1_by_class'][c], 2)} | "
        + " | ".join(str(v) for v in ogf["confusion"]["matrix"][i])
        + " |"
        for i, c in enumerate(ogf["confusion"]["true"])
    )
    head = " | ".join(ogf["confusion"]["predicted"])
    dsf = metrics["default_severity"]["fault"]
    ds_head = " | ".join(dsf["confusion"]["predicted"])
    ds_rows = "\n".join(
        f"| {c} | {_f(dsf['f1_by_class'][c], 2)} | "
        + " | ".join(str(v) for v in dsf["confusion"]["matrix"][i])
        + " |"
        for i, c in enumerate(dsf["confusion"]["true"])
    )
    members = sorted({k for row in dsf["set_membership"].values() for k in row})
    set_head = " | ".join(members)
    set_rows = "\n".join(
        f"| {c} | " + " | ".join(_f(row.get(k, 0.0), 2) for k in members) + " |"
        for c, row in dsf["set_membership"].items()
    )
    ablation_rows = "\n".join(
        f"| {r['features']} | {r['n_features']} | {_um(r['mae'])} | {r['coverage']:.3f} | "
        f"{_um(r['width'])} | {r['macro_f1']:.3f} |"
        for r in metrics["ablation"]
    )
    sensitivity_rows = "\n".join(
        f"| `{r['parameter']}` | {r['low']:.4g} … {r['high']:.4g} | {r['n']} | {_um(r['bias'])} | "
        f"{_um(r['mae'])} | {_f(r['coverage'])} |"
        for r in metrics["sensitivity"]
    )
    honesty_rows = "\n".join(
        f"| {label} | {h['n']} | {h['ood_flagged']} | {h['median_ood_score']:.2f} | "
        f"{h['cannot_tell']} | {h['confident_wrong']} | {h['warned']} |"
        for label, h in metrics["honesty"].items()
    )

    def importance(key):
        rows = [r for r in metrics.get(key, []) if r["kind"] == "group"]
        return "\n".join(
            f"| {r['name']} | {r['importance_mean']:.4f} ± {r['importance_std']:.4f} |"
            for r in rows
        )

    return f"""# Model card — `models/default.skops` (instrumentation `flight-ema`)

*Generated by `tools/release/train_default_model.py`; every number below was measured by it.*

**What it is.** The default diagnosis model of `prsm-health diagnose` / `replay` / the service,
for a paper-01 PRSM measured by the `flight-ema` instrumentation (resolver, phase-current
torque, LVDT on the output rod, one axial MEMS accelerometer; no load cell —
docs/instrumentation.md): a `ClearanceEstimator` (gradient-boosted point model; gradient-boosted
quantiles of its out-of-fold residual, conformally calibrated to a 90 % interval), a
`FaultClassifier` (gradient boosting, sigmoid-calibrated probabilities) and a
`DistributionGuard` (k-nearest-neighbour out-of-distribution score), on the
{len(metrics["feature_names"])} indicators of `prsm_health.signals.features` this instrumentation gives,
over {recipe["window"]:g} s windows at {metrics["sample_rate"]:g} Hz. File size
{size / 1e6:.2f} MB; prsm_health, scikit-learn and numpy versions are recorded in the file and
checked on load. Required channels: {", ".join(metrics["channels"])}.

**Data.** `datasets/flight-ema-reference.toml`, domain-randomised: {metrics["runs"]["train"]}
training and {metrics["runs"]["test"]} held-out runs (random 20 % split) of a Latin hypercube over
clearance 0–40 µm, uneven wear, preload 0–5 µm, speed 50–130 rad/s, mean load ±400 N with a
300–2500 N swing at 4–16 Hz and 1–20 ms reversal ramps, lubricant degradation 0–1,
temperature 10–70 °C, the fault cases of docs/faults.md (spalls on screw, nut, roller; ring-
and roller-gear tooth cracks; a tooth pit; preload loss) at 0.5–1.5× default severity, contact
damping 0.02–0.034 and restitution 0.4–0.8, coupling stiffness and damping, payload, linkage
stiffness, accelerometer/LVDT/torque noise; sensor gains, offsets and harmonic errors and the
manufacturing scatter drawn per run from their documented spreads. Classes (precedence):
spall > tooth_damage > severe_wear (b ≥ 30 µm) > wear (b ≥ 15 µm) > preload_loss (≥ 50 % lost)
> lubrication (degradation ≥ 0.5) > healthy.

## Metrics

Clearance through the diagnosis (gates and OOD score applied: an interval is the whole trained
range where the clearance was not observable or the window out of distribution); fault macro-F1
counts `cannot_tell` as a miss.

| set | clearance MAE | 90 % coverage | mean width | fault macro-F1 (models alone: argmax; through the diagnosis: class sets) |
|---|---|---|---|---|
| 3-fold CV on train (grouped by operating point; models alone) | {_um(cv["mae"])} | {_f(cv["interval_coverage"])} | {_um(cv["mean_interval_width"])} | {_f(fcv["macro_f1"])} |
| held-out split ({ct["n"]} runs; models alone) | {_um(ct["mae"])} | {_f(ct["interval_coverage"])} | {_um(ct["mean_interval_width"])} | {_f(ft["macro_f1"])} |
| off-grid ({ogc["n"]} runs: a fresh hypercube, recipe seed + 1, run seeds never used in training; through the diagnosis) | {_um(ogc["mae"])} | {_f(ogc["coverage"])} | {_um(ogc["mean_width"])} | {_f(ogf["macro_f1"])} |

Off-grid: clearance observable in {_f(ogc["observable_fraction"], 2)} of the runs; out of
distribution {_f(og["ood"]["flagged_fraction"], 3)}; `cannot_tell` {_f(ogf["cannot_tell_fraction"], 3)};
macro-F1 of the runs given a class {_f(ogf["macro_f1_told"])}.

Figures of the off-grid set: [predicted vs true clearance](figures/clearance.png),
[class calibration](figures/calibration.png) (the probabilities are cautious: the share correct
lies above the top probability), [confusion matrix](figures/confusion.png).

### Each class at its default severity

{metrics["default_severity"]["per_class"]} runs per class, on otherwise healthy units (clearance
< 12 µm, lubricant degradation < 0.4) except where the class is the clearance or the lubricant,
everything else drawn from the reference ranges, fresh seeds: fault macro-F1
**{_f(metrics["default_severity"]["fault"]["macro_f1"])}** (`cannot_tell` counted as a miss;
{_f(metrics["default_severity"]["fault"]["macro_f1_told"])} over the runs given a class,
`cannot_tell` {_f(metrics["default_severity"]["fault"]["cannot_tell_fraction"], 3)}); clearance MAE
{_um(metrics["default_severity"]["clearance"]["mae"])}, coverage
{_f(metrics["default_severity"]["clearance"]["coverage"])}.

| class | F1 | {ds_head} |
|---|---|{"---|" * len(metrics["default_severity"]["fault"]["confusion"]["predicted"])}
{ds_rows}

**Named classes and class sets.** A diagnosis names the most probable class when its
probability reaches 0.5, else it answers `cannot_tell`; beside it, the model's 90 % class set
(per-class conformal thresholds from the calibration folds: `FaultClassifier.predict_set`)
lists the classes the evidence cannot rule out, in a warning when it holds more than the named
class. At default severity the sets hold the true class in {_f(dsf["set_coverage"])} of the runs, with
{_f(dsf["mean_set_size"], 2)} classes on average; confident wrong answers (a class named, wrong,
top probability > 0.6): {_f(dsf["confident_wrong_fraction"], 3)} of the runs (off-grid:
{_f(ogf["confident_wrong_fraction"], 3)}). Share of each class's runs whose set holds each
class (rows true):

| class | {set_head} |
|---|{"---|" * len(members)}
{set_rows}

### Fault classes (off-grid): F1 and confusion (rows true, columns predicted)

| class | F1 | {head} |
|---|---|{"---|" * len(ogf["confusion"]["predicted"])}
{per_class}

## Honesty checks (simulated recordings the model must not answer confidently)

Six recordings each, from test-split points of the reference recipe with new seeds. A
*confident wrong* class is a class other than the truth and `cannot_tell` with probability > 0.6.

| recording | n | OOD flagged (score > {OOD_LIMIT:g}) | median OOD score | `cannot_tell` | confident wrong | warned |
|---|---|---|---|---|---|---|
{honesty_rows}

## Sensitivity (off-grid runs in thirds of each varied element's range)

How the clearance estimate shifts across each chain element's range: bias (estimate − truth),
MAE and interval coverage of the runs in each third.

| element | range | n | bias | MAE | coverage |
|---|---|---|---|---|---|
{sensitivity_rows}

## What each indicator group adds (held-out split, both models retrained without it)

| features | n | clearance MAE | 90 % coverage | mean width | fault macro-F1 (argmax) |
|---|---|---|---|---|---|
{ablation_rows}

Permutation importance (held-out, groups permuted together) — clearance (drop of R²):

| group | importance |
|---|---|
{importance("clearance_importance")}

Fault class (drop of accuracy):

| group | importance |
|---|---|
{importance("fault_importance")}

## What it does not cover

- One design (paper01); another design's recording is warned about and scored out of
  distribution (honesty checks), not diagnosed.
- One instrumentation (flight-ema). A recording without one of its channels is diagnosed with
  what it has, the clearance is not observable without the LVDT, and the class is
  `cannot_tell`.
- Contact damping ratios above 0.034 (the RK4 step would have to shrink, docs/performance.md),
  clearances beyond 40 µm, speeds beyond 50–130 rad/s, loads beyond the trained swing: the
  diagnosis warns outside the trained speed and drive-torque ranges.
- Clearance is not observable without a load or motion reversal (steady load holds each roller
  on one flank): the interval is the trained range and the class `cannot_tell`.
- **Faults this chain cannot tell apart.** Gear tooth damage has no signature in these
  channels (docs/faults.md); spalls at default severity barely do at these loads, and the
  impacts of the clearance at every reversal dominate the envelope; a lubricant's extra
  friction is hidden in a drive torque dominated by an axial load no sensor measures (no load
  cell on a flight EMA); a partial preload loss changes the play by a few µm, inside the
  clearance's own spread. Only wear and severe wear are seen (by the lost motion: the argmax of
  the classifier reaches F1 ≈ 0.7–0.9 on them, ablation and earlier cards). But a spall or a
  cracked tooth may sit on a worn unit too (the taxonomy names the localised fault first), and
  nothing in these channels rules it out: the class set keeps spall and tooth damage for nearly
  every window, and the warning says so beside what it *does* rule out (healthy and
  lubrication for most worn units, the class-set table); the clearance estimate and its
  interval carry the wear. The issue asked for a fault macro-F1 ≥ 0.9 at default severities;
  this instrumentation cannot give it honestly: naming the most probable class whatever its
  probability (the previous card, 2026-11-24) scored 0.34, and gave a wrong class to 25–29 of
  the 30 runs of healthy, preload loss, spall and tooth damage (14 of lubrication), at
  probabilities of 0.25–0.3; naming only classes that reach 0.5 scores
  {_f(dsf["macro_f1"])} with {_f(dsf["confident_wrong_fraction"], 3)} confident wrong answers.
  No indicator we tried (time-synchronous averages, envelope lines at the defect frequencies,
  spectral kurtosis, plain-spectrum lines at the defect frequencies) changed that (ablation
  table, docs/faults.md). What would: a load cell, a tangential accelerometer, longer windows
  at higher load (docs/faults.md).
- Real recordings differ from the simulator (mounting, transfer paths, temperature): validate
  on measured data (`prsm-health import`, `prsm-health evaluate`) before trusting it.
"""


def experiment(reference: Recipe, instrumentation: str, work: Path, args) -> int:
    """The reference recipe measured by another instrumentation profile: train, then the
    held-out split and each class at default severity through the diagnosis. Writes
    WORK/<profile>.skops and WORK/<profile>.metrics.json; the shipped model is not touched."""

    source = dict(reference.source, instrumentation=instrumentation)
    source["name"] = f"{reference.name}-{instrumentation}"
    # the sensor sweeps name flight-ema's sensors; this profile keeps its own figures
    source["sweep"] = {
        k: v for k, v in reference.sweep.items() if not k.startswith("instrumentation.")
    }
    other = Recipe.from_dict(source)
    generate(other, work / other.name, workers=args.workers)
    model_path = work / f"{instrumentation}.skops"
    metrics = train(work / other.name, model_path, name=f"prsm-{instrumentation}", cv=3)
    bundle = load_bundle(model_path)
    held_out, _ = evaluate_model(bundle, Dataset(work / other.name))
    result = {
        "instrumentation": instrumentation,
        "channels": list(bundle.channels),
        "indicators": len(bundle.feature_names),
        "held_out": held_out,
        "default_severity": default_severity(bundle, other, work, args),
        "fault_importance": metrics.get("fault_importance"),
    }
    path = work / f"{instrumentation}.metrics.json"
    path.write_text(json.dumps(result, indent=2, default=float))
    print(json.dumps({k: result[k] for k in ("held_out", "default_severity")}, indent=2))
    print(f"metrics {path}")
    return 0


def evaluation(bundle, reference: Recipe, work: Path, args) -> dict:
    """The model through the diagnosis: off-grid set (and its figures), sensitivity table, each
    class at default severity, honesty checks."""

    from prsm_health.apps.plots import plot_evaluation

    out = {}
    off = off_grid_recipe(reference, args.off_grid)
    generate(off, work / off.name, workers=args.workers)
    report, records = evaluate_model(bundle, Dataset(work / off.name), split="all", progress=True)
    out["off_grid"] = report
    plot_evaluation(report, records, MODELS / "figures")
    varied = [k for k in off.sweep if k not in ("mode", "samples", "repeats", "fault_case")]
    label_of = {"clearance": "clearance", "speed": "screw_speed", "load": "axial_load"}
    out["sensitivity"] = sensitivity_table(records, [label_of.get(k, k) for k in varied])
    out["default_severity"] = default_severity(bundle, reference, work, args)
    out["honesty"] = honesty_checks(bundle, reference)
    return out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--work", default=str(ROOT / "build"))
    parser.add_argument("--off-grid", type=int, default=300, help="off-grid evaluation runs")
    parser.add_argument(
        "--per-class", type=int, default=30, help="runs per class at default severity"
    )
    parser.add_argument(
        "--evaluate-only",
        action="store_true",
        help="re-score the shipped model (off-grid, default severity, honesty) without training",
    )
    parser.add_argument(
        "--instrumentation",
        default="flight-ema",
        help="another profile (e.g. lab-rig): an experiment with metrics in WORK, no card",
    )
    args = parser.parse_args()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    MODELS.mkdir(exist_ok=True)
    reference = load_recipe(ROOT / "datasets" / f"{REFERENCE}.toml")
    if args.instrumentation != "flight-ema":
        return experiment(reference, args.instrumentation, work, args)
    model_path = MODELS / "default.skops"
    metrics_path = MODELS / "default.metrics.json"
    if args.evaluate_only:  # the shipped model as it is; its training metrics kept
        metrics = json.loads(metrics_path.read_text())
    else:
        generate(reference, work / REFERENCE, workers=args.workers)
        metrics = train(work / REFERENCE, model_path, name="prsm-default-flight-ema", cv=3)
    bundle = load_bundle(model_path)
    metrics.update(evaluation(bundle, reference, work, args))
    metrics["feature_names"] = bundle.feature_names
    metrics["channels"] = list(bundle.channels)
    if not args.evaluate_only:
        metrics["ablation"] = ablation(work / REFERENCE, bundle.feature_names)
    metrics["sample_rate"] = bundle.metadata["sample_rate"]
    metrics_path.write_text(json.dumps(metrics, indent=2, default=float))
    size = model_path.stat().st_size
    (MODELS / "MODEL_CARD.md").write_text(card(metrics, size))
    print(json.dumps({k: metrics[k] for k in ("off_grid", "honesty")}, indent=2))
    print(f"model {model_path} ({size / 1e6:.2f} MB), card {MODELS / 'MODEL_CARD.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
