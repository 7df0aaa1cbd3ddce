"""Diagnosis throughput against a plain Welch of the same channels, per signal-second.

    python tools/bench/bench_diagnosis.py [--rounds 9]

One 10 s recording at 20 kHz (the shipped default model's training sensors: every channel,
0.05 m/s² RMS accelerometer noise) and one built-in health check (``health-check``, flight-ema
sensors). Measured in one run, in interleaved rounds (each round times every stage once, so a
load change on the shared machine hits all stages alike):

* **plain Welch** — what a user would otherwise write: ``scipy.signal.welch`` (Hann, 1024
  samples, 75 % overlap) of every measured channel of each window the diagnosis reads, one
  call per channel (the brief's baseline), and the stricter form: one call per window on the
  channels stacked;
* **diagnose** — ``diagnose(run)`` of the recording (cut into the model's windows, every
  window's indicators in one batch, the model, the aggregate; the check read phase by phase);
* the parts: the indicators alone (batched, and window by window), the model alone, and
  window by window as ``replay`` and the service diagnose (streaming).

Printed: the median over the rounds and the range (min – max) of signal-seconds per wall
second, and of each round's ratio to the plain Welch of the same round.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy import signal

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.actuator.health_check import BUILT_IN
from prsm_health.diagnostics.diagnosis import (
    diagnose,
    diagnose_indicators,
    diagnose_window,
    load_bundle,
    split_windows,
)

AXES = ("axial", "tangential", "radial_x", "radial_y")
NPERSEG = 1024


def recording():
    return simulate(
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


def welch_per_channel(parts) -> None:
    for p in parts:
        for x in p.channels.values():
            signal.welch(x, fs=p.sample_rate, nperseg=NPERSEG, noverlap=3 * NPERSEG // 4)


def welch_stacked(parts) -> None:
    for p in parts:
        stacked = np.stack(list(p.channels.values()))
        signal.welch(stacked, fs=p.sample_rate, nperseg=NPERSEG, noverlap=3 * NPERSEG // 4)


def summary(values, digits: int = 1) -> str:
    return f"{statistics.median(values):.{digits}f} ({min(values):.{digits}f} – {max(values):.{digits}f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9)
    args = parser.parse_args()

    run = recording()
    check = simulate(
        "paper01", None, OperatingProfile(check=BUILT_IN["health-check"]), "flight-ema", 3
    )
    bundle = load_bundle()
    parts, _ = split_windows(run, bundle.window)
    seconds = len(run) / run.sample_rate
    check_seconds = len(check) / check.sample_rate
    check_parts, _ = split_windows(check, bundle.window)
    rows = bundle.indicators_batch(parts)
    # warm-up: numba's cached kernels, the contact modes, the thread pools
    diagnose(run, bundle)
    diagnose(check, bundle)

    stages = {
        "welch": lambda: welch_per_channel(parts),
        "welch stacked": lambda: welch_stacked(parts),
        "diagnose": lambda: diagnose(run, bundle),
        "indicators": lambda: bundle.indicators_batch(parts),
        "indicators one by one": lambda: [bundle.indicators(p) for p in parts],
        "model": lambda: diagnose_indicators(rows, bundle),
        "streaming": lambda: [diagnose_window(p, bundle) for p in parts],
        "check welch": lambda: welch_per_channel(check_parts),
        "check welch stacked": lambda: welch_stacked(check_parts),
        "check diagnose": lambda: diagnose(check, bundle),
    }
    times: dict[str, list[float]] = {name: [] for name in stages}
    for _ in range(args.rounds):
        for name, stage in stages.items():
            t0 = time.perf_counter()
            stage()
            times[name].append(time.perf_counter() - t0)

    def rate(name, length=seconds):
        return [length / t for t in times[name]]

    def ratio(name, floor):  # of the same round
        return [f / t for f, t in zip(times[floor], times[name])]

    print(
        f"{seconds:g} s at {run.sample_rate:g} Hz, {len(run.channels)} channels, cut into "
        f"{len(parts)} windows of {bundle.window:g} s (the model's); health check "
        f"{check_seconds:.2f} s, {len(check.channels)} channels; {args.rounds} interleaved "
        "rounds: median (min – max)\n"
    )
    print(
        "| stage | signal-seconds per second | × plain Welch (one call per channel) | × plain Welch (channels stacked) |"
    )
    print("|---|---|---|---|")
    print(f"| plain Welch, one call per channel and window | {summary(rate('welch'))} | 1 | |")
    print(f"| plain Welch, one call per window | {summary(rate('welch stacked'))} | | 1 |")
    for name, words in (
        ("diagnose", "`diagnose` of the recording"),
        ("indicators", "indicators only, all windows batched"),
        ("indicators one by one", "indicators only, window by window"),
        ("streaming", "indicators + model window by window (streaming)"),
    ):
        print(
            f"| {words} | {summary(rate(name))} | {summary(ratio(name, 'welch'), 2)} "
            f"| {summary(ratio(name, 'welch stacked'), 2)} |"
        )
    print(
        f"| `diagnose` of the health check (phase by phase) | "
        f"{summary(rate('check diagnose', check_seconds))} | "
        f"{summary(ratio('check diagnose', 'check welch'), 2)} | "
        f"{summary(ratio('check diagnose', 'check welch stacked'), 2)} |"
    )
    ms = [1e3 * t / len(parts) for t in times["model"]]
    print(f"\nmodel alone: {summary(ms, 2)} ms per window in a batch of {len(parts)}")
    check_ms = [1e3 * t for t in times["check diagnose"]]
    print(f"health check: {summary(check_ms)} ms per diagnosis")


if __name__ == "__main__":
    main()
