"""Diagnosis throughput: windows per second for 1 s windows at 20 kHz (shipped default model).

    python tools/bench/bench_diagnosis.py

Measures, in one run, the indicators alone (window by window, and all windows in one
``indicators_batch`` call), indicators + model window by window (streaming: ``replay``, the
service) and all windows together (``diagnose`` of a recording), and the floor a user would
otherwise write: a plain ``scipy.signal.welch`` of every channel of each window (Hann, 1024
samples, 75 % overlap) and nothing else. Each stage is timed ``REPEATS`` times, the best kept
(the machine's other load only slows a run down).
"""

from __future__ import annotations

import time

import numpy as np
from scipy import signal

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.diagnostics.diagnosis import diagnose_indicators, load_bundle
from prsm_health.signals.features import windows

AXES = ("axial", "tangential", "radial_x", "radial_y")
REPEATS = 3


def main() -> None:
    run = simulate(
        "paper01",
        HealthState.uniform(20e-6),
        OperatingProfile(
            duration=10.0,
            load=0.0,
            load_profile="reversing",
            load_amplitude=300.0,
            load_frequency=10.0,
            accel_time=0.002,
        ),
        # the shipped model's training sensors: all channels, 0.05 m/s² RMS accelerometer noise
        # (5e-4 m/s²/√Hz over the 10 kHz band)
        {
            "profile": "ideal",
            **{f"nut_{a}_accel": {"noise_density": 5e-4} for a in AXES},
        },
        1,
        options=SimulationOptions(contact_law="hertz"),
    )
    parts = list(windows(run, 1.0))
    bundle = load_bundle()
    diagnose_indicators(bundle.indicators_batch(parts[:2]), bundle)  # warm-up (thread pools)

    def welch_floor():
        for p in parts:
            stacked = np.stack([p.channels[c] for c in p.channels])
            signal.welch(stacked, fs=p.sample_rate, nperseg=1024, noverlap=768, axis=-1)

    def streaming():
        for p in parts:
            diagnose_indicators([bundle.indicators(p)], bundle)

    def model_single():
        for row in rows:
            diagnose_indicators([row], bundle)

    rows = bundle.indicators_batch(parts)
    stages = {
        "floor": welch_floor,
        "indicators": lambda: [bundle.indicators(p) for p in parts],
        "indicators batched": lambda: bundle.indicators_batch(parts),
        "streaming": streaming,
        "batched": lambda: diagnose_indicators(bundle.indicators_batch(parts), bundle),
        "model": model_single,
        "model batched": lambda: diagnose_indicators(rows, bundle),
    }
    best = dict.fromkeys(stages, float("inf"))
    for _ in range(REPEATS):
        for name, stage in stages.items():
            t0 = time.perf_counter()
            stage()
            best[name] = min(best[name], time.perf_counter() - t0)
    n = len(parts)
    print(f"{n} windows of 1 s at 20 kHz (20,000 samples × {len(parts[0].channels)} channels)\n")
    print("| stage | windows per second |")
    print("|---|---|")
    print(f"| floor: scipy.signal.welch of every channel, nothing else | {n / best['floor']:.1f} |")
    print(f"| indicators only, window by window | {n / best['indicators']:.1f} |")
    print(f"| indicators only, {n} windows batched | {n / best['indicators batched']:.1f} |")
    print(f"| indicators + model, one window at a time (streaming) | {n / best['streaming']:.1f} |")
    print(f"| indicators + model, {n} windows batched | {n / best['batched']:.1f} |")
    print(
        f"\nmodel alone: {1e3 * best['model'] / n:.1f} ms per window, "
        f"{1e3 * best['model batched'] / n:.2f} ms per window batched"
    )


if __name__ == "__main__":
    main()
