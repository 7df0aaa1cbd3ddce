"""Units of your own design monitored check by check: healthy units never alarm, spalled ones
are named within a few checks (issue 42's must-show on a design file that is no preset).

The units are drawn as ``datasets/own-design-check-baseline.toml`` draws them (its ``[units]``
build ranges, on ``datasets/designs/paper02.toml``) with a units seed no dataset uses, so
every unit is fresh: ``--healthy`` units record eight built-in health checks each, healthy (the
temperature and a little lubricant ageing drawn per check); ``--spalled`` units record three
healthy checks (their baseline) and then three with a spall — half on the nut, half on a roller,
at the recipe's default severity. Every check is diagnosed under its unit's asset id by the
model trained on the own-design recipes (``diagnose --asset`` does the same: the unit's
baseline, evidence and change statistic; the first three checks are its baseline), and the
status the fleet page shows is taken after each check (``prsm_health.monitoring.status``).

    prsm-health generate datasets/own-design-check.toml --out own-checks
    prsm-health generate datasets/own-design-check-baseline.toml --out own-baseline
    prsm-health train own-checks --baseline own-baseline --out own.skops
    python tools/studies/own_design_monitoring.py --model own.skops    # ≈ 8 min on 2 cores

Quoted in docs/diagnostics.md ("A health check for your own actuator").
"""

from __future__ import annotations

import argparse
import json
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from tqdm import tqdm

from prsm_health.core.tomlfile import read_toml
from prsm_health.datasets.recipe import Recipe, RunSpec
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.monitoring import FileAssetStore, diagnose_asset
from prsm_health.monitoring.status import asset_status

BASELINE_RECIPE = Path(__file__).parents[2] / "datasets" / "own-design-check-baseline.toml"
#: A units seed no recipe uses: fresh units.
UNITS_SEED = 90_421
BASELINE_CHECKS = 3
HEALTHY_CHECKS = 8
SPALL_CHECKS = 3
SPALLS = {
    "spall_nut": {"kind": "spall", "location": "nut"},
    "spall_roller": {"kind": "spall", "location": "roller"},
}


def recipe(units: int) -> Recipe:
    data = read_toml(BASELINE_RECIPE, "recipe")
    data["units"] = {**data["units"], "seed": UNITS_SEED, "count": units}
    data["fault_cases"] = {name: [case] for name, case in SPALLS.items()}
    return Recipe.from_dict(data, base=BASELINE_RECIPE.parent)


def one_unit(task) -> dict:
    model, units, unit, case = task
    r = recipe(units)
    bundle = load_bundle(model)
    build = r.unit_build(unit)
    rng = np.random.default_rng([UNITS_SEED, unit])
    checks = HEALTHY_CHECKS if case == "none" else BASELINE_CHECKS + SPALL_CHECKS
    out = []
    with tempfile.TemporaryDirectory() as store_dir:
        store = FileAssetStore(store_dir)
        for k in range(checks):
            point = {
                **build,
                "temperature": float(rng.uniform(283.15, 343.15)),
                "lubricant_degradation": float(rng.uniform(0.0, 0.2)),
                "fault_case": case if k >= BASELINE_CHECKS else "none",
                "severity": 1.0,
            }
            seed = int(np.random.SeedSequence([UNITS_SEED, unit, k]).generate_state(1)[0])
            run = RunSpec(r, unit + units * k, point, seed, "test").scenario().simulate()
            d = diagnose_asset(
                run.without_truth(),
                bundle,
                store,
                f"unit-{unit}",
                f"check-{k}",
                healthy=True if k < BASELINE_CHECKS else None,
                operating_hours=100.0 * k,
            )
            evidence = d.asset.evidence
            status = asset_status(
                None if evidence is None else dict(evidence),
                None if d.asset.baseline is None else dict(d.asset.baseline),
                d.fault_class,
            )
            out.append(
                {
                    "check": k,
                    "fault_class": d.fault_class,
                    "named": None if evidence is None else evidence.fault_class,
                    "change_alarm": None if evidence is None else evidence.change_alarm,
                    "status": status["level"],
                    "clearance": d.clearance.estimate,
                    "realised": 0.5
                    * (
                        run.labels["clearance_screw_realised_mean"]
                        + run.labels["clearance_nut_realised_mean"]
                    ),
                }
            )
    return {"unit": unit, "case": case, "checks": out}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--model", required=True, help="the model trained on the own-design recipes"
    )
    parser.add_argument("--healthy", type=int, default=20, help="healthy units")
    parser.add_argument(
        "--spalled", type=int, default=20, help="spalled units (half nut, half roller)"
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("own_design_monitoring.json"))
    args = parser.parse_args()
    units = args.healthy + args.spalled
    cases = ["none"] * args.healthy + [list(SPALLS)[i % 2] for i in range(args.spalled)]
    tasks = [(args.model, units, u, case) for u, case in enumerate(cases)]
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(tqdm(pool.map(one_unit, tasks), total=len(tasks), desc="units"))
    healthy = [u for u in results if u["case"] == "none"]
    spalled = [u for u in results if u["case"] != "none"]
    after = [c for u in healthy for c in u["checks"][BASELINE_CHECKS:]]
    summary = {
        "healthy_units": len(healthy),
        "healthy_checks_after_baseline": len(after),
        "healthy_units_with_alarm": sum(
            any(c["status"] == "alarm" for c in u["checks"]) for u in healthy
        ),
        "healthy_status_counts": {
            level: sum(c["status"] == level for c in after)
            for level in ("healthy", "unknown", "watch", "alarm")
        },
    }
    for case in SPALLS:
        units_of = [u for u in spalled if u["case"] == case]
        named_at = []
        for u in units_of:
            spall = u["checks"][BASELINE_CHECKS:]
            hit = next((i + 1 for i, c in enumerate(spall) if c["named"] == "spall"), None)
            named_at.append(hit)
        summary[case] = {
            "units": len(units_of),
            "named_within_3": sum(h is not None for h in named_at),
            "named_at_check": named_at,
            "alarm_within_3": sum(
                any(c["status"] == "alarm" for c in u["checks"][BASELINE_CHECKS:]) for u in units_of
            ),
        }
    args.out.write_text(json.dumps({"summary": summary, "units": results}, indent=1))
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
