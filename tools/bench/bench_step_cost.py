"""The full model's cost per simulated second, this checkout against an earlier commit's, side by
side in one run (issue [5/5] item 1: cheaper full-model steps).

    python tools/bench/bench_step_cost.py [--baseline 767234c] [--rounds 5] [--runs 3]

The earlier commit is checked out into a temporary git worktree and measured by the same script in
a subprocess of this interpreter with that worktree first on ``sys.path``; the two versions
alternate, round after round, so a change of machine speed (±30 % here between minutes) hits
both. Each round measures, per version:

- **kernel**: the dynamics kernel alone (``integrate``) on 0.2 s of each run's model, h = 5 µs;
- **simulate**: a whole ``simulate`` of each run (model build, step guard, settling, kernel,
  decimation, sensor models): what ``generate`` pays per run.

Runs: the first ``--runs`` of ``datasets/flight-ema-reference.toml`` (the realistic-duty recipe:
flight-ema sensors, the drive train, loads of 2–40 % C_a) cut to 1 s. Prints the best rate of each
version (simulated s per wall s), the ratio of the bests and the median of the per-round ratios
(each round measures both within a minute, so its ratio cancels the machine's drift), and what the
changed arithmetic did to the statistics of the measured channels (bits change: a rational tanh,
reciprocals).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]

#: Measures one version (its package first on sys.path) and prints a JSON line.
MEASURE = r"""
import json, sys, time
import numpy as np
from scipy import signal
from prsm_health.datasets import Recipe, load_recipe
from prsm_health.simulation.dynamics import simulate as S
from prsm_health.simulation.dynamics.model import build_model, initial_state

recipe_path, n_runs = sys.argv[1], int(sys.argv[2])
source = load_recipe(recipe_path).source
recipe = Recipe.from_dict(dict(source, name="bench-step", duration=1.0, test_fraction=0.0))
scenarios = [spec.scenario() for spec in recipe.runs()[:n_runs]]
h, span = 5e-6, 0.2
kernel = simulate_rate = 0.0
stats = []
scenarios[0].simulate()  # compiled (cache) and warm
for sc in scenarios:
    model = build_model(sc.design, sc.health, sc.profile, sc.options, sc.seed, sc.drive_train)
    y = initial_state(model)
    t0 = time.perf_counter()
    S.integrate(model, y, h, int(span / h))
    kernel += time.perf_counter() - t0
    t0 = time.perf_counter()
    run = sc.simulate()
    simulate_rate += time.perf_counter() - t0
    accel = run.channels["nut_axial_accel"]
    f, psd = signal.welch(accel - accel.mean(), run.sample_rate, nperseg=2048)
    df = f[1] - f[0]
    stats.append({
        "accel_rms": float(np.std(accel)),
        "band_below_3k": float(psd[(f >= 20) & (f < 3000)].sum() * df),
        "band_3k_8k": float(psd[(f >= 3000) & (f < 8000)].sum() * df),
        "torque_mean": float(np.mean(run.channels["drive_torque"])),
        "energy_residual": float(
            (run.energy["drive"] + run.energy["load"] - run.energy["dissipated"])
            / max(abs(run.energy["drive"]), 1e-12)
        ),
    })
print(json.dumps({
    "kernel": len(scenarios) * span / kernel,
    "simulate": len(scenarios) * 1.0 / simulate_rate,
    "stats": stats,
}))
"""


def _measure(package_root: Path, recipe: Path, runs: int) -> dict:
    code = f"import sys; sys.path.insert(0, {str(package_root)!r})\n" + MEASURE
    out = subprocess.run(
        [sys.executable, "-c", code, str(recipe), str(runs)],
        capture_output=True,
        text=True,
        check=True,
        cwd=package_root,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--baseline", default="767234c", help="the earlier commit")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    recipe = ROOT / "datasets" / "flight-ema-reference.toml"
    with tempfile.TemporaryDirectory() as tmp:
        worktree = Path(tmp) / "baseline"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(worktree), args.baseline],
            check=True,
            capture_output=True,
        )
        try:
            versions = {f"baseline {args.baseline}": worktree, "this checkout": ROOT}
            results = {name: [] for name in versions}
            for _ in range(args.rounds):
                for name, root in versions.items():
                    results[name].append(_measure(root, recipe, args.runs))
                    print(".", end="", flush=True, file=sys.stderr)
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(worktree)],
                check=False,
            )
    print(file=sys.stderr)
    base, new = (results[name] for name in versions)
    print(f"{args.runs} one-second runs of flight-ema-reference, {args.rounds} rounds alternated\n")
    print("| version | kernel alone: simulated s per wall s (best) | whole simulate (best) |")
    print("|---|---|---|")
    for name, rows in results.items():
        kernel = max(r["kernel"] for r in rows)
        whole = max(r["simulate"] for r in rows)
        print(f"| {name} | {kernel:.3f} | {whole:.3f} |")
    ratio_k = max(r["kernel"] for r in new) / max(r["kernel"] for r in base)
    ratio_s = max(r["simulate"] for r in new) / max(r["simulate"] for r in base)
    print(f"| ratio of the bests | {ratio_k:.2f}× | {ratio_s:.2f}× |")
    # Each round measures both versions within a minute: its ratio cancels the machine's drift
    # between minutes, which the best of each does not.
    paired = {
        key: np.array([n[key] / b[key] for b, n in zip(base, new)])
        for key in ("kernel", "simulate")
    }
    print(
        "| ratio per round: median (min–max) | "
        + " | ".join(f"{np.median(v):.2f}× ({v.min():.2f}–{v.max():.2f})" for v in paired.values())
        + " |\n"
    )
    print("| run | statistic | baseline | this checkout | change |")
    print("|---|---|---|---|---|")
    for k, (a, b) in enumerate(zip(base[0]["stats"], new[0]["stats"])):
        for key in a:
            change = (b[key] - a[key]) / abs(a[key]) if a[key] else float("nan")
            if key == "energy_residual":
                change = b[key] - a[key]
            print(f"| {k} | {key} | {a[key]:.4g} | {b[key]:.4g} | {100 * change:+.2f} % |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
