"""Train the check part of the shipped default model and score it on units it never saw.

    python tools/release/train_check_model.py [--workers 2] [--work build] [--units 8]

1. generates (resumably) into WORK the health-check recordings of datasets/flight-ema-check.toml
   (units in every state), the same units' baselines (flight-ema-check-baseline.toml), their
   checks as they age from the baseline (flight-ema-check-aging.toml) and their further healthy
   checks (flight-ema-check-healthy.toml);
2. trains the check model on the three pooled (prsm_health.training.check_training:
   clearance, the class alone, the class against the unit's baseline) and saves it beside
   models/default.skops (models/default.check.skops);
3. generates fresh units (prsm_health.training.check_evaluation.evaluation_recipes: three
   baseline checks and five checks per state each) and scores the diagnosis on them — one check
   alone, and five checks against the unit's baseline with the evidence accumulated;
4. writes the numbers into models/default.metrics.json ("check") and re-renders
   models/MODEL_CARD.md, whose "Health-check recordings" section they fill.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from prsm_health.datasets import generate, load_recipe
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL, load_bundle
from prsm_health.release.diagnosis_card import write_model_card
from prsm_health.training.check_evaluation import (
    evaluate_check_model,
    evaluation_recipes,
    generate_evaluation,
)
from prsm_health.training.check_training import (
    BASELINE_ONLY,
    BASELINE_ONLY_CASES,
    NOT_OBSERVABLE,
    UNSEEN_CASES,
    add_check_model,
    train_check_model,
)

ROOT = Path(__file__).resolve().parents[2]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--work", default=str(ROOT / "build"))
    parser.add_argument("--units", type=int, default=8, help="fresh units per state")
    parser.add_argument(
        "--evaluate-only", action="store_true", help="score the check model already shipped"
    )
    args = parser.parse_args(argv)
    work = Path(args.work)
    training = load_recipe(ROOT / "datasets" / "flight-ema-check.toml")
    baseline = load_recipe(ROOT / "datasets" / "flight-ema-check-baseline.toml")
    supplements = [
        load_recipe(ROOT / "datasets" / f"flight-ema-check-{name}.toml")
        for name in ("aging", "healthy")
    ]
    metrics_path = DEFAULT_MODEL.with_name("default.metrics.json")
    metrics = json.loads(metrics_path.read_text())
    if not args.evaluate_only:
        for recipe in (training, baseline, *supplements):
            generate(recipe, work / recipe.name, workers=args.workers)
        part, trained = train_check_model(
            [work / r.name for r in (training, *supplements)],
            work / baseline.name,
            not_observable=NOT_OBSERVABLE,
            unseen_cases=UNSEEN_CASES,
            baseline_only=BASELINE_ONLY,
            baseline_only_cases=BASELINE_ONLY_CASES,
            progress=True,
        )
        add_check_model(DEFAULT_MODEL, part)
        metrics["check"] = {"training": trained}
    datasets = generate_evaluation(
        evaluation_recipes(training, args.units), work, workers=args.workers
    )
    scored = evaluate_check_model(load_bundle(DEFAULT_MODEL), datasets)
    metrics.setdefault("check", {})["evaluation"] = scored
    metrics_path.write_text(json.dumps(metrics, indent=2, default=float))
    write_model_card(metrics, DEFAULT_MODEL)
    summary = {k: v for k, v in scored.items() if k not in ("records", "units")}
    print(json.dumps(summary, indent=2, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
