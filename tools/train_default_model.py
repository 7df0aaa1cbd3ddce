"""Train the shipped default model from datasets/clearance-study.toml and write its model card.

    python tools/train_default_model.py [--workers 2] [--work build]

1. generates the reference dataset (resumable) into WORK/clearance-study;
2. trains the clearance estimator and fault classifier (prsm_health.training.train) →
   models/default.skops and models/default.metrics.json;
3. evaluates them on an off-grid set: speeds, loads and clearances drawn inside the training
   ranges but off its grid (Latin hypercube), with the same sensor noise;
4. writes models/MODEL_CARD.md from the measured numbers.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from prsm_health.dataset import Dataset, Recipe, generate, load_recipe  # noqa: E402
from prsm_health.diagnosis import diagnose_indicators, load_bundle  # noqa: E402
from prsm_health.features import GROUPS, dataset_features  # noqa: E402
from prsm_health.training import CLEARANCE_PARAMS, clearance_target, train  # noqa: E402

MODELS = ROOT / "models"


def off_grid_recipe(reference: Recipe, samples: int) -> Recipe:
    source = dict(reference.source)

    def span(key):
        value = reference.sweep[key]
        return list(value["uniform"]) if isinstance(value, dict) else [min(value), max(value)]

    source.update(
        name="clearance-study-off-grid",
        seed=reference.seed + 1,
        test_fraction=0.0,
        sweep={
            "mode": "lhs",
            "samples": samples,
            "clearance": span("clearance"),
            "speed": span("speed"),
            "load": span("load"),
            "friction_scale": span("friction_scale"),
        },
    )
    return Recipe.from_dict(source)


def evaluate(bundle, table) -> dict:
    rows = [{k: row[k] for k in bundle.feature_names} for _, row in table.iterrows()]
    results = diagnose_indicators(rows, bundle)
    y = clearance_target(table)
    est = np.array([r.clearance["estimate"] for r in results], float)
    lo = np.array([r.clearance["lower"] for r in results], float)
    hi = np.array([r.clearance["upper"] for r in results], float)
    from sklearn.metrics import f1_score

    pred = [r.fault_class for r in results]
    return {
        "n": len(y),
        "clearance_mae": float(np.mean(np.abs(est - y))),
        "interval_coverage": float(np.mean((y >= lo) & (y <= hi))),
        "mean_interval_width": float(np.mean(hi - lo)),
        "fault_macro_f1": float(f1_score(table["fault_class"].astype(str), pred, average="macro")),
    }


def ablation(work: Path) -> list[dict]:
    """Held-out clearance MAE and interval width with feature subsets (each model retrained)."""
    from prsm_health.estimators import ClearanceEstimator

    table = dataset_features(Dataset(work / "clearance-study"))
    train_rows, test_rows = table[table["split"] == "train"], table[table["split"] == "test"]
    y_train, y_test = clearance_target(train_rows), clearance_target(test_rows)
    # only the indicators this instrumentation gives (an absent channel's are all NaN)
    given = {c for c in table.columns if table[c].notna().any()}
    everything = [c for c in table.columns if c in set(sum(GROUPS.values(), [])) & given]
    subsets = {
        "all indicators": everything,
        "all but lost motion (vibration + torque only)": [
            c for c in everything if c not in GROUPS["lost_motion"]
        ],
        "axial frequency + operating": GROUPS["axial_frequency"] + GROUPS["operating"],
        "mesh + operating": GROUPS["mesh"] + GROUPS["operating"],
        "classic + operating": GROUPS["classic"] + GROUPS["operating"],
        "lost motion + operating": GROUPS["lost_motion"] + GROUPS["operating"],
        "torque rattle + operating": GROUPS["torque_rattle"] + GROUPS["operating"],
    }
    rows = []
    for label, cols in subsets.items():
        cols = [c for c in cols if c in given]
        if not cols:
            continue
        model = ClearanceEstimator(**CLEARANCE_PARAMS)  # the settings train() uses
        model.fit(train_rows[cols], y_train)
        pred = model.predict(test_rows[cols])
        lo, hi = model.predict_interval(test_rows[cols])
        rows.append(
            {
                "features": label,
                "n_features": len(cols),
                "mae": float(np.mean(np.abs(pred - y_test))),
                "coverage": float(np.mean((y_test >= lo) & (y_test <= hi))),
                "width": float(np.mean(hi - lo)),
            }
        )
    return rows


def card(metrics: dict, size: int) -> str:
    def um(x):
        return f"{1e6 * x:.2f} µm"

    ct, cv, og = metrics["clearance_test"], metrics["clearance_cv"], metrics["off_grid"]
    ablation_rows = "\n".join(
        f"| {r['features']} | {r['n_features']} | {um(r['mae'])} | {r['coverage']:.3f} | {um(r['width'])} |"
        for r in metrics["ablation"]
    )
    ft, fcv = metrics["fault_test"], metrics["fault_cv"]
    recipe = metrics["model"]

    def importance(key):
        rows = [r for r in metrics[key] if r["kind"] == "group"]
        return "\n".join(
            f"| {r['name']} | {r['importance_mean']:.4f} ± {r['importance_std']:.4f} |"
            for r in rows
        )

    return f"""# Model card — `models/default.skops`

