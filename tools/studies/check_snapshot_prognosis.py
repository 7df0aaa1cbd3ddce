"""Prognostics on health-check snapshots: datasets/fleet-check.toml (the shipped fleet's 20 units,
10 health checks each) generated, read by the shipped model's check part, fitted on the
training units and scored on the held-out ones — each method, as
tools/release/train_prognostics_model.py scores the in-service fleet.

    python tools/studies/check_snapshot_prognosis.py [--work build/fleet-check] [--workers 2]
        [--windows build/fleet-diagnoses.parquet]

``--windows``: the in-service fleet's cached diagnoses (tools/release/train_prognostics_model.py
writes them beside its dataset): the same units read by both, a check half an hour after the
window of its age, scored as one history per unit too.

Prints the generation time, how the check diagnoses scatter around the units' true mean
clearance, and α–λ (α = 0.2) after half of life, 90 % coverage, RMSE and prognostic horizon per
method. Nothing is shipped: the shipped prognostics model reads in-service windows.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from prsm_health.datasets import Dataset, generate, load_recipe
from prsm_health.prognostics import fit_prognostics_model, fleet_histories

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", default=str(ROOT / "build" / "fleet-check"))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--windows", help="the in-service fleet's cached diagnoses (Parquet)")
    args = parser.parse_args()
    recipe = load_recipe(ROOT / "datasets" / "fleet-check.toml")
    t0 = time.perf_counter()
    report = generate(recipe, args.work, workers=args.workers, progress=True)
    print(
        f"{report.total_runs} check snapshots ({report.resumed_runs} already there) in "
        f"{time.perf_counter() - t0:.0f} s on {args.workers} workers"
    )
    cache = Path(str(args.work).rstrip("/") + "-diagnoses.parquet")
    if cache.exists():
        histories = pd.read_parquet(cache)
    else:
        histories = fleet_histories(Dataset(args.work), progress=True)
        histories.to_parquet(cache)
    error = 1e6 * (histories["clearance"] - histories["clearance_mean_true"])
    inside = histories["clearance_lower"] <= histories["clearance_mean_true"]
    inside &= histories["clearance_mean_true"] <= histories["clearance_upper"]
    print(
        f"check diagnoses against the true mean clearance: bias {error.mean():.2f} µm, "
        f"sd {error.std():.2f} µm, 90 % interval coverage {inside.mean():.3f}"
    )
    tables = {"checks": histories}
    if args.windows:
        windows = pd.read_parquet(args.windows)
        columns = [c for c in windows.columns if c in histories.columns]
        # a unit's history needs increasing ages: its check half an hour after the window
        checks = histories.assign(age_hours=histories["age_hours"] + 0.5)[columns]
        both = pd.concat([windows[columns], checks], ignore_index=True)
        tables["windows and checks"] = both.sort_values(["unit_id", "age_hours"], kind="stable")
    print(
        "| snapshots | method | α–λ after half | coverage after half | RMSE after half [h] | PH [h] |"
    )
    print("|---|---|---|---|---|---|")
    for name, table in tables.items():
        _, fit = fit_prognostics_model(Dataset(args.work), histories=table, alpha=0.2)
        for method, s in fit.summary.items():
            print(
                f"| {name} | {method} | {s['alpha_lambda']:.3f} | {s['coverage_after']:.3f} | "
                f"{s['rmse_after']:.0f} | {s['prognostic_horizon']:.0f} |"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
