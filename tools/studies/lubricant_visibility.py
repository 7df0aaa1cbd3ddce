"""Can a load cell see the lubricant? The reference recipe's healthy and lubrication units
(no localised fault, clearance below the wear threshold) measured by ``lab-rig`` (which has a
load cell) and by ``flight-ema`` (which has not), and how well the lubricant's degradation is
read from the drive's energy balance (the ``efficiency`` indicator) and from all indicators.

    python tools/studies/lubricant_visibility.py [--samples 200] [--workers 2] [--work build]

Prints, per instrumentation: the rank correlation (Spearman) of ``efficiency`` and of
``drive_torque_mean`` with the lubricant degradation and with the temperature, and the
cross-validated ROC AUC of healthy vs lubrication (degradation ≥ 0.5) from ``efficiency``
alone and from every indicator (gradient boosting, 5 folds) — side by side in one run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from prsm_health.datasets import Dataset, Recipe, generate, load_recipe
from prsm_health.signals.features import FEATURES, dataset_features

ROOT = Path(__file__).resolve().parents[2]


def recipe(instrumentation: str, samples: int) -> Recipe:
    reference = load_recipe(ROOT / "datasets" / "flight-ema-reference.toml")
    source = dict(reference.source, instrumentation=instrumentation, test_fraction=0.0)
    source["name"] = f"lubricant-visibility-{instrumentation}"
    sweep = {k: v for k, v in reference.sweep.items() if not k.startswith("instrumentation.")}
    sweep.update(samples=samples, fault_case=["none"], clearance=[0.0, 12e-6], preload=[0.0, 0.0])
    source["sweep"] = sweep
    return Recipe.from_dict(source)


def study(table) -> dict:
    from scipy.stats import spearmanr
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.metrics import roc_auc_score
    from sklearn.model_selection import cross_val_predict

    y = (table["lubricant_degradation"] >= 0.5).to_numpy()
    out = {}
    for name in ("efficiency", "drive_torque_mean"):
        x = table[name].to_numpy(float)
        ok = np.isfinite(x)
        out[name] = {
            "finite": float(np.mean(ok)),
            "rho_degradation": spearmanr(x[ok], table["lubricant_degradation"][ok])[0]
            if ok.sum() > 2
            else np.nan,
            "rho_temperature": spearmanr(x[ok], table["temperature"][ok])[0]
            if ok.sum() > 2
            else np.nan,
        }
    present = [c for c in FEATURES if table[c].notna().any()]  # the profile's indicators
    for label, cols in (("efficiency alone", ["efficiency"]), ("every indicator", present)):
        if not table[cols].notna().any().any():
            out[f"AUC {label}"] = np.nan
            continue
        model = HistGradientBoostingClassifier(max_iter=100, random_state=0)
        p = cross_val_predict(model, table[cols], y, cv=5, method="predict_proba")[:, 1]
        out[f"AUC {label}"] = float(roc_auc_score(y, p))
    return out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=200)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--work", default=str(ROOT / "build"))
    args = parser.parse_args()
    results = {}
    for instrumentation in ("lab-rig", "flight-ema"):
        r = recipe(instrumentation, args.samples)
        path = Path(args.work) / r.name
        generate(r, path, workers=args.workers)
        results[instrumentation] = study(dataset_features(Dataset(path)))
    rows = sorted({k for r in results.values() for k in r})
    print(f"{args.samples} healthy/lubrication units per instrumentation\n")
    print("| measure | " + " | ".join(results) + " |")
    print("|---|" + "---|" * len(results))
    for key in rows:
        cells = []
        for r in results.values():
            v = r[key]
            cells.append(
                ", ".join(f"{k} {w:.2f}" for k, w in v.items())
                if isinstance(v, dict)
                else f"{v:.3f}"
            )
        print(f"| {key} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
