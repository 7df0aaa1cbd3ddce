"""Cost of the fault mechanisms and the lubrication regime in the dynamics, measured side by side.

paper-01 design, default drive train, ideal sensors, 100 rad/s, 100 N, 1 s runs (whole
`simulate`, compiled beforehand), two passes: paper 02's constant coefficient (the baseline),
the lubrication regime (the default: one table lookup per roller and stage), and the regime
with a nut spall or a ring-tooth crack (their tables read only when the run has one).

    python tools/bench/bench_fault_costs.py
"""

import time

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.actuator.faults import Spall, ToothCrack

CASES = {
    "constant μ (paper 02)": (HealthState(), SimulationOptions(lubrication="constant")),
    "lubrication regime (default)": (HealthState(), SimulationOptions()),
    "regime + spall": (HealthState(faults=(Spall(location="nut"),)), SimulationOptions()),
    "regime + tooth crack": (HealthState(faults=(ToothCrack(),)), SimulationOptions()),
}
PROFILE = OperatingProfile(duration=1.0, speed=100.0, load=100.0)


def main() -> None:
    for health, options in CASES.values():  # compile and fill the caches first
        simulate("paper01", health, OperatingProfile(duration=0.01), "ideal", 0, options=options)
    print("| pass | case | simulated s per wall s |\n|---|---|---|")
    for rep in range(2):
        for name, (health, options) in CASES.items():
            start = time.perf_counter()
            simulate("paper01", health, PROFILE, "ideal", 0, options=options)
            print(f"| {rep + 1} | {name} | {1.0 / (time.perf_counter() - start):.2f} |")


if __name__ == "__main__":
    main()
