"""Map which clearance indicator responds monotonically where (docs/validation.md).

Regimes × screw speeds × mean loads × clearances, each run with the default drive train and the
default instrumentation (``flight-ema``: what a flight actuator measures), indicators from
:func:`prsm_health.signals.features.extract_features` over the last 0.3 s of 0.4 s. For every regime and
operating point, the Spearman rank correlation ρ between the clearance b (5, 15, 25, 35 µm, two
seeds each) and each indicator: |ρ| ≥ 0.8 with the same sign at every operating point of a
regime is a usable monotone response there.

    python tools/studies/map_clearance_signatures.py [--workers 2]

Writes docs/figures/clearance_signature_map.png and prints the Markdown table.
"""

from __future__ import annotations

import argparse
import itertools
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import stats

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.signals.features import extract_features

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures" / "clearance_signature_map.png"
CLEARANCES = (5e-6, 15e-6, 25e-6, 35e-6)
SEEDS = (1, 2)
SPEEDS = (60.0, 100.0)
LOADS = (0.0, 100.0)
REVERSING = dict(load_profile="reversing", load_amplitude=300.0, load_frequency=10.0)
#: Regime → OperatingProfile fields (speed and mean load come from the grid).
REGIMES = {
    "steady": {},
    # mean load + 150 N ± 80 N: oscillating, never reversing
    "oscillating load ±80 N, 20 Hz": dict(
        load_profile="sinusoidal", load_amplitude=80.0, load_frequency=20.0, load_offset=150.0
    ),
    "reversing load, 2 ms edges": dict(REVERSING, accel_time=0.002),
    "reversing load, 10 ms ramps": dict(REVERSING, load_ramp_time=0.01),
    "reversing load, 20 ms cosine": dict(REVERSING, load_ramp_time=0.02, load_ramp_shape="cosine"),
    "reversing motion, position loop": dict(
        motion="reversing", motion_period=0.2, accel_time=0.02, drive="position_loop"
    ),
}
INDICATORS = (
    "lost_motion",
    "torque_rattle_rate",
    "ax_rms",
    "ax_kurtosis",
    "axial_dominant_frequency",
    "drive_torque_ripple",
)


def _indicators(job):
    regime, speed, load, clearance, seed = job
    fields = dict(duration=0.4, speed=speed, load=load)
    fields.update(REGIMES[regime])
    fields["load"] = load + fields.pop("load_offset", 0.0)
    run = simulate(
        "paper01",
        HealthState.uniform(clearance),
        OperatingProfile(**fields),
        None,  # the default instrumentation
        seed,
        options=SimulationOptions(contact_law="hertz"),
    )
    tail = run.slice(int(0.1 * run.sample_rate), len(run))
    values = extract_features(tail)
    return job, {name: values[name] for name in INDICATORS}


def correlations(results) -> dict[tuple[str, float, float], dict[str, float]]:
    """Spearman ρ(b, indicator) per (regime, speed, load); NaN where the indicator is NaN."""
    grouped: dict = {}
    for (regime, speed, load, clearance, _), values in results:
        grouped.setdefault((regime, speed, load), []).append((clearance, values))
    out = {}
    for key, rows in grouped.items():
        b = np.array([r[0] for r in rows])
        out[key] = {}
        for name in INDICATORS:
            y = np.array([r[1][name] for r in rows], dtype=float)
            ok = np.isfinite(y)
            if ok.sum() < 6:  # not computable in this regime (e.g. lost motion without reversal)
                out[key][name] = np.nan
            elif np.ptp(y[ok]) == 0:  # computable, but the same for every clearance
                out[key][name] = 0.0
            else:
                out[key][name] = float(stats.spearmanr(b[ok], y[ok])[0])
    return out


def verdicts(rho) -> dict[str, dict[str, str]]:
    """Per regime and indicator: '↑' or '↓' when |ρ| ≥ 0.8 with one sign at every operating
    point, else the range of ρ."""
    table: dict = {}
    for regime in REGIMES:
        table[regime] = {}
        for name in INDICATORS:
            values = np.array(
                [rho[(regime, s, lo)][name] for s, lo in itertools.product(SPEEDS, LOADS)]
            )
            if np.any(np.isnan(values)):
                table[regime][name] = "not computable"
            elif np.all(values >= 0.8):
                table[regime][name] = f"↑ ({values.min():.2f})"
            elif np.all(values <= -0.8):
                table[regime][name] = f"↓ ({values.max():.2f})"
            else:
                table[regime][name] = f"{values.min():+.2f}…{values.max():+.2f}"
    return table


def plot(rho) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [(r, s, lo) for r in REGIMES for s, lo in itertools.product(SPEEDS, LOADS)]
    grid = np.array([[rho[k][name] for name in INDICATORS] for k in keys])
    fig, ax = plt.subplots(figsize=(9, 0.32 * len(keys) + 1.6))
    image = ax.imshow(grid, cmap="RdBu_r", vmin=-1, vmax=1, aspect="auto")
    ax.set_xticks(range(len(INDICATORS)), INDICATORS, rotation=30, ha="right", fontsize=8)
    labels = [f"{r} · {s:.0f} rad/s · {lo:.0f} N" for r, s, lo in keys]
    ax.set_yticks(range(len(keys)), labels, fontsize=7)
    for i, j in itertools.product(range(len(keys)), range(len(INDICATORS))):
        if np.isfinite(grid[i, j]):
            ax.text(j, i, f"{grid[i, j]:.2f}", ha="center", va="center", fontsize=6)
    fig.colorbar(image, ax=ax, label="Spearman ρ(b, indicator)")
    ax.set_title(
        "Clearance signatures, flight-ema instrumentation, default drive train", fontsize=9
    )
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    jobs = list(itertools.product(REGIMES, SPEEDS, LOADS, CLEARANCES, SEEDS))
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(_indicators, jobs, chunksize=4))
    rho = correlations(results)
    plot(rho)
    table = verdicts(rho)
    print("| regime | " + " | ".join(f"`{n}`" for n in INDICATORS) + " |")
    print("|---|" + "---|" * len(INDICATORS))
    for regime, row in table.items():
        print(f"| {regime} | " + " | ".join(row[n] for n in INDICATORS) + " |")
    print(f"\nwrote {OUT}")


if __name__ == "__main__":
    main()
