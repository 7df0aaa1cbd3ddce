"""The health check as a measuring instrument: the clearance gauge on simulated units whose
build is drawn from the documented ranges, commissioned and not, beside the learnt clearance.

Each unit (paper01, ``flight-ema`` with its installed sensors' noise drawn as the check recipes
draw it) gets a build drawn uniformly from :data:`RANGES` — thrust-bearing stiffness and play,
coupling, gearhead backlash, friction, lubricant, wear spread — an as-built clearance b_c in
[2, 8] µm and a worn one in [b_c, 30] µm. It runs the built-in check twice at b_c
(commissioning: the gauge's constant offset from the as-built clearance, which is the realised
mean at assembly) and three times on its way to the worn clearance, each at a housing
temperature drawn from 10–70 °C and with its own sensor noise. Every service check is read by
the gauge (:class:`prsm_health.diagnostics.clearance_gauge.Gauge`) commissioned and nominal,
and by the shipped check model (the learnt clearance).

Two sets of units on disjoint seeds: **calibration** (the conformal factor of the interval:
the ⌈(n+1)·0.9⌉-th smallest |error|/sd) and **fresh** (seeds never used elsewhere: the
must-show figures — error sd, unit bias sd, coverage of the calibrated 90 % interval — and the
table by factor, each factor's lower against upper third of its range).

    python tools/studies/clearance_gauge.py --units 30          # ≈ 20 min on 2 cores
    python tools/studies/clearance_gauge.py --factors           # one factor at a time, ≈ 1 min
    python tools/studies/clearance_gauge.py --repeatability     # the sensors' scatter, ≈ 1 min
    python tools/studies/clearance_gauge.py --record clearance_gauge.json   # into the card

Quoted in docs/diagnostics.md ("Clearance measured by physics") and models/MODEL_CARD.md.
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from tqdm import tqdm

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.diagnostics.clearance_gauge import Commissioning, Gauge
from prsm_health.signals.check_indicators import check_indicators
from prsm_health.simulation.scenario import Scenario, SimulationOptions
from prsm_health.training.gauge_calibration import conformal_factor

DESIGN = preset("paper01")
#: What a unit is built and installed with: uniform draws.
RANGES = {
    "thrust_bearing_stiffness": (1.0e8, 2.0e8),  # N/m
    "thrust_bearing_play": (0.0, 5e-6),  # m, half-play
    "coupling_stiffness": (1.0e3, 3.0e3),  # N·m/rad
    "gear_backlash_share": (0.0, 2.0),  # × the datasheet's
    "friction_scale": (0.7, 1.5),
    "lubricant_degradation": (0.0, 1.0),
    "wear_spread": (0.0, 0.3),
    "lvdt_noise": (2e-6, 10e-6),  # m RMS
}
AS_BUILT = (2e-6, 8e-6)
WORN_MAX = 30e-6
TEMPERATURE = (283.15, 343.15)
COMMISSIONING_CHECKS = 2
SERVICE_CHECKS = 3
SEEDS = {"calibration": 710_000, "fresh": 720_000}


def draw_unit(seed: int) -> dict:
    rng = np.random.default_rng([seed, 42])
    unit = {k: float(rng.uniform(*r)) for k, r in RANGES.items()}
    unit["as_built"] = float(rng.uniform(*AS_BUILT))
    unit["worn"] = float(rng.uniform(unit["as_built"], WORN_MAX))
    unit["temperatures"] = [
        float(t) for t in rng.uniform(*TEMPERATURE, COMMISSIONING_CHECKS + SERVICE_CHECKS)
    ]
    return unit


def simulate_check(unit: dict, seed: int, clearance: float, temperature: float, sensor_seed: int):
    dt = DriveTrain(
        thrust_bearing_stiffness=unit["thrust_bearing_stiffness"],
        thrust_bearing_play=unit["thrust_bearing_play"],
        coupling_stiffness=unit["coupling_stiffness"],
        gear_backlash=unit["gear_backlash_share"] * DriveTrain().gear_backlash,
    )
    health = HealthState.uniform(
        clearance,
        wear_spread=unit["wear_spread"],
        friction_scale=unit["friction_scale"],
        lubricant_degradation=unit["lubricant_degradation"],
    )
    instrumentation = {"profile": "flight-ema", "nut_position": {"noise": unit["lvdt_noise"]}}
    run = Scenario(
        DESIGN,
        health,
        OperatingProfile(check="health-check", temperature=temperature),
        instrumentation,
        SimulationOptions(contact_law="hertz"),
        seed,
        dt,
        sensor_seed,
    ).simulate()
    labels = run.labels
    real = 0.5 * (labels["clearance_screw_realised_mean"] + labels["clearance_nut_realised_mean"])
    return run, real


def _learnt(run, bundle):
    """The shipped check model's own clearance (the cross-check beside the measured one)."""
    from prsm_health.diagnostics.check_model import diagnose_check

    c = diagnose_check(run.without_truth(), bundle).measured_clearance.learnt
    return [c.estimate, c.lower, c.upper]


