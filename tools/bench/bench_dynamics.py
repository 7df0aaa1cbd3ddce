"""Benchmark the dynamics engine against the baselines a user would otherwise write.

Measured in one run, on the paper-01 design (7 rollers, 82 states), 100 rad/s, 100 N:

1. prsm_health's numba RK4 kernel, h = 5 µs (after compilation): simulated s per wall s;
2. scipy ``solve_ivp`` (RK45, rtol 1e-6) driving the *same* numba right-hand side;
3. the same RK4 loop with the right-hand side run as plain Python/numpy
   (``NUMBA_DISABLE_JIT=1``, a subprocess), i.e. the model without numba;
4. start-up of a fresh process (compilation cache): time to the first simulated step;
5. throughput of many independent runs on 1 and 2 worker processes.

    python tools/bench/bench_dynamics.py [--quick]

Prints a Markdown table for docs/performance.md.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor

from scipy.integrate import solve_ivp

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.actuator.design import preset
from prsm_health.simulation.dynamics.model import build_model, initial_state
from prsm_health.simulation.dynamics.simulate import integrate, right_hand_side

PROFILE = dict(speed=100.0, load=100.0)


def bench_kernel(duration: float) -> float:
    simulate(
        "paper01", HealthState(), OperatingProfile(duration=0.005, **PROFILE), "ideal"
    )  # compile
    model = build_model(
        preset("paper01"),
        HealthState(),
        OperatingProfile(duration=duration, **PROFILE),
        SimulationOptions(),
        0,
    )
    h = 5e-6
    n = int(duration / h)
    y = initial_state(model)
    t0 = time.perf_counter()
    integrate(model, y, h, n)  # what simulate() runs: the kernel on 20 ms at a time
    return duration / (time.perf_counter() - t0)


def bench_solve_ivp(duration: float) -> tuple[float, int]:
    model = build_model(
        preset("paper01"),
        HealthState(),
        OperatingProfile(duration=duration, **PROFILE),
        SimulationOptions(),
        0,
    )
    y0 = initial_state(model)
    # the kernel's right-hand side, the prescribed motor angle set from the motion at t
    f = right_hand_side(model)

    t0 = time.perf_counter()
    sol = solve_ivp(f, (0.0, duration), y0, method="RK45", rtol=1e-6, atol=1e-12)
    return duration / (time.perf_counter() - t0), sol.nfev


PURE_PYTHON = """
import time
from prsm_health import HealthState, OperatingProfile, SimulationOptions
from prsm_health.actuator.design import preset
from prsm_health.simulation.dynamics.model import build_model, initial_state
from prsm_health.simulation.dynamics.simulate import integrate
d = {duration}
m = build_model(preset("paper01"), HealthState(), OperatingProfile(duration=d, speed=100.0, load=100.0), SimulationOptions(), 0)
y = initial_state(m)
t0 = time.perf_counter()
integrate(m, y, 5e-6, int(d / 5e-6))
print(d / (time.perf_counter() - t0))
"""


def bench_pure_python(duration: float) -> float:
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run(
        [sys.executable, "-c", PURE_PYTHON.format(duration=duration)],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    return float(out.stdout.strip().splitlines()[-1])


STARTUP = """
import time; t0 = time.perf_counter()
from prsm_health import simulate, OperatingProfile
simulate("paper01", profile=OperatingProfile(duration=0.001))
print(time.perf_counter() - t0)
"""


def bench_startup() -> float:
    out = subprocess.run(
        [sys.executable, "-c", STARTUP], capture_output=True, text=True, check=True
    )
    return float(out.stdout.strip().splitlines()[-1])


def _one_run(seed: int) -> int:
    r = simulate("paper01", HealthState(), OperatingProfile(duration=0.2, **PROFILE), "ideal", seed)
    return len(r)


def bench_parallel(n_runs: int, workers: int) -> float:
    with ProcessPoolExecutor(workers) as pool:
        list(pool.map(_one_run, range(workers)))  # warm the workers (cache load)
        t0 = time.perf_counter()
        list(pool.map(_one_run, range(n_runs)))
        return n_runs / (time.perf_counter() - t0) * 60.0


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="shorter durations")
    args = parser.parse_args()
    d_kernel = 0.5 if args.quick else 2.0
    d_ivp = 0.01 if args.quick else 0.03
    d_py = 0.0005 if args.quick else 0.002

    kernel = bench_kernel(d_kernel)
    ivp, nfev = bench_solve_ivp(d_ivp)
    python = bench_pure_python(d_py)
    startup = bench_startup()
    runs_1 = bench_parallel(8 if args.quick else 16, 1)
    runs_2 = bench_parallel(8 if args.quick else 16, 2)

    print(
        f"machine: {os.cpu_count()} cores, numba kernel duration {d_kernel} s, solve_ivp {d_ivp} s ({nfev} RHS calls), pure Python {d_py} s\n"
    )
    print(
        "| method (paper01, 7 rollers, 100 rad/s) | simulated s per wall s | ratio to numba RK4 |"
    )
    print("|---|---|---|")
    print(f"| prsm_health numba RK4, h = 5 µs | {kernel:.3g} | 1 |")
    print(
        f"| scipy solve_ivp RK45 (rtol 1e-6), same numba RHS | {ivp:.3g} | {kernel / ivp:.0f}× slower |"
    )
    print(
        f"| same RK4, RHS as plain Python/numpy (no numba) | {python:.3g} | {kernel / python:.0f}× slower |"
    )
    print()
    print(
        f"fresh-process start-up to first simulated step (compilation cache warm): {startup:.2f} s"
    )
    print(
        f"0.2 s runs per minute: 1 process {runs_1:.0f}, 2 processes {runs_2:.0f} (scaling {runs_2 / runs_1:.2f}×)"
    )


if __name__ == "__main__":
    main()
