"""Commands that make datasets: ``generate`` (from a recipe) and ``import`` (a rig's
recordings)."""

from __future__ import annotations

import sys

from prsm_health.datasets import Dataset, dataset_throughput, load_recipe
from prsm_health.datasets import generate as generate_dataset
from prsm_health.datasets.importer import import_recordings as import_dataset
from prsm_health.training.train import training_problems

from .output import print_json, print_table


def generate(args) -> int:
    recipe = load_recipe(args.recipe)
    try:
        report = generate_dataset(
            recipe,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            formats=args.format,
            progress=not args.json,
        )
    except KeyboardInterrupt:
        print(
            f"interrupted: completed batches are kept in {args.out}; run the same command to resume",
            file=sys.stderr,
        )
        return 130
    if args.json:
        print_json(
            {
                "out": str(report.out),
                "runs": report.total_runs,
                "generated": report.generated_runs,
                "resumed": report.resumed_runs,
                "seconds": report.seconds,
                "runs_per_minute": report.runs_per_minute,
            }
        )
    else:
        print(f"{recipe.name}: {dataset_throughput(report)} → {report.out}")
    for text in training_problems(Dataset(report.out).runs):
        print(f"warning: this dataset cannot train a model as is ({text})", file=sys.stderr)
    return 0


def import_recordings(args) -> int:
    summary = import_dataset(
        args.recordings,
        args.labels,
        args.map,
        args.out,
        test_fraction=args.test_fraction,
        seed=args.seed,
        overwrite=args.overwrite,
    )
    if args.json:
        print_json(summary)
        return 0
    print_table(
        [
            ("dataset", summary["out"], ""),
            ("runs", f"{summary['runs']} ({summary['train']} train, {summary['test']} test)", ""),
            ("channels", ", ".join(summary["channels"]), ""),
            ("sample rate", summary["sample_rate"], "Hz"),
            ("classes", ", ".join(summary["classes"]) or "–", ""),
            *group_rows(summary["indicator_groups"]),
        ]
    )
    return 0


def group_rows(groups: dict[str, str]) -> list:
    """Table rows of the indicator groups a dataset can use, and why the others not."""
    usable = [g for g, why in groups.items() if why == "usable"]
    rows = [("indicator groups usable", ", ".join(usable) or "–", "")]
    rows += [(f"  not {g}", why, "") for g, why in groups.items() if why != "usable"]
    return rows