def one_unit(task) -> dict:
    """Commission one unit and read its service checks."""
    from prsm_health.diagnostics.diagnosis import load_bundle

    kind, index, base = task
    seed = base + index
    unit = draw_unit(seed)
    gauge = Gauge.nominal(DESIGN, instrumentation="flight-ema")
    bundle = load_bundle()
    temps = unit["temperatures"]
    first, first_one, as_built_real = [], [], []
    for k in range(COMMISSIONING_CHECKS):
        run, real = simulate_check(unit, seed, unit["as_built"], temps[k], seed * 10 + k)
        reversals = check_indicators(run, DESIGN).reversals
        first.append(gauge.read(reversals))
        first_one.append(gauge.read(reversals[:1]))  # a check with one reversal
        as_built_real.append(real)
    # the as-built clearance known at commissioning: the unit's realised mean then
    as_built = float(np.mean(as_built_real))
    commissioning = Commissioning.from_indicators([r.indicators() for r in first], as_built)
    first_zero_load = float(np.median([r.zero_load_lost_motion for r in first]))
    one = Commissioning.from_indicators([r.indicators() for r in first_one], as_built)
    checks = []
    for j in range(SERVICE_CHECKS):
        b = unit["as_built"] + (unit["worn"] - unit["as_built"]) * (j + 1) / SERVICE_CHECKS
        k = COMMISSIONING_CHECKS + j
        run, real = simulate_check(unit, seed, b, temps[k], seed * 10 + k)
        reversals = check_indicators(run, DESIGN).reversals
        own = gauge.read(reversals, commissioning)
        nominal = gauge.read(reversals)
        heavy = gauge.read(reversals[:1], one)
        # commissioned by the two-load extrapolation's zero-load lost motion instead of the
        # unit's own chain: the reading the uneven gaps pull down most
        two_load = as_built + (nominal.zero_load_lost_motion - first_zero_load) / 4
        checks.append(
            {
                "set": b,
                "real": real,
                "temperature": temps[k],
                "commissioned": [own.estimate, own.sd, own.stiffness_factor],
                "commissioned_two_load": [two_load, own.sd],
                "nominal": [nominal.estimate, nominal.sd],
                "one_reversal": [heavy.estimate, heavy.sd],
                "learnt": _learnt(run, bundle),
                "budget": own.budget,
            }
        )
    # the heaviest reversal's lost motion at each commissioning check (same unit and clearance,
    # each at its own temperature: the friction's torsion moves it, the measured torque with it)
    heavy_steps = [r.reversals[0][2] for r in first]
    return {
        "kind": kind,
        "seed": seed,
        "unit": unit,
        "checks": checks,
        "commissioning": heavy_steps,
    }


def summary(units: list[dict], key: str, scale: float | None) -> dict:
    errors, per_unit, inside = [], [], []
    for u in units:
        e = [c[key][0] - c["real"] for c in u["checks"]]
        errors += e
        per_unit.append(np.mean(e))
        if scale is not None:
            inside += [abs(c[key][0] - c["real"]) <= scale * c[key][1] for c in u["checks"]]
    out = {
        "error_sd_um": float(np.std(errors, ddof=1) * 1e6),
        "error_mean_um": float(np.mean(errors) * 1e6),
        "rmse_um": float(np.sqrt(np.mean(np.square(errors))) * 1e6),
        "unit_bias_sd_um": float(np.std(per_unit, ddof=1) * 1e6),
    }
    if inside:
        out["coverage"] = float(np.mean(inside))
    return out


def learnt_summary(units) -> dict:
    errors = [c["learnt"][0] - c["real"] for u in units for c in u["checks"]]
    inside = [c["learnt"][1] <= c["real"] <= c["learnt"][2] for u in units for c in u["checks"]]
    per_unit = [np.mean([c["learnt"][0] - c["real"] for c in u["checks"]]) for u in units]
    return {
        "error_sd_um": float(np.std(errors, ddof=1) * 1e6),
        "error_mean_um": float(np.mean(errors) * 1e6),
        "rmse_um": float(np.sqrt(np.mean(np.square(errors))) * 1e6),
        "unit_bias_sd_um": float(np.std(per_unit, ddof=1) * 1e6),
        "coverage": float(np.mean(inside)),
    }


