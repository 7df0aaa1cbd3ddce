"""Where the shifted axial frequency falls with the clearance, off the signature map.

Random operating points across the flight-EMA duty (docs/validation.md, "The shifted axial
frequency off the map"): screw speed 50–130 rad/s, a load reversing about a mean of ±5 % C_a
with a swing of 2–30 % C_a at 4–16 Hz through 10 ms ramps (C_a: the design's basic dynamic axial
load rating). Each point is simulated at the half-clearances b = 10, 20, 30 µm with one seed
(the same manufacturing variation and sensor errors for the three), the default drive train,
Hertzian flanks and the ``flight-ema`` instrumentation; 0.4 s, the last 0.3 s analysed by
:func:`prsm_health.signals.features.extract_features`. Per point and indicator: does it fall
strictly from 10 to 20 to 30 µm? The share of points where it does, for the tracked contact
frequency (``axial_contact_frequency``, :mod:`prsm_health.signals.axial_mode`) and the dominant
peak (``axial_dominant_frequency``) on the same runs, and the points where either fails.

    python tools/studies/axial_frequency_tracking.py [--points 100] [--seed 2024] [--workers 2]
        [--contact-law hertz] [--drive-trains default|spread]

``--drive-trains spread`` draws each point's payload (5–20 kg) and linkage stiffness
(2e7–1e8 N/m) as the reference recipe does; the indicators, as for a recording, are not told.
≈ 4 min for 100 points on 2 idle cores. The test (tests/signals/test_axial_mode.py) draws its own
points with another seed.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.physics.load_rating import load_ratings
from prsm_health.signals.axial_mode import duty_band
from prsm_health.signals.features import extract_features
from prsm_health.simulation.dynamics.model import SimulationOptions
from prsm_health.simulation.scenario import simulate

DESIGN = "paper01"
SPEEDS = (50.0, 130.0)  # rad/s
MEAN_SHARES = (-0.05, 0.05)  # of C_a
SWING_SHARES = (0.02, 0.30)  # of C_a
LOAD_FREQUENCIES = (4.0, 16.0)  # Hz
RAMP_TIME = 0.01  # s
CLEARANCES = (10e-6, 20e-6, 30e-6)  # m
DURATION = 0.4  # s
SETTLE = 0.1  # s left out of the analysis
INDICATORS = ("axial_contact_frequency", "axial_dominant_frequency")
PAYLOADS = (5.0, 20.0)  # kg, the reference recipe's spread (--drive-trains spread)
LINKAGES = (2e7, 1e8)  # N/m


def operating_points(n: int, seed: int, design=DESIGN, spread: bool = False) -> list[dict]:
    """``n`` operating points drawn uniformly over the duty: speed [rad/s], mean load and swing
    [N], load frequency [Hz], the simulation seed of the point and, with ``spread``, its
    payload [kg] and linkage stiffness [N/m] (else the default drive train's)."""
    rating = load_ratings(preset(design) if isinstance(design, str) else design).dynamic
    rng = np.random.default_rng(seed)
    default = DriveTrain()
    points = []
    for _ in range(n):
        point = {
            "speed": float(rng.uniform(*SPEEDS)),
            "load": float(rng.uniform(*MEAN_SHARES) * rating),
            "load_amplitude": float(rng.uniform(*SWING_SHARES) * rating),
            "load_frequency": float(rng.uniform(*LOAD_FREQUENCIES)),
            "seed": int(rng.integers(0, 2**31 - 1)),
            "payload_mass": default.payload_mass,
            "linkage_stiffness": default.linkage_stiffness,
        }
        if spread:
            point["payload_mass"] = float(rng.uniform(*PAYLOADS))
            point["linkage_stiffness"] = float(rng.uniform(*LINKAGES))
        points.append(point)
    return points


def indicators(point: dict, clearance: float, contact_law: str = "hertz") -> dict[str, float]:
    """The two axial-frequency indicators of one point at one half-clearance [m]."""
    profile = OperatingProfile(
        duration=DURATION,
        speed=point["speed"],
        load=point["load"],
        load_profile="reversing",
        load_amplitude=point["load_amplitude"],
        load_frequency=point["load_frequency"],
        load_ramp_time=RAMP_TIME,
    )
    run = simulate(
        DESIGN,
        HealthState.uniform(clearance),
        profile,
        "flight-ema",
        point["seed"],
        options=SimulationOptions(contact_law=contact_law),
        drive_train=DriveTrain(
            payload_mass=point["payload_mass"], linkage_stiffness=point["linkage_stiffness"]
        ),
    )
    tail = run.slice(int(SETTLE * run.sample_rate), len(run))
    values = extract_features(tail)
    return {name: values[name] for name in INDICATORS}


def _job(args):
    index, point, clearance, law = args
    return index, clearance, indicators(point, clearance, law)


def measure(points: list[dict], workers: int = 1, contact_law: str = "hertz") -> np.ndarray:
    """Indicator values, shape (points, clearances, indicators) [Hz]."""
    jobs = [(i, p, b, contact_law) for i, p in enumerate(points) for b in CLEARANCES]
    out = np.full((len(points), len(CLEARANCES), len(INDICATORS)), np.nan)
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            results = list(pool.map(_job, jobs, chunksize=3))
    else:
        results = [_job(job) for job in jobs]
    for i, b, values in results:
        out[i, CLEARANCES.index(b)] = [values[name] for name in INDICATORS]
    return out


def falls(values: np.ndarray) -> np.ndarray:
    """Per point (and indicator): strictly falling over the clearances (axis 1)."""
    return np.all(np.diff(values, axis=1) < 0, axis=1)


def reverses(point: dict) -> bool:
    """The load changes sign: a swing beyond the mean (else every roller stays on one flank
    and the clearance cannot change the frequency, docs/validation.md)."""
    return point["load_amplitude"] > abs(point["load"])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--seed", type=int, default=2024)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--contact-law", default="hertz", choices=("hertz", "linear"))
    parser.add_argument("--drive-trains", default="default", choices=("default", "spread"))
    args = parser.parse_args()
    design = preset(DESIGN)
    rating = load_ratings(design).dynamic
    points = operating_points(args.points, args.seed, spread=args.drive_trains == "spread")
    values = measure(points, args.workers, args.contact_law)
    ok = falls(values)
    reversing = np.array([reverses(p) for p in points])
    lo, hi = duty_band(design)
    print(
        f"{DESIGN}, C_a = {rating:.0f} N, contact band {lo:.0f}–{hi:.0f} Hz, "
        f"{args.contact_law} flanks, {args.drive_trains} drive trains, "
        f"{args.points} points (seed {args.seed})\n"
    )
    print(
        "| indicator | falls 10 → 20 → 30 µm | where the load reverses | "
        "mean change 10 → 30 µm [Hz] |"
    )
    print("|---|---|---|---|")
    for j, name in enumerate(INDICATORS):
        change = values[:, 2, j] - values[:, 0, j]
        print(
            f"| `{name}` | {ok[:, j].mean():.0%} ({ok[:, j].sum()}/{len(points)}) | "
            f"{ok[reversing, j].mean():.0%} ({ok[reversing, j].sum()}/{reversing.sum()}) | "
            f"{np.nanmean(change):+.1f} |"
        )
    print("\nPoints where either fails (values at 10/20/30 µm [Hz]):\n")
    print(
        "| speed [rad/s] | mean [% C_a] | swing [% C_a] | load freq. [Hz] | reverses | "
        + " | ".join(f"`{n}`" for n in INDICATORS)
        + " |"
    )
    print("|---|---|---|---|---|" + "---|" * len(INDICATORS))
    for i in np.flatnonzero(~np.all(ok, axis=1)):
        p = points[i]
        cells = [
            ("✓ " if ok[i, j] else "✗ ") + " / ".join(f"{v:.0f}" for v in values[i, :, j])
            for j in range(len(INDICATORS))
        ]
        print(
            f"| {p['speed']:.0f} | {100 * p['load'] / rating:+.1f} | "
            f"{100 * p['load_amplitude'] / rating:.1f} | {p['load_frequency']:.1f} | "
            f"{'yes' if reversing[i] else 'no'} | " + " | ".join(cells) + " |"
        )
    # by swing: where the clearance's share of the cycle is small, the shift is small
    swing = np.array([p["load_amplitude"] / rating for p in points])
    print(
        "\n| swing [% C_a] | points | `axial_contact_frequency` falls | dominant falls | "
        "contact change 10 → 30 µm [Hz] |"
    )
    print("|---|---|---|---|---|")
    for a, b in ((0.02, 0.10), (0.10, 0.20), (0.20, 0.30)):
        sel = (swing >= a) & (swing < b) & reversing
        if sel.any():
            change = values[sel, 2, 0] - values[sel, 0, 0]
            print(
                f"| {100 * a:.0f}–{100 * b:.0f} | {sel.sum()} | {ok[sel, 0].mean():.0%} | "
                f"{ok[sel, 1].mean():.0%} | {np.nanmedian(change):+.1f} (median) |"
            )


if __name__ == "__main__":
    main()
