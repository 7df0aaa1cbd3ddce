"""Train the shipped default model (flight-ema) from datasets/flight-ema-reference.toml and write
its model card: the command line of :mod:`prsm_health.release.diagnosis_model`.

    python tools/release/train_default_model.py [--workers 2] [--work build] [--evaluate-only]

1. generates the domain-randomised reference dataset (resumable) into WORK/flight-ema-reference;
2. trains the clearance estimator and fault classifier (prsm_health.training.train.train) →
   models/default.skops and models/default.metrics.json;
3. evaluates them through the diagnosis (gates, OOD score, cannot_tell) on an off-grid set: a
   fresh Latin hypercube over the same ranges with another recipe seed (run seeds never used in
   training), and a sensitivity table over every varied chain element;
4. checks the honesty gates: recordings of another design and another instrumentation (OOD
   flagged?), steady-load recordings and accelerometer-only recordings (no confident class?);
5. writes models/MODEL_CARD.md from the measured numbers, and the off-grid figures into
   models/figures/.

``--instrumentation lab-rig`` (any other profile): the same recipe measured by that profile,
trained and evaluated (held-out split, each class at default severity) into WORK, as an
experiment on what an instrumentation can see; the shipped model is not touched.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from prsm_health.apps.plots import plot_evaluation
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL
from prsm_health.release.diagnosis_model import (
    REFERENCE_RECIPE,
    SHIPPED_INSTRUMENTATION,
    default_recipe,
    instrumentation_experiment,
    train_default_model,
)

ROOT = Path(__file__).resolve().parents[2]
MODELS = DEFAULT_MODEL.parent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
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
        default=SHIPPED_INSTRUMENTATION,
        help="another profile (e.g. lab-rig): an experiment with metrics in WORK, no card",
    )
    args = parser.parse_args(argv)
    work = Path(args.work)
    reference = default_recipe(REFERENCE_RECIPE)
    if args.instrumentation != SHIPPED_INSTRUMENTATION:
        result = instrumentation_experiment(
            reference, args.instrumentation, work, per_class=args.per_class, workers=args.workers
        )
        print(json.dumps({k: result[k] for k in ("held_out", "default_severity")}, indent=2))
        print(f"metrics {result['metrics_path']}")
        return 0
    result = train_default_model(
        MODELS,
        reference,
        work=work,
        workers=args.workers,
        off_grid=args.off_grid,
        per_class=args.per_class,
        evaluate_only=args.evaluate_only,
    )
    metrics = result.metrics
    plot_evaluation(metrics["off_grid"], result.off_grid_records, MODELS / "figures")
    size = result.model_path.stat().st_size
    print(json.dumps({k: metrics[k] for k in ("off_grid", "honesty")}, indent=2))
    print(f"model {result.model_path} ({size / 1e6:.2f} MB), card {result.card_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