def by_factor(units, key="commissioned") -> dict:
    """Each factor's lower against upper third: the error's mean and sd [µm]."""
    out = {}
    factors = [*RANGES, "temperature", "real"]
    for factor in factors:
        values, errors = [], []
        for u in units:
            for c in u["checks"]:
                values.append(c[factor] if factor in c else u["unit"][factor])
                errors.append(c[key][0] - c["real"])
        values, errors = np.asarray(values), np.asarray(errors) * 1e6
        low, high = np.percentile(values, [100 / 3, 200 / 3])
        out[factor] = {
            "lower third": [
                float(errors[values <= low].mean()),
                float(errors[values <= low].std()),
            ],
            "upper third": [
                float(errors[values >= high].mean()),
                float(errors[values >= high].std()),
            ],
        }
    return out


def run_units(count: int, workers: int) -> list[dict]:
    tasks = [(kind, i) for kind in SEEDS for i in range(count)]
    # the seeds travel with the task: a --fresh-seeds choice reaches the worker processes
    tasks = [(kind, i, SEEDS[kind]) for kind, i in tasks]
    with ProcessPoolExecutor(workers) as pool:
        return list(tqdm(pool.map(one_unit, tasks), total=len(tasks), desc="units"))


def report(units: list[dict]) -> dict:
    calibration = [u for u in units if u["kind"] == "calibration"]
    fresh = [u for u in units if u["kind"] == "fresh"]
    out = {}
    for key in ("commissioned", "commissioned_two_load", "nominal", "one_reversal"):
        scores = [abs(c[key][0] - c["real"]) / c[key][1] for u in calibration for c in u["checks"]]
        scale = conformal_factor(scores)
        out[key] = {"conformal_scale": scale, "fresh": summary(fresh, key, scale)}
    out["learnt"] = {"fresh": learnt_summary(fresh)}
    out["by_factor"] = by_factor(fresh)
    out["budget_mean_um"] = {
        term: float(np.mean([c["budget"][term] for u in fresh for c in u["checks"]]) * 1e6)
        for term in fresh[0]["checks"][0]["budget"]
    }
    pairs = [u["commissioning"] for u in units]
    out["commissioning_step_sd_um"] = float(
        np.std([a - b for a, b, *_ in pairs], ddof=1) / np.sqrt(2) * 1e6
    )
    out["units"] = {"calibration": len(calibration), "fresh": len(fresh)}
    return out


#: The flight EMA's unit as the datasheets give it (the one-factor runs change one field).
DEFAULT_UNIT = {
    "thrust_bearing_stiffness": DriveTrain().thrust_bearing_stiffness,
    "thrust_bearing_play": 0.0,
    "coupling_stiffness": DriveTrain().coupling_stiffness,
    "gear_backlash_share": 1.0,
    "friction_scale": 1.0,
    "lubricant_degradation": 0.0,
    "wear_spread": 0.0,
    "lvdt_noise": 5e-6,
}
FACTORS = {
    "default": ({}, {}),
    "bearing 1e8 N/m": ({"thrust_bearing_stiffness": 1e8}, {}),
    "bearing 2e8 N/m": ({"thrust_bearing_stiffness": 2e8}, {}),
    "bearing half-play 5 µm": ({"thrust_bearing_play": 5e-6}, {}),
    "coupling 1e3 N·m/rad": ({"coupling_stiffness": 1e3}, {}),
    "coupling 3e3 N·m/rad": ({"coupling_stiffness": 3e3}, {}),
    "no gearhead backlash": ({"gear_backlash_share": 0.0}, {}),
    "lubricant degraded": ({}, {"lubricant_degradation": 1.0}),
    "friction ×1.5": ({}, {"friction_scale": 1.5}),
    "wear spread 0.3": ({}, {"wear_spread": 0.3}),
    "10 °C": ({}, {"temperature": 283.15}),
    "70 °C": ({}, {"temperature": 343.15}),
}


def one_factor(task):
    label, b = task
    drive, health = FACTORS[label]
    unit = {**DEFAULT_UNIT, **drive}
    unit.update({k: v for k, v in health.items() if k != "temperature"})
    run, real = simulate_check(unit, 0, b, health.get("temperature", 313.15), 0)
    reversals = check_indicators(run, DESIGN).reversals
    gauge = Gauge.nominal(DESIGN, instrumentation="flight-ema")
    two, one = gauge.read(reversals), gauge.read(reversals[:1])
    return label, b, real, two.estimate, one.estimate, two.stiffness_factor


