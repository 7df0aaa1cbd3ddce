"""What a condensed fidelity (issue [5/5] item 2) may spend per step to be 4× (10×) faster than
the full model, and what RK4 at its larger step does to the measured band.

    python tools/studies/condensed_budget.py [--span 0.05]

For the acceptance check's steady duty (``prsm_health.validation.fidelity``: paper-01 PRSM in its
drive train, 20 % C_a, 100 rad/s, Hertzian flanks, seed 0) at each contact damping ratio of the
check:

1. **The full model's step** h_full (``max_step = "auto"``): what the condensed model must beat.
2. **The right-hand side's cost**: the kernel timed on the same model with its first k rollers
   (k = 1 … n), ``--span`` simulated seconds each at h = 1 µs; the slope over k is one roller's
   share of a right-hand side, the intercept everything else. A condensed right-hand side that
   still evaluates every roller's contacts (the clearances, the errors, the traction: the
   physics the check compares) costs at least the rollers' share.
3. **The budget**: at a condensed RK4 step H = 1/(m·f_s) (f_s = 20 kHz, the default output), the
   work allowed per step for a speed-up S is 4·(H/h_full)/S right-hand sides; RK4 itself takes 4.
4. **The band at H**: RK4 damps and detunes a mode at frequency f by its amplification
   R(iωH) (ω = 2πf): added damping ratio ζ = −ln|R|/(ωH), frequency error arg R/(ωH) − 1 — at
   3, 5 and 8 kHz, the acceptance check's band edges.

Timings are one core, best of ``--repeats``; this machine drifts ±15 % between minutes, so read
the ratios, not the absolute figures.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from prsm_health.simulation.dynamics.model import build_model, initial_state
from prsm_health.simulation.dynamics.simulate import (
    integrate,
    integration_step,
    max_stable_step,
)
from prsm_health.validation.fidelity import DAMPINGS, Case, case_scenario

SAMPLE_RATE = 20_000.0  # [Hz] the default instrumentation's output
TIMING_STEP = 1e-6  # [s] small enough to be stable with any roller count and damping
SPEED_UPS = (4.0, 10.0)  # the targets: at the default damping, at 0.1
BAND_EDGES = (3000.0, 5000.0, 8000.0)  # [Hz]


def steady_model(damping: float):
    """The acceptance check's steady case (seed 0) at ``damping``, as the kernel's Model."""
    s = case_scenario(Case("steady 20 % C_a", damping, 0, 0.1), {})
    return build_model(s.design, s.health, s.profile, s.options, s.seed, s.drive_train)


def _step_cost(model, span: float, repeats: int) -> float:
    """Wall seconds per RK4 step of the kernel on ``model`` (best of ``repeats``)."""
    n_steps = int(round(span / TIMING_STEP))
    best = math.inf
    for _ in range(repeats):
        y = initial_state(model)
        t0 = time.perf_counter()
        integrate(model, y, TIMING_STEP, n_steps, record=False)
        best = min(best, time.perf_counter() - t0)
    return best / n_steps


def rhs_cost(model, span: float, repeats: int) -> tuple[float, float]:
    """(per-roller share, the rest) of one right-hand side [s], by a line through the kernel's
    cost per step with the first k rollers, k = 1 … n (a step is four right-hand sides)."""
    counts = np.arange(1, model.n_rollers + 1)
    per_rhs = [
        _step_cost(replace(model, rollers=model.rollers[:k].copy()), span, repeats) / 4.0
        for k in counts
    ]
    slope, intercept = np.polyfit(counts, per_rhs, 1)
    return float(slope), float(intercept)


def rk4_band_error(frequency: float, step: float) -> tuple[float, float]:
    """(added damping ratio, relative frequency error) of RK4 at ``step`` on an undamped mode."""
    z = 1j * 2.0 * math.pi * frequency * step
    r = 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24
    wh = abs(z)
    return -math.log(abs(r)) / wh, np.angle(r) / wh - 1.0


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--span", type=float, default=0.05, help="simulated s per timing")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    print("| contact damping | full model's step h_full | rhs per call (rollers' share) |")
    print("|---|---|---|")
    steps = {}
    for damping in DAMPINGS:
        model = steady_model(damping)
        h_stable, f_max = max_stable_step(model)
        h_full, _ = integration_step("auto", h_stable, f_max, SAMPLE_RATE)
        steps[damping] = h_full
        per_roller, rest = rhs_cost(model, args.span, args.repeats)
        whole = rest + per_roller * model.n_rollers
        print(
            f"| {damping:g} | {1e6 * h_full:.2f} µs | {1e9 * whole:.0f} ns "
            f"({model.n_rollers} × {1e9 * per_roller:.0f} ns = "
            f"{100 * per_roller * model.n_rollers / whole:.0f} %) |"
        )

    print(
        "\nRight-hand sides a condensed RK4 step H may cost, for a speed-up S over the full model"
    )
    print("(RK4 itself takes 4; the rest is what the rollers' condensation may spend per step):\n")
    condensed = [1.0 / (m * SAMPLE_RATE) for m in (2, 3, 4)]
    head = " | ".join(f"H = {1e6 * H:.1f} µs" for H in condensed)
    print(f"| contact damping | S | {head} |")
    print("|---|---|" + "---|" * len(condensed))
    for damping in DAMPINGS:
        for target in SPEED_UPS:
            cells = " | ".join(f"{4.0 * H / steps[damping] / target:.1f}" for H in condensed)
            print(f"| {damping:g} | {target:g}× | {cells} |")

    print(
        "\nRK4 at the condensed step on an undamped mode: added damping ratio, frequency error:\n"
    )
    print("| H | " + " | ".join(f"{f / 1000:g} kHz" for f in BAND_EDGES) + " |")
    print("|---|" + "---|" * len(BAND_EDGES))
    for H in condensed:
        cells = []
        for f in BAND_EDGES:
            zeta, detune = rk4_band_error(f, H)
            cells.append(f"ζ + {100 * zeta:.2f} %, {100 * detune:+.2f} %")
        print(f"| {1e6 * H:.1f} µs | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
