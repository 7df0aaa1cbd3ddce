"""Dataset generation throughput toward issue [5/7]'s "1000 one-second runs in 5 minutes on 2
cores": one-second runs of the default flight-ema instrumentation written to Parquet, measured
in one run side by side with the loop a user would otherwise write (``simulate`` and
``write_run_parquet`` in a plain ``for`` loop, one process), and with ``options.max_step`` at
its default and at ``"auto"``.

    python tools/bench/bench_generation.py [--runs 40] [--workers 2] [--work build/bench-generation]

Runs: the paper-01 PRSM in its drive train, Hertzian flanks, a reversing load (±300 N at 10 Hz
about a mean of 0 or 100 N), 60 or 100 rad/s, clearance 0–40 µm — the demo recipe's ranges at
1 s per run. Prints runs per minute and the time 1000 such runs would take at that rate.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

from prsm_health.datasets import Recipe, generate, load_recipe
from prsm_health.io.parquet import write_run_parquet

ROOT = Path(__file__).resolve().parents[2]


def recipe(runs: int, max_step) -> Recipe:
    demo = load_recipe(ROOT / "datasets" / "demo.toml")
    source = dict(demo.source, name=f"bench-1s-{max_step}", duration=1.0, test_fraction=0.0)
    source["options"] = dict(source.get("options", {}), max_step=max_step)
    source["sweep"] = dict(demo.sweep, repeats=max(1, runs // 8))
    return Recipe.from_dict(source)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=40, help="runs per measurement (× 8)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--work", default=str(ROOT / "build" / "bench-generation"))
    args = parser.parse_args()
    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    rows = []
    # the baseline: a plain loop in one process over the same runs
    base = recipe(args.runs, 5e-6)
    specs = base.runs()[: max(4, args.runs // 4)]
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        for spec in specs:
            write_run_parquet(spec.scenario().simulate(), Path(tmp) / f"{spec.run_id}.parquet")
        rows.append(("plain loop, 1 process, max_step 5 µs", len(specs), time.perf_counter() - t0))
    for step in (5e-6, "auto"):
        r = recipe(args.runs, step)
        t0 = time.perf_counter()
        report = generate(r, work / r.name, workers=args.workers, progress=False)
        label = f"prsm-health generate, {args.workers} workers, max_step {step}"
        rows.append((label, report.generated_runs, time.perf_counter() - t0))
    print("| method | runs | wall time | runs per minute | 1000 one-second runs |")
    print("|---|---|---|---|---|")
    for label, n, wall in rows:
        rate = 60.0 * n / wall
        print(f"| {label} | {n} | {wall:.1f} s | {rate:.1f} | {1000 / rate:.1f} min |")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