*Generated by `tools/train_default_model.py`; every number below was measured by it.*

**What it is.** The default diagnosis model of `prsm-health diagnose` / `replay` / the service:
a `ClearanceEstimator` (gradient-boosted point model; gradient-boosted quantiles of its
out-of-fold residual, conformally calibrated to a 90 % interval) and a `FaultClassifier` (gradient boosting with sigmoid-calibrated probabilities),
on the {len(metrics["feature_names"])} indicators of `prsm_health.features` computed over
{recipe["window"]:g} s windows at {metrics["sample_rate"]:g} Hz. Design: `{recipe["design"]}`.
File size {size / 1e6:.2f} MB. prsm_health, scikit-learn and numpy versions are recorded in the
file and checked on load.

**Data.** `datasets/clearance-study.toml`: paper-01 PRSM, {metrics["runs"]["train"]} training and
{metrics["runs"]["test"]} held-out runs (random 20 % split), clearance drawn uniformly in 0–40 µm
per run (screw = nut = gear), screw speed 50/80/110 rad/s, mean load 0/100/200 N with a ±300 N reversing load at
10 Hz, lubricant friction scale 1.0/2.2, Hertzian flanks, manufacturing variation and
geometric errors on (ISO 3408-3 grade 5), the default drive train (motor, coupling, thrust
bearing, 10 kg payload on its linkage), measured by the `flight-ema` instrumentation (resolver,
phase-current torque, LVDT on the rod, one axial accelerometer; docs/instrumentation.md) — no
load cell, no friction or carrier truth. Indicators it cannot give (tangential and radial
accelerations, load) are left out: {len(metrics["indicators_absent"])} of
{len(metrics["feature_names"]) + len(metrics["indicators_absent"])}. Target: thread
half-clearance b (mean of screw and nut sides) [m]; classes: healthy / wear (b ≥ 15 µm) /
severe_wear (b ≥ 30 µm) / lubrication (friction scale ≥ 1.8), wear taking precedence.

## Metrics

| set | clearance MAE | 90 % interval coverage | mean interval width | fault macro-F1 |
|---|---|---|---|---|
| 5-fold CV on train (grouped by operating point) | {um(cv["mae"])} | {cv["interval_coverage"]:.3f} | {um(cv["mean_interval_width"])} | {fcv["macro_f1"]:.3f} |
| held-out split ({ct["n"]} runs) | {um(ct["mae"])} | {ct["interval_coverage"]:.3f} | {um(ct["mean_interval_width"])} | {ft["macro_f1"]:.3f} |
| off-grid ({og["n"]} runs: speed, load, clearance, lubricant drawn inside the ranges, off the grid; same noise) | {um(og["clearance_mae"])} | {og["interval_coverage"]:.3f} | {um(og["mean_interval_width"])} | {og["fault_macro_f1"]:.3f} |

