"""Benchmark the recirculating PRSM's dynamic model against the baselines a user would write.

Measured in one run, paper 03's §4.2 case (the paper03 preset, 12 rollers, 40π rad/s, 20 kN):

1. prsm_health's guarded fixed-step RK4 (numba, 2 µs outer steps, sub-stepped through every
   cam impact): wall seconds per simulated second, after compilation;
2. scipy ``solve_ivp`` with LSODA (the stiff solver a user reaches for with the paper's
   damping-dominated IMPACT contact; rtol 1e-6) driving the *same* numba right-hand side;
3. the standard PRSM of the same size of run (paper01, 7 rollers, 100 rad/s, 100 N, ideal
   sensors) through ``simulate``: the cost the recirculating model is compared with.

    python tools/bench/bench_recirculating.py [--duration 0.05]

Prints a Markdown table for docs/performance.md.
"""

from __future__ import annotations

import argparse
import math
import time

from scipy.integrate import solve_ivp

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.actuator.design import preset
from prsm_health.simulation.recirculating import right_hand_side, simulate_recirculating

SPEED, LOAD = 40 * math.pi, 2e4


def timed(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--duration", type=float, default=0.05, help="simulated seconds")
    args = parser.parse_args()
    design = preset("paper03")
    simulate_recirculating(design, screw_speed=SPEED, load=LOAD, duration=0.002)  # compile
    ours = timed(
        lambda: simulate_recirculating(design, screw_speed=SPEED, load=LOAD, duration=args.duration)
    )
    f, y0 = right_hand_side(design, screw_speed=SPEED, load=LOAD)
    f(0.0, y0)  # compile its call from Python before the clock runs
    scipy_span = min(args.duration, 0.01)  # LSODA is slow: a shorter span, scaled
    lsoda = timed(
        lambda: solve_ivp(f, (0.0, scipy_span), y0, method="LSODA", rtol=1e-6, atol=1e-12)
    ) * (args.duration / scipy_span)
    simulate("paper01", HealthState(), OperatingProfile(duration=0.005, speed=100.0), "ideal")
    standard = timed(
        lambda: simulate(
            "paper01",
            HealthState(),
            OperatingProfile(duration=args.duration, speed=100.0, load=100.0),
            "ideal",
        )
    )
    per = 1.0 / args.duration
    print(f"simulated {args.duration:g} s; wall seconds per simulated second:\n")
    print("| engine | wall s / simulated s |")
    print("|---|---|")
    print(f"| recirculating, guarded RK4 (numba) | {ours * per:.2f} |")
    print(f"| recirculating, scipy LSODA, same right-hand side | {lsoda * per:.1f} |")
    print(f"| standard PRSM (paper01), `simulate`, ideal sensors | {standard * per:.2f} |")


if __name__ == "__main__":
    main()
