"""Train and score the shipped prognostics model (models/prognostics.json) on the fleet recipe,
and write its card: the command line of :mod:`prsm_health.release.prognostics_model`.

    python tools/release/train_prognostics_model.py [--dataset build/fleet] [--workers 2]
        [--evaluate-only]

1. generates datasets/fleet.toml (20 units × 30 snapshots) into ``--dataset`` unless it is
   complete (resumable), timed;
2. diagnoses every snapshot with the shipped diagnosis model (batched), as the histories a
   user's fleet would give (cached beside the dataset as ``<dataset>-diagnoses.parquet``);
3. fits the model (what ``prsm-health train FLEET --target rul`` runs) on the training units,
   its threshold the diagnosed clearance at failure;
4. scores the three methods (degradation model, similarity baseline, physics) on the held-out
   units and on every unit of the fleet (4 folds over the units); the default method is the
   one with the best cross-validated α–λ accuracy after half of life; measures what limits it
   (usage variability, indicator noise);
5. writes models/prognostics.json, models/prognostics.metrics.json, models/PROGNOSTICS_CARD.md
   and models/figures/prognostics_*.png.

``--evaluate-only`` re-scores the shipped model without fitting.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from prsm_health.apps.plots import plot_prognostics
from prsm_health.prognostics import DEFAULT_PROGNOSTICS_MODEL
from prsm_health.release.prognostics_model import ALPHA, fleet_recipe, train_prognostics_model

ROOT = Path(__file__).resolve().parents[2]
MODELS = DEFAULT_PROGNOSTICS_MODEL.parent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dataset", default=str(ROOT / "build" / "fleet"))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--evaluate-only", action="store_true", help="re-score the shipped model without fitting"
    )
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    result = train_prognostics_model(
        MODELS,
        fleet_recipe(),
        dataset=args.dataset,
        workers=args.workers,
        evaluate_only=args.evaluate_only,
        progress=True,
    )
    metrics = result.metrics
    figures = plot_prognostics(
        result.histories, result.predictions, result.model, MODELS / "figures", alpha=ALPHA
    )
    drawn = [p.name for p in figures]
    if drawn != metrics["figures"]:  # the card links the figures by name
        raise SystemExit(f"the card links {metrics['figures']}, the figures drawn are {drawn}")
    fleet = metrics["fleet"]
    print(
        f"fleet: {fleet['generation']['runs']} snapshots "
        f"({fleet['generation']['resumed_runs']} already there); "
        f"diagnosed clearance at failure {metrics['model']['threshold'] * 1e6:.2f} µm "
        f"(true limit {fleet['failure_clearance'] * 1e6:g} µm); "
        f"default method {metrics['model']['method']}; {time.perf_counter() - t0:.0f} s"
    )
    for label, summary in (
        ("held out", metrics["held_out"]),
        ("every unit", metrics["cross_validated"]["summary"]),
    ):
        print(label)
        _print_summary(summary)
    print(f"model {result.model_path}, metrics {result.metrics_path}, card {result.card_path}")
    return 0


def _print_summary(summary: dict) -> None:
    for method, s in summary.items():
        print(
            f"{method:12s} α–λ {s['alpha_lambda']:.3f} (whole life {s['alpha_lambda_all']:.3f})"
            f"  coverage after half {s['coverage_after']:.3f}"
            f"  (all {s['coverage']:.3f})  RMSE after half {s['rmse_after']:.0f} h"
            f"  PH {s['prognostic_horizon']:.0f} h"
        )


if __name__ == "__main__":
    sys.exit(main())