## What the indicators contribute (held-out permutation importance, groups permuted together)

Clearance (drop of R²):

| group | importance |
|---|---|
{importance("clearance_importance")}

Fault class (drop of accuracy):

| group | importance |
|---|---|
{importance("fault_importance")}

Ablation (clearance estimator retrained on feature subsets, held-out split):

| features | n | MAE | 90 % coverage | mean width |
|---|---|---|---|---|
{ablation_rows}

Groups (all indicators, before the instrumentation's): {", ".join(f"{k} ({len(v)})" for k, v in GROUPS.items())}.
Lost motion at the load reversals (LVDT position against the resolver angle, the sensor's
nonlinearity removed as a smooth function of position) carries the clearance almost alone: it
measures the 4b of play directly, so given it the other groups add little (permutation
importance). The ablation shows what the other indicators can do without it — an actuator
without an output position sensor: the axial accelerometer's classic indicators reach about
1.5–2 µm, the torque rattle (bounces across the gap seen in the motor current) and the shifted
axial frequency much less.

## Limits

- Trained on simulated data of one design (paper01) in one regime: a load reversing through
  zero. Clearance is **not observable** without a load or motion reversal (steady preload holds
  each roller on one flank); the diagnosis then reports the whole trained range 0–40 µm as the
  interval (regime gate on the lost-motion indicator).
- Outside 0–40 µm, 50–110 rad/s, −300…500 N or friction scale 1–2.2 the model extrapolates.
- Lubricant: trained on friction scales 1.0 and 2.2 only, seen through the motor current
  alone (no friction truth); off-grid scales near the 1.8 class threshold are where the
  classifier errs (off-grid macro-F1 above), between wear and lubrication.
- Interval coverage can fall below the nominal 90 % (table: cross-validated and off-grid
  rows): the conformal calibration holds for exchangeable data, the binomial spread with 60–79
  runs is ±3–4 %, and off-grid points are not exchangeable with the grid. Read the intervals
  as ≈ 85–90 %.
- Real recordings differ from the simulator (mounting, sensor placement, temperature): retrain
  or at least validate on measured data before trusting absolute numbers.
- The split-conformal guarantee assumes exchangeable data (same distribution as training).
"""


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--work", default=str(ROOT / "build"))
    parser.add_argument("--off-grid", type=int, default=60, help="off-grid evaluation runs")
    args = parser.parse_args()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    MODELS.mkdir(exist_ok=True)
    reference = load_recipe(ROOT / "datasets" / "clearance-study.toml")
    generate(reference, work / "clearance-study", workers=args.workers)
    model_path = MODELS / "default.skops"
    metrics = train(work / "clearance-study", model_path, name="prsm-default")
    off = off_grid_recipe(reference, args.off_grid)
    generate(off, work / "clearance-study-off-grid", workers=args.workers)
    table = dataset_features(Dataset(work / "clearance-study-off-grid"), progress=True)
    bundle = load_bundle(model_path)
    metrics["off_grid"] = evaluate(bundle, table)
    metrics["feature_names"] = bundle.feature_names
    metrics["ablation"] = ablation(work)
    metrics["sample_rate"] = bundle.metadata["sample_rate"]
    metrics_path = MODELS / "default.metrics.json"
    metrics_path.write_text(json.dumps(metrics, indent=2))
    size = model_path.stat().st_size
    (MODELS / "MODEL_CARD.md").write_text(card(metrics, size))
    print(
        json.dumps({k: metrics[k] for k in ("clearance_test", "fault_test", "off_grid")}, indent=2)
    )
    print(f"model {model_path} ({size / 1e6:.2f} MB), card {MODELS / 'MODEL_CARD.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
