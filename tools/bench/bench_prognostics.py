"""Benchmark the ageing and prognostics path against what a user would otherwise write.

Measured side by side in one run:

1. the fleet's lives (datasets/fleet.toml, 20 units): prsm_health.physics.life (the lubricant's film
   and the wear rates computed once on a degradation grid, then integrated on an age grid)
   against a plain age-stepping loop that asks the lubrication model for the film at every
   step (1 h steps);
2. diagnosing a fleet's snapshots: ``diagnose_runs`` in batches of 32 against a loop of
   ``diagnose`` per snapshot (needs the fleet dataset: ``--dataset build/fleet``);
3. a prognosis: ``prognose`` on a 10-check history with the shipped model (per call), each
   method.

    python tools/bench/bench_prognostics.py [--dataset build/fleet-check] [--snapshots 96]
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import pandas as pd

from prsm_health.actuator.design_files import load_design
from prsm_health.datasets import Dataset, load_recipe
from prsm_health.diagnostics.diagnosis import diagnose, diagnose_runs, load_bundle
from prsm_health.physics.life import fleet_lives
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.lubrication import asperity_share, stribeck_curve
from prsm_health.physics.wear import PartGeometry, clearance_growth_rate, contact_states
from prsm_health.prognostics import load_prognostics_model, prognose

ROOT = Path(__file__).resolve().parents[2]


def stepping_life(design, spec, unit, geometry) -> float:
    """The loop a user would write: step the age by 1 h, ask the film at the current
    degradation, add the wear (no usage variation); returns the failure age [h]."""
    duty, wear = spec.duty.resolved(load_ratings(design)), spec.wear
    b = unit.initial_clearance + unit.assembly_play  # the installed clearance fails
    age = 0.0
    contacts = [
        (
            load * unit.load_scale,
            share,
            contact_states(design, geometry, load * unit.load_scale, duty.speed),
        )
        for load, share in zip(duty.loads, duty.shares)
    ]
    while b < spec.failure_clearance and age < spec.max_age:
        d = min(age / unit.lubricant_life, 1.0)
        rate = 0.0
        for load, share, states in contacts:
            for side, contact in states.items():
                film = stribeck_curve(
                    design,
                    spec.lubricant,
                    [contact.entrainment_speed],
                    axial_load=load,
                    temperature=unit.temperature,
                    degradation=d,
                )
                rate += (
                    0.5
                    * share
                    * duty.motion_fraction
                    * 3600
                    * clearance_growth_rate(
                        geometry,
                        contact,
                        side,
                        stroke=duty.stroke,
                        asperity_share=float(asperity_share(film.film_ratio)[0]),
                        coefficient=wear.coefficient(d) * unit.wear_scale,
                    )
                )
        b += rate  # 1 h
        age += 1.0
    return age


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", default=str(ROOT / "build" / "fleet-check"))
    parser.add_argument("--snapshots", type=int, default=96)
    args = parser.parse_args()
    recipe = load_recipe(ROOT / "datasets" / "fleet-check.toml")
    design, spec = load_design(recipe.design), recipe.life_spec

    t0 = time.perf_counter()
    lives = fleet_lives(design, spec, recipe.seed)
    t_life = time.perf_counter() - t0
    geometry = PartGeometry.of(design)
    t0 = time.perf_counter()
    stepped = [stepping_life(design, spec, u, geometry) for u in lives[:2]]
    t_step = (time.perf_counter() - t0) / 2 * len(lives)
    print("| what | prsm_health | baseline | ratio |\n|---|---|---|---|")
    print(
        f"| lives of the 20-unit fleet | {t_life:.3f} s | {t_step:.1f} s (1 h steps, "
        f"film per step; 2 units timed) | {t_step / t_life:.0f}× |"
    )
    steady = fleet_lives(
        design, replace(spec, scatter=replace(spec.scatter, usage=0.0)), recipe.seed
    )
    print(
        f"  (check: stepped failure ages {stepped[0]:.0f}, {stepped[1]:.0f} h; the life model's "
        f"without usage variation {steady[0].failure_age:.0f}, {steady[1].failure_age:.0f} h)",
        file=sys.stderr,
    )

    if Path(args.dataset).exists():
        dataset = Dataset(args.dataset)
        bundle = load_bundle()
        ids = list(dataset.runs["run_id"].astype(int))[: args.snapshots]
        runs = [dataset.run(i, truth=False) for i in ids]
        diagnose_runs(runs[:2], bundle)  # compiled kernels warm
        t0 = time.perf_counter()
        for start in range(0, len(runs), 32):
            diagnose_runs(runs[start : start + 32], bundle)
        t_batch = time.perf_counter() - t0
        t0 = time.perf_counter()
        for run in runs:
            diagnose(run, bundle)
        t_loop = time.perf_counter() - t0
        n = len(runs)
        print(
            f"| diagnose {n} snapshots | {n / t_batch:.0f} /s (batches of 32) | "
            f"{n / t_loop:.0f} /s (`diagnose` per run) | {t_loop / t_batch:.2f}× |"
        )

    model = load_prognostics_model()
    unit = lives[0]
    ages = unit.snapshot_ages(10)
    value = unit.clearance(ages) + 0.2e-6  # a commissioned check's reading (card: indicator)
    history = pd.DataFrame(
        {
            "age_hours": ages,
            "clearance": value,
            "clearance_lower": value - 0.75e-6,
            "clearance_upper": value + 0.75e-6,
        }
    )
    prognose(history, model)
    times = []
    for method, repeats in (("degradation", 20), ("similarity", 20), ("physics", 3)):
        t0 = time.perf_counter()
        for _ in range(repeats):
            prognose(history, model, method)
        times.append((time.perf_counter() - t0) / repeats)
    print(
        f"| one prognosis, 10 checks | degradation {times[0] * 1e3:.1f} ms, similarity "
        f"{times[1] * 1e3:.1f} ms, physics (default) {times[2]:.2f} s | – | – |"
    )


if __name__ == "__main__":
    main()
