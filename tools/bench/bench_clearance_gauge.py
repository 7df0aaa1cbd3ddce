"""The clearance gauge's reading of one built-in health check, against the straightforward
chain a user would write: the thread term averaged over every settled sample.

    python tools/bench/bench_clearance_gauge.py [--rounds 7]

One built-in health check (paper01, flight-ema, 12 µm, seed 3) is read once for its reversals
(``check_indicators``); then, in interleaved rounds, the gauge reads them
(:meth:`~prsm_health.diagnostics.clearance_gauge.Gauge.read`: the compliance chain's thread
term from 64 quantiles of each reversal's load shares) and the straightforward form computes
the same chain with the thread term over all the settled samples
(:func:`~prsm_health.physics.stiffness.axial.axial_stiffness` on each sample's load). Printed:
the median and range of each, their ratio, and the two thread terms' relative difference.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.physics.stiffness.axial import axial_stiffness
from prsm_health.signals.check_indicators import check_indicators


def every_sample(gauge, reversals):
    """The thread term of each reversal over every settled sample (the straightforward chain)."""
    out = []
    for r in reversals:
        axial = axial_stiffness(gauge.design, r.load * r.load_shares)
        out.append(2.0 * float(np.mean(axial.deformation - axial.deformation_split["shaft"])))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    run = simulate(
        "paper01",
        HealthState.uniform(12e-6),
        OperatingProfile(check="health-check"),
        "flight-ema",
        3,
    ).without_truth()
    bundle = load_bundle()
    gauge = bundle.clearance_gauge
    reversals = check_indicators(run, bundle.design).reversals
    stages = {
        "gauge.read": lambda: gauge.read(reversals),
        "every sample": lambda: every_sample(gauge, reversals),
    }
    for stage in stages.values():  # warm caches (load ratings, thread geometry)
        stage()
    times = {name: [] for name in stages}
    for _ in range(args.rounds):
        for name, stage in stages.items():
            start = time.perf_counter()
            stage()
            times[name].append(time.perf_counter() - start)
    for name, values in times.items():
        print(
            f"{name:14s} median {1e3 * statistics.median(values):8.1f} ms "
            f"({1e3 * min(values):.1f} – {1e3 * max(values):.1f})"
        )
    ratios = [b / a for a, b in zip(times["gauge.read"], times["every sample"])]
    print(f"every sample / gauge.read: {min(ratios):.0f}–{max(ratios):.0f}×")
    exact = every_sample(gauge, reversals)
    quick = [gauge.chain(r).thread_contacts for r in reversals]
    worst = max(abs(q - e) / e for q, e in zip(quick, exact))
    print(f"thread term from 64 quantiles against every sample: {worst:.1e} relative")


if __name__ == "__main__":
    main()
