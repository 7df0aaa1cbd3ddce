"""Diagnosis throughput: windows per second for 1 s windows at 20 kHz (shipped default model).

    python tools/bench_diagnosis.py

Measures, in one run, (a) the indicators alone, (b) indicators + model (the full
`diagnose_indicators` path) per window, (c) a batch of windows through the model at once, and
the floor a user would otherwise write: a plain ``scipy.signal.welch`` of every channel of each
window (Hann, 1024 samples, 75 % overlap) and nothing else.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import signal

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.diagnosis import diagnose_indicators, load_bundle
from prsm_health.features import windows

AXES = ("axial", "tangential", "radial_x", "radial_y")


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
    diagnose_indicators([bundle.indicators(parts[0])], bundle)  # warm-up (thread pools)
    t0 = time.perf_counter()
    rows = [bundle.indicators(p) for p in parts]
    t_features = time.perf_counter() - t0
    t0 = time.perf_counter()
    for p in parts:
        stacked = np.stack([p.channels[c] for c in p.channels])
        signal.welch(stacked, fs=p.sample_rate, nperseg=1024, noverlap=768, axis=-1)
    t_welch = time.perf_counter() - t0
    t0 = time.perf_counter()
    for row in rows:
        diagnose_indicators([row], bundle)
    t_model_single = time.perf_counter() - t0
    t0 = time.perf_counter()
    diagnose_indicators(rows, bundle)
    t_model_batch = time.perf_counter() - t0
    n = len(parts)
    print(f"{n} windows of 1 s at 20 kHz (20,000 samples × {len(parts[0].channels)} channels)\n")
    print("| stage | windows per second |")
    print("|---|---|")
    print(f"| floor: scipy.signal.welch of every channel, nothing else | {n / t_welch:.1f} |")
    print(f"| indicators only | {n / t_features:.1f} |")
    print(
        f"| indicators + model, one window at a time (streaming) | {n / (t_features + t_model_single):.1f} |"
    )
    print(f"| indicators + model, {n} windows batched | {n / (t_features + t_model_batch):.1f} |")
    print(
        f"\nmodel alone: {1e3 * t_model_single / n:.1f} ms per window, {1e3 * t_model_batch / n:.2f} ms per window batched"
    )


if __name__ == "__main__":
    main()
