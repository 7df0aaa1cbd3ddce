"""Fault signatures at light load and at realistic duty, measured on the flight-ema channels.

Re-measures, with the package's own simulation and signal tools, the signatures that a monitor
can read where it should look (issue [2/5], docs/faults.md "At realistic duty"):

* nut and roller spalls — time-synchronous average (TSA) of the measured nut axial acceleration
  on the measured screw angle, over one nut pass (a carrier turn over the number of rollers:
  every roller passes a nut spall once per carrier turn) and one roller spin relative to the
  carrier (roller spall); SNR = energy of the TSA over the energy of the residual (the
  periodic-vs-residual ratio: what repeats at the period against what does not);
* preload loss — spectral centroid 200–3000 Hz of the nut axial acceleration at no load (the
  nut's axial resonance on its threads softens as the preload goes);
* lost motion under a slow load reversal — the ``lost_motion`` indicator of
  :func:`prsm_health.signals.features.extract_features` (LVDT against resolver);
* lubricant — ratio of the mean drive torque at 10 and 100 rad/s under one load (no load cell,
  no torque constant needed);
* the same four read from the phases of the built-in health check
  (:mod:`prsm_health.actuator.health_check`), one check per unit and seed.

Loads as shares of the design's dynamic rating C_a (:mod:`prsm_health.physics.load_rating`).

    python tools/studies/duty_signatures.py [--seeds 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np
from scipy.signal import welch

from prsm_health.actuator.design import preset
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.core.quantities import force_newtons
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings
from prsm_health.signals.features import extract_features
from prsm_health.signals.gear_indicators import time_synchronous_average
from prsm_health.simulation.scenario import simulate

DESIGN = preset("paper01")
RATINGS = {"C_a": load_ratings(DESIGN).dynamic, "C_0a": load_ratings(DESIGN).static}
LIGHT = 300.0  # N: the former recipes' level, ≈ 3 % of C_a
DUTIES = {"light 300 N": LIGHT, "20 % C_a": "20 % C_a", "40 % C_a": "40 % C_a"}


def newtons(load) -> float:
    return force_newtons(load, RATINGS)


def tsa_snr(x: np.ndarray, angle: np.ndarray, period: float) -> float:
    """Energy of the TSA (what repeats at the period) over the energy of the residual (what
    does not): the periodic-vs-residual ratio of a synchronous average."""
    tsa, periods = time_synchronous_average(x - np.mean(x), angle, period, 256)
    if periods.shape[0] < 2:
        return math.nan
    return float(np.var(tsa) / np.var(periods - tsa))


def spall_table(seeds: int) -> list[dict]:
    ratios = speed_ratios(DESIGN)
    periods = {
        # every roller passes a nut spall once per carrier turn: n_R passes per turn
        "nut": 2 * math.pi / abs(ratios.carrier) / DESIGN.n_rollers,
        "roller": 2 * math.pi / abs(ratios.roller_spin - ratios.carrier),
    }
    cases = {
        "healthy": (),
        "nut": ({"kind": "spall", "location": "nut"},),
        "roller": ({"kind": "spall", "location": "roller"},),
    }
    rows = []
    for duty, load in DUTIES.items():
        for case, faults in cases.items():
            snr = {k: [] for k in periods}
            for seed in range(seeds):
                run = simulate(
                    DESIGN,
                    HealthState(faults=faults),
                    OperatingProfile(duration=0.5, speed=100.0, load=newtons(load)),
                    "flight-ema",
                    seed=100 + seed,
                )
                x, angle = run["nut_axial_accel"], run["screw_angle"]
                for k, period in periods.items():
                    snr[k].append(tsa_snr(x, angle, period))
            rows.append({"duty": duty, "case": case, **{f"snr_{k}": v for k, v in snr.items()}})
    return rows


def centroid(run, low=200.0, high=3000.0) -> float:
    f, p = welch(run["nut_axial_accel"], fs=run.sample_rate, nperseg=2048)
    band = (f >= low) & (f <= high)
    return float(np.sum(f[band] * p[band]) / np.sum(p[band]))


def preloaded(lost: float) -> HealthState:
    faults = ({"kind": "preload_loss", "fraction": lost},) if lost else ()
    return HealthState(
        clearance_screw=0.0, clearance_nut=0.0, clearance_gear=10e-6, preload=5e-6, faults=faults
    )


def preload_table(seeds: int) -> list[dict]:
    rows = []
    for lost in (0.0, 0.6, 1.0):
        resonance, lost_motion = [], []
        for seed in range(seeds):
            run = simulate(
                DESIGN,
                preloaded(lost),
                OperatingProfile(duration=0.3, speed=100.0, load=0.0),
                "flight-ema",
                seed=200 + seed,
            )
            resonance.append(centroid(run))
            reversal = OperatingProfile(
                duration=1.0,
                speed=20.0,
                load=0.0,
                load_profile="reversing",
                load_amplitude=newtons("30 % C_a"),
                load_frequency=1.0,
                load_ramp_time=0.2,
                load_ramp_shape="cosine",
            )
            run = simulate(DESIGN, preloaded(lost), reversal, "flight-ema", seed=200 + seed)
            lost_motion.append(float(extract_features(run)["lost_motion"]))
        rows.append({"preload_lost": lost, "centroid_hz": resonance, "lost_motion_m": lost_motion})
    return rows


def lubricant_table(seeds: int) -> list[dict]:
    rows = []
    for degradation in (0.0, 1.0):
        ratio = []
        for seed in range(seeds):
            torque = {}
            for speed in (10.0, 100.0):
                profile = OperatingProfile(duration=0.3, speed=speed, load=newtons("20 % C_a"))
                run = simulate(
                    DESIGN,
                    HealthState(lubricant_degradation=degradation),
                    profile,
                    "flight-ema",
                    seed=300 + seed,
                )
                torque[speed] = float(np.mean(run["drive_torque"][len(run) // 3 :]))
            ratio.append(torque[10.0] / torque[100.0])
        rows.append({"lubricant_degradation": degradation, "torque_ratio_10_100": ratio})
    return rows


#: Units run through the built-in health check: (name, health).
CHECK_UNITS = {
    "healthy": HealthState(),
    "nut spall": HealthState(faults=({"kind": "spall", "location": "nut"},)),
    "roller spall": HealthState(faults=({"kind": "spall", "location": "roller"},)),
    "preload 5 µm": preloaded(0.0),
    "preload 60 % lost": preloaded(0.6),
    "lubricant degraded": HealthState(lubricant_degradation=1.0),
}


def check_table(seeds: int) -> list[dict]:
    """Each phase of the built-in health check read for what it is there to show (flight-ema,
    the default drive train): the no-load centroid, the torque ratio between the low- and the
    high-speed stroke, the lost motion of the slow reversal, the TSA SNR of the high-load stroke."""
    ratios = speed_ratios(DESIGN)
    nut_pass = 2 * math.pi / abs(ratios.carrier) / DESIGN.n_rollers
    roller = 2 * math.pi / abs(ratios.roller_spin - ratios.carrier)
    rows = []
    for unit, health in CHECK_UNITS.items():
        values = {k: [] for k in ("centroid", "ratio", "lost", "snr_nut", "snr_roller")}
        for seed in range(seeds):
            run = simulate(
                DESIGN,
                health,
                OperatingProfile(check="health-check"),
                "flight-ema",
                seed=500 + seed,
            )
            phase = run.phases()
            values["centroid"].append(centroid(phase["no-load stroke"]))
            low = np.mean(np.abs(phase["low-speed stroke"]["drive_torque"]))
            high = np.mean(np.abs(phase["high-speed stroke"]["drive_torque"]))
            values["ratio"].append(float(low / high))
            values["lost"].append(float(extract_features(phase["slow reversal"])["lost_motion"]))
            loaded = phase["high-load stroke"]
            x, angle = loaded["nut_axial_accel"], loaded["screw_angle"]
            values["snr_nut"].append(tsa_snr(x, angle, nut_pass))
            values["snr_roller"].append(tsa_snr(x, angle, roller))
        rows.append({"unit": unit, **values})
    return rows


def _fmt(values) -> str:
    values = np.asarray(values, float)
    return f"{np.median(values):.3g} ({np.min(values):.3g}–{np.max(values):.3g})"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--json", help="write the tables as JSON")
    args = parser.parse_args(argv)
    print(f"paper01: C_a = {RATINGS['C_a']:.0f} N, C_0a = {RATINGS['C_0a']:.0f} N")
    tables = {
        "spalls": spall_table(args.seeds),
        "preload": preload_table(args.seeds),
        "lubricant": lubricant_table(args.seeds),
        "check": check_table(args.seeds),
    }
    print("\n| duty | unit | TSA SNR, nut pass (nut spall) | TSA SNR, roller spin (roller spall) |")
    print("|---|---|---|---|")
    for r in tables["spalls"]:
        print(f"| {r['duty']} | {r['case']} | {_fmt(r['snr_nut'])} | {_fmt(r['snr_roller'])} |")
    print("\n| preload lost | no-load centroid 200–3000 Hz [Hz] | lost motion, ±30 % C_a [µm] |")
    print("|---|---|---|")
    for r in tables["preload"]:
        lm = 1e6 * np.asarray(r["lost_motion_m"])
        print(f"| {r['preload_lost']:.0%} | {_fmt(r['centroid_hz'])} | {_fmt(lm)} |")
    print("\n| lubricant degradation | drive torque 10 / 100 rad/s at 20 % C_a |")
    print("|---|---|")
    for r in tables["lubricant"]:
        print(f"| {r['lubricant_degradation']:.0%} | {_fmt(r['torque_ratio_10_100'])} |")
    print(
        "\n| unit (built-in check) | no-load centroid [Hz] | torque 10 / 100 rad/s "
        "| lost motion, slow reversal [µm] | TSA SNR nut pass | TSA SNR roller spin |"
    )
    print("|---|---|---|---|---|---|")
    for r in tables["check"]:
        lost = 1e6 * np.asarray(r["lost"])
        print(
            f"| {r['unit']} | {_fmt(r['centroid'])} | {_fmt(r['ratio'])} | {_fmt(lost)} "
            f"| {_fmt(r['snr_nut'])} | {_fmt(r['snr_roller'])} |"
        )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(tables, f, indent=1)


if __name__ == "__main__":
    main()
