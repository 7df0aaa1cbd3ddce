"""The reset-comb indicators (prsm_health.signals.reset_comb) on simulated recirculating units.

    python tools/studies/reset_comb_indicators.py [--units 10] [--workers 2] [--seed 9100]

Each unit: the paper03 preset at paper 03's 40π rad/s, thread half-clearance 3–10 µm, no
payload, simulated by prsm_health.simulation.recirculating; half the units carry a nut-flank
spall (angle anywhere on the rollers' path, 1–3 mm long, 10–30 µm deep, on every engaged turn),
each unit its own seed. Measured by the flight-ema instrumentation (its resolver on the motor
shaft through the drive train's reduction, its ADXL1002 axial accelerometer at 20 kHz; the axial
model has no lateral motion, so the cross-axis inputs are zero) twice: as it is, and with the
accelerometer's ±50 g range lifted — the simulated resets ring the nut at 2–5 km/s², so the
ADXL1002 clips a third of the samples. The first 20 ms of every run (the model's start, its
load ramp ringing at 3× the steady level) are left out of the recording.

1. **Same load.** 20 kN, 0.1 s recorded: each indicator's AUC healthy vs spalled (> 0.5:
   higher for the spalled units; over all spalls, and over the spalls whose strike falls
   outside the reset window), the two-sided AUC (distance from the healthy units' median: a
   spall that moves an indicator either way counts), and each class's median and range.
2. **Reversing load.** Load knots 0 plus a 20 kN, 10 Hz sine, 0.2 s recorded, with a load cell
   (the lab rig's strain-gauge cell, its span widened to ±50 kN; flight-ema has none): the
   same table; comb_load_slope is the one this measurement is for.

Prints one JSON document (per-unit values under "units"). ≈ 1.5 s of CPU per unit.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np

SPEED = 40 * math.pi
LOAD = 20e3
DURATION = 0.1
#: Simulated before the recording starts [s]: the model starts unloaded and its 5 ms load ramp
#: rings the nut at 3× the steady level for ≈ 10 ms (tools/studies/recirculating_spall.py
#: leaves out as much) — a start-up of the model, not of a unit in service.
SETTLED = 0.02
REVERSING = {"load": np.array([[0.0, 0.22], [0.0, 0.0]]), "load_sine": (20e3, 10.0)}
REVERSING_DURATION = 0.2
#: The load cell's span [N] for the reversing measurement: the lab rig's cell is ±2 kN.
LOAD_CELL_SPAN = 1e5
#: The usable band as a share of the sample rate (the feature table's SEARCH_SHARE).
BAND_SHARE = 0.45
#: The accelerometers measured through: flight-ema's ADXL1002 as it is (±50 g) and the same
#: without its range — the simulated resets ring the nut at 2–5 km/s², beyond ±50 g.
SENSORS = {"flight_ema": False, "flight_ema_unclipped": True}


def _measure(
    run, design, sensor_seed: int, with_load: bool, unclipped: bool = False
) -> dict[str, np.ndarray]:
    """The flight-ema channels the reset comb reads (nut_axial_accel, screw_angle, and a load
    cell's axial_load when ``with_load``), from a recirculating run's truth; ``unclipped``:
    the accelerometer without its ±50 g range (a sensor that does not saturate)."""
    from prsm_health.actuator.drive_train import DriveTrain
    from prsm_health.simulation.instrumentation import (
        bind_drive_train,
        load_instrumentation,
        sensor_rng,
    )

    profile = load_instrumentation("flight-ema")
    keep = {"nut_axial_accel", "screw_angle"}
    changes = {c: None for c in profile.fitted if c not in keep}
    if with_load:
        cell = load_instrumentation("lab-rig").axial_load
        changes["axial_load"] = dataclasses.replace(cell, full_scale=LOAD_CELL_SPAN)
    if unclipped:
        changes["nut_axial_accel"] = dataclasses.replace(profile.nut_axial_accel, range=0.0)
    profile = dataclasses.replace(profile, **changes)
    drive_train = DriveTrain()
    t = run.time
    zero = np.zeros_like(t)
    truth = {
        "motor_angle": drive_train.gear_ratio * run.screw_angle,
        "screw_angle": run.screw_angle,
        "nut_axial_accel": run.nut_acceleration,
        "nut_tangential_accel": zero,
        "nut_radial_x_accel": zero,
        "nut_radial_y_accel": zero,
        "axial_load": run.axial_load,
        "load_force": run.axial_load,
    }
    rate = 1.0 / (t[1] - t[0])
    # the model's 2 µs step: 500 kHz, 25 × the 20 kHz of the profile; the last sample dropped
    # so the record is whole 20 kHz samples
    n = (len(t) - 1) // 25 * 25
    truth = {k: v[:n] for k, v in truth.items()}
    out = bind_drive_train(profile, drive_train).measure(truth, rate, sensor_rng(sensor_seed))
    start = int(round(SETTLED * profile.sample_rate))
    return {k: v[start:] for k, v in out.items()}


def spall_phase(design, spall) -> float:
    """Where a spall's strike falls in the passage period [share], from the resets' entry: a
    roller enters the threadless area at orbital angle −β (forward rotation) and meets the
    spall (spall.angle + β)/ω_c later; rollers follow each other 2π/N apart."""
    from prsm_health.physics.recirculating import orbital_angle

    return ((spall.angle + orbital_angle(design)) / (2 * math.pi / design.n_rollers)) % 1.0


def unit(job) -> dict:
    """One unit's indicators at the same load and under the reversing load, through the
    flight-ema accelerometer as it is and without its range."""
    from prsm_health.actuator.design import preset
    from prsm_health.signals.reset_comb import reset_comb_indicators
    from prsm_health.simulation.recirculating import NutSpall, simulate_recirculating

    seed, spalled = job
    rng = np.random.default_rng(seed)
    design = preset("paper03")
    clearance = float(rng.uniform(3e-6, 10e-6))
    spall = None
    if spalled:
        spall = NutSpall(
            angle=float(rng.uniform(0.0, 2 * math.pi)),
            length=float(rng.uniform(1e-3, 3e-3)),
            depth=float(rng.uniform(10e-6, 30e-6)),
        )
    out = {
        "seed": seed,
        "clearance": clearance,
        "spall": dataclasses.asdict(spall) if spall else None,
        "spall_phase": spall_phase(design, spall) if spall else None,
    }
    same = simulate_recirculating(
        design,
        screw_speed=SPEED,
        load=LOAD,
        duration=SETTLED + DURATION,
        clearance=clearance,
        nut_spall=spall,
    )
    reversing = simulate_recirculating(
        design,
        screw_speed=SPEED,
        duration=SETTLED + REVERSING_DURATION,
        clearance=clearance,
        nut_spall=spall,
        **REVERSING,
    )
    for sensor, unclipped in SENSORS.items():
        channels = _measure(same, design, seed, False, unclipped)
        values = reset_comb_indicators(channels, design, BAND_SHARE)
        values["clipped_share"] = _clipped(channels, unclipped)
        out[f"same_load/{sensor}"] = values
        channels = _measure(reversing, design, seed + 1, True, unclipped)
        values = reset_comb_indicators(channels, design, BAND_SHARE)
        values["clipped_share"] = _clipped(channels, unclipped)
        out[f"reversing/{sensor}"] = values
    return out


def _clipped(channels, unclipped: bool) -> float:
    """Share of the acceleration's samples at the accelerometer's range [-]."""
    if unclipped:
        return 0.0
    from prsm_health.simulation.instrumentation import load_instrumentation

    limit = load_instrumentation("flight-ema").nut_axial_accel.range
    return float(np.mean(np.abs(channels["nut_axial_accel"]) >= (1 - 1e-9) * limit))


def auc(healthy, faulty) -> float:
    """P(a spalled unit's value > a healthy unit's) [-], ties counted half; NaNs left out."""
    h = np.asarray([v for v in healthy if np.isfinite(v)])
    f = np.asarray([v for v in faulty if np.isfinite(v)])
    if len(h) == 0 or len(f) == 0:
        return math.nan
    from sklearn.metrics import roc_auc_score

    return float(roc_auc_score(np.r_[np.zeros(len(h)), np.ones(len(f))], np.r_[h, f]))


def two_sided_auc(healthy, faulty) -> float:
    """:func:`auc` of the distance from the healthy units' median [-]: a fault that moves an
    indicator either way off the healthy population counts (each healthy unit measured from
    the median of the others, so it is not its own reference)."""
    h = np.asarray([v for v in healthy if np.isfinite(v)])
    f = np.asarray([v for v in faulty if np.isfinite(v)])
    if len(h) < 2 or len(f) == 0:
        return math.nan
    own = [abs(v - np.median(np.delete(h, i))) for i, v in enumerate(h)]
    return auc(own, np.abs(f - np.median(h)))


def _summary(values) -> dict:
    v = np.asarray([x for x in values if np.isfinite(x)])
    if len(v) == 0:
        return {"n": 0}
    return {
        "n": len(v),
        "median": float(np.median(v)),
        "min": float(v.min()),
        "max": float(v.max()),
    }


def main() -> None:
    from prsm_health.signals.reset_comb import RESET_COMB

    parser = argparse.ArgumentParser()
    parser.add_argument("--units", type=int, default=10, help="units of each class")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=9100, help="first unit's seed")
    args = parser.parse_args()
    jobs = [(args.seed + k, k % 2 == 1) for k in range(2 * args.units)]
    with ProcessPoolExecutor(args.workers) as pool:
        units = list(pool.map(unit, jobs))
    healthy = [u for u in units if u["spall"] is None]
    spalled = [u for u in units if u["spall"] is not None]
    from prsm_health.actuator.design import preset
    from prsm_health.signals.reset_comb import reset_window_share

    window = reset_window_share(preset("paper03"))
    apart = [u for u in spalled if u["spall_phase"] >= window]
    result: dict = {"units_each": args.units, "reset_window_share": window}
    result["spalled_outside_reset_window"] = len(apart)
    for key in [f"{m}/{s}" for m in ("same_load", "reversing") for s in SENSORS]:
        table = {}
        for name in [*RESET_COMB, "clipped_share"]:
            h = [u[key][name] for u in healthy]
            f = [u[key][name] for u in spalled]
            table[name] = {
                "auc": auc(h, f),
                "auc_spall_outside_window": auc(h, [u[key][name] for u in apart]),
                "auc_two_sided": two_sided_auc(h, f),
                "healthy": _summary(h),
                "spalled": _summary(f),
            }
        result[key] = table
    result["units"] = units
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
