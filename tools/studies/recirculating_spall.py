"""A nut-flank spall on a recirculating PRSM against the reset comb on the same line.

    python tools/studies/recirculating_spall.py [--units 24] [--workers 2]
        [--baseline-spread 0.05]

Both the resets and a nut-flank spall strike once per roller passage, N·f_c: the comb is in
every recording. Each unit (the paper03 preset at paper 03's 40π rad/s; load 20–60 kN, thread
half-clearance 3–10 µm, 0.1 s) is simulated by prsm_health.simulation.recirculating and measured
by the flight-ema axial accelerometer (20 kHz, its noise and band; the axial model has no
lateral motion, so the cross-axis inputs are zero). Half the units have a spall (angle anywhere
on the rollers' path, 1–3 mm long, 10–30 µm deep), each unit its own seed.

Indicator (the doublet): the time-synchronous average of the measured nut acceleration over the
roller-passage period T_p = 2π/(N·ω_c), phased on the resets (roller 1 enters the threadless
area at t = 0); the share of its energy outside the resets' window (the passage of the
threadless area and its ringing). A healthy unit has one pulse per period, a spalled unit a
second one — unless the spall lies at the resets' phase: then the same line, the same phase,
and one recording at one load cannot tell them apart (a second load would: the platform's
impact does not feel the load, the spall's does).

Prints AUC (all units; units whose spall lies outside the resets' window) and the indicator
per unit (JSON).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
from concurrent.futures import ProcessPoolExecutor
from functools import partial

import numpy as np

SPEED = 40 * math.pi
DURATION = 0.1
SETTLED = 0.02  # s: the load ramp and the start's ringing left out
BINS = 100
#: The resets' window in the passage period: the threadless area's passage (2β/ω_c ≈ 0.19 of
#: T_p for the preset) and the ringing after it.
RESET_WINDOW = (0.0, 0.45)


def _tsa(design, load, clearance, spall, sensor_seed):
    """The measured nut acceleration's synchronous average over the passage period, phased on
    the resets (BINS bins), and the run's energy error."""
    from prsm_health.simulation.instrumentation import load_instrumentation
    from prsm_health.simulation.recirculating import simulate_recirculating

    run = simulate_recirculating(
        design,
        screw_speed=SPEED,
        load=load,
        duration=DURATION,
        clearance=clearance,
        nut_spall=spall,
    )
    profile = load_instrumentation("flight-ema")
    accel_only = dataclasses.replace(
        profile, **{c: None for c in profile.fitted if c != "nut_axial_accel"}
    )
    zero = np.zeros_like(run.nut_acceleration)
    truth = {
        "nut_axial_accel": run.nut_acceleration,
        "nut_tangential_accel": zero,
        "nut_radial_x_accel": zero,
        "nut_radial_y_accel": zero,
    }
    rate = 1.0 / (run.time[1] - run.time[0])
    a = accel_only.measure(truth, rate, np.random.default_rng(sensor_seed))["nut_axial_accel"]
    t = np.arange(len(a)) / accel_only.sample_rate
    keep = t >= SETTLED
    period = 2 * math.pi / (design.n_rollers * abs(float(np.mean(run.carrier_speed))))
    bins = np.minimum(((t[keep] / period) % 1.0 * BINS).astype(int), BINS - 1)
    tsa = np.bincount(bins, weights=a[keep], minlength=BINS) / np.bincount(bins, minlength=BINS)
    return tsa - tsa.mean(), run.energy_error


def unit(job, spread=0.05):
    from prsm_health.actuator.design import preset
    from prsm_health.physics.recirculating import orbital_angle
    from prsm_health.simulation.recirculating import NutSpall

    seed, spalled = job
    rng = np.random.default_rng(seed)
    design = preset("paper03")
    load = float(rng.uniform(20e3, 60e3))
    clearance = float(rng.uniform(3e-6, 10e-6))
    spall = None
    if spalled:
        spall = NutSpall(
            angle=float(rng.uniform(0.0, 2 * math.pi)),
            length=float(rng.uniform(1e-3, 3e-3)),
            depth=float(rng.uniform(10e-6, 30e-6)),
        )
    # the unit's own baseline: healthy, at a load within ±spread of today's (a health check
    # commands its load: a small spread), other sensor noise
    baseline_load = load * float(rng.uniform(1.0 - spread, 1.0 + spread))
    baseline, _ = _tsa(design, baseline_load, clearance, None, [seed, 2])
    tsa, energy_error = _tsa(design, load, clearance, spall, [seed, 1])
    energy = tsa**2
    centres = (np.arange(BINS) + 0.5) / BINS
    outside = ~((centres >= RESET_WINDOW[0]) & (centres < RESET_WINDOW[1]))
    share = float(energy[outside].sum() / energy.sum())
    change = float(np.sum((tsa - baseline) ** 2) / np.sum(baseline**2))
    spall_phase = None
    if spall is not None:
        # where its pulse falls in the passage period, from the threadless area's entrance
        entry = -orbital_angle(design)
        spall_phase = ((spall.angle - entry) / (2 * math.pi / design.n_rollers)) % 1.0
    return {
        "seed": seed,
        "spall": spalled,
        "load": load,
        "off_reset_share": share,
        "change_from_baseline": change,
        "spall_phase": spall_phase,
        "energy_error": energy_error,
    }


def auc(healthy, faulty) -> float:
    """ROC AUC of the faulty against the healthy values: P(faulty > healthy), ties half."""
    from sklearn.metrics import roc_auc_score

    h, f = np.asarray(healthy, float), np.asarray(faulty, float)
    return float(roc_auc_score(np.r_[np.zeros(len(h)), np.ones(len(f))], np.r_[h, f]))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--units", type=int, default=24, help="units of each class")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--baseline-spread",
        type=float,
        default=0.05,
        help="the baseline's load within ±this share of today's (a check commands its load)",
    )
    args = parser.parse_args()
    jobs = [(7000 + k, k % 2 == 1) for k in range(2 * args.units)]
    with ProcessPoolExecutor(args.workers) as pool:
        units = list(pool.map(partial(unit, spread=args.baseline_spread), jobs))
    healthy = [u["off_reset_share"] for u in units if not u["spall"]]
    spalled = [u for u in units if u["spall"]]
    apart = [u for u in spalled if not (RESET_WINDOW[0] <= u["spall_phase"] < RESET_WINDOW[1])]
    change_healthy = [u["change_from_baseline"] for u in units if not u["spall"]]
    result = {
        "units_each": args.units,
        "baseline_spread": args.baseline_spread,
        "auc_all": auc(healthy, [u["off_reset_share"] for u in spalled]),
        "auc_spall_outside_reset_window": auc(healthy, [u["off_reset_share"] for u in apart]),
        "auc_change_from_own_baseline": auc(
            change_healthy, [u["change_from_baseline"] for u in spalled]
        ),
        "spalled_outside_window": len(apart),
        "healthy_share_max": max(healthy),
        "largest_energy_error": max(u["energy_error"] for u in units),
        "units": units,
    }
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