def one_repeat(task):
    noise, sensor_seed = task
    unit = {**DEFAULT_UNIT, "lvdt_noise": noise}
    run, _ = simulate_check(unit, 7, 10e-6, 313.15, sensor_seed)
    return noise, [r.lost_motion for r in check_indicators(run, DESIGN).reversals]


def repeatability(workers: int) -> None:
    """The settled steps' scatter from the sensors alone: one unit, one clearance and
    temperature, six sensor seeds, at the LVDT noise range's ends."""
    tasks = [(noise, seed) for noise in RANGES["lvdt_noise"] for seed in range(6)]
    with ProcessPoolExecutor(workers) as pool:
        rows = list(pool.map(one_repeat, tasks))
    for noise in RANGES["lvdt_noise"]:
        steps = np.array([r for n, r in rows if n == noise]) * 1e6
        print(
            f"LVDT {noise * 1e6:g} µm RMS: sd of the settled step over 6 sensor seeds "
            f"{steps[:, 0].std(ddof=1):.3f} µm (±25 % C_a), {steps[:, 1].std(ddof=1):.3f} µm "
            "(±10 % C_a)"
        )


def factors(workers: int) -> None:
    tasks = [(label, b) for label in FACTORS for b in (5e-6, 20e-6)]
    with ProcessPoolExecutor(workers) as pool:
        rows = list(pool.map(one_factor, tasks))
    print("one factor at a time (flight-ema, LVDT 5 µm; nominal gauge, not commissioned):")
    print("  error [µm of b] of the two-load reading / one reversal, at b = 5 and 20 µm; k")
    table = {}
    for label, _b, real, two, one, k in rows:
        table.setdefault(label, []).append((two - real, one - real, k))
    for label, ((t5, o5, k5), (t20, o20, k20)) in table.items():
        print(
            f"  {label:24s} two loads {t5 * 1e6:+5.2f} {t20 * 1e6:+5.2f}   one reversal "
            f"{o5 * 1e6:+5.2f} {o20 * 1e6:+5.2f}   k {k5:.2f} {k20:.2f}"
        )


def record(result: dict) -> None:
    """The study's result, with the ranges it drew from, into the shipped metrics and card."""
    from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL
    from prsm_health.release.diagnosis_card import write_model_card

    units = {
        "thrust_bearing_stiffness": (1.0, "N/m"),
        "thrust_bearing_play": (1e6, "µm half-play"),
        "coupling_stiffness": (1.0, "N·m/rad"),
        "gear_backlash_share": (1.0, "× the datasheet's"),
        "friction_scale": (1.0, "×"),
        "lubricant_degradation": (1.0, ""),
        "wear_spread": (1.0, ""),
        "lvdt_noise": (1e6, "µm RMS"),
    }
    ranges = {
        k: f"{lo * units[k][0]:g} – {hi * units[k][0]:g} {units[k][1]}".rstrip()
        for k, (lo, hi) in RANGES.items()
    }
    ranges["temperature"] = f"{TEMPERATURE[0]:g} – {TEMPERATURE[1]:g} K"
    ranges["real"] = (
        f"as built {AS_BUILT[0] * 1e6:g}–{AS_BUILT[1] * 1e6:g} µm, worn ≤ {WORN_MAX * 1e6:g} µm"
    )
    metrics_path = DEFAULT_MODEL.with_name("default.metrics.json")
    metrics = json.loads(metrics_path.read_text())
    metrics["gauge"] = {**result, "ranges": ranges}
    metrics_path.write_text(json.dumps(metrics, indent=2, default=float))
    print(write_model_card(metrics, DEFAULT_MODEL))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=30, help="units per set")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--factors", action="store_true", help="one factor at a time instead")
    parser.add_argument(
        "--repeatability", action="store_true", help="the settled steps' scatter from the sensors"
    )
    parser.add_argument("--out", type=Path, default=Path("clearance_gauge.json"))
    parser.add_argument(
        "--fresh-seeds",
        type=int,
        default=SEEDS["fresh"],
        metavar="BASE",
        help="the first seed of the fresh units (another set than the card's)",
    )
    parser.add_argument(
        "--record",
        type=Path,
        default=None,
        metavar="JSON",
        help="put a study's result (an --out file) in models/default.metrics.json and "
        "regenerate models/MODEL_CARD.md from it, simulating nothing",
    )
    args = parser.parse_args()
    if args.factors:
        factors(args.workers)
        return
    if args.repeatability:
        repeatability(args.workers)
        return
    if args.record is not None:
        record(json.loads(args.record.read_text())["result"])
        return
    SEEDS["fresh"] = args.fresh_seeds
    units = run_units(args.units, args.workers)
    result = report(units)
    args.out.write_text(json.dumps({"result": result, "units": units}, indent=1))
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
