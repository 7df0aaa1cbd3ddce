"""Does a Rosenbrock-W step with the rollers' contact damping implicit pass for the full model at
contact damping 0.1 and 0.2? (issue [5/5] item 2: the partition tools/studies/implicit_partition.py
rates best by its linear analysis, tried on the nonlinear model.)

    python tools/studies/rosenbrock_trial.py [--seeds 3] [--duration 0.3]

The acceptance check's two duties (``prsm_health.validation.fidelity``) at contact damping 0.1
and 0.2, ``--seeds`` seeds of ``--duration`` s each, settled as ``simulate`` does: the full
model's RK4 at its automatic step against ROS34PW2 (a four-stage, third-order Rosenbrock-W
method, Rang & Angermann 2005) whose W = I − γhJ holds each roller's 4×4 velocity block of J
only (``_rosenbrock_kernels.py``; a W-method keeps its order with any such block), the block
taken two ways:

- **at the step's state**, by one-sided differences (one column of every roller at once: rollers
  do not couple directly) — four extra right-hand sides a step;
- **loaded**: linearised once on the loaded flanks with every clearance closed
  (``simulate.linearised_jacobian``), kept in each roller's pocket frame and turned to X, Y at
  the step's carrier angle — no extra right-hand side.

Prints, per case and step, the seed means of the nut's true axial acceleration — RMS, band power
20 Hz–3 kHz and 3–8 kHz (Welch) — relative to RK4's, and the wall-time speed-up (the kernel only,
after a warm-up call). The acceptance check allows ±10 % below 3 kHz and ±20 % at 3–8 kHz.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _rosenbrock_kernels as K  # noqa: E402

from prsm_health.simulation.decimation import decimate  # noqa: E402
from prsm_health.simulation.dynamics import layout as L  # noqa: E402
from prsm_health.simulation.dynamics.model import (  # noqa: E402
    AUTO_STABLE_FRACTION,
    build_model,
    initial_state,
)
from prsm_health.simulation.dynamics.simulate import (  # noqa: E402
    integrate,
    linearised_jacobian,
    max_stable_step,
    settled_state,
)
from prsm_health.validation.fidelity import DUTIES, Case, case_scenario  # noqa: E402

#: Contact damping → the Rosenbrock steps tried [s] (the linear analysis' stable step ≈ 8 µs).
STEPS = {0.1: (4e-6, 5e-6), 0.2: (2e-6, 3e-6)}
SETTLE = 0.01  # [s] settled before t = 0 with RK4 (both methods start from the same state)


def loaded_blocks(model) -> np.ndarray:
    """Each roller's velocity block of the loaded, closed-clearance Jacobian in its pocket frame."""
    jac, free = linearised_jacobian(model)
    index = {j: k for k, j in enumerate(free)}
    nq = model.n_coordinates
    th_p = initial_state(model)[L.Q_THP]
    blocks = np.zeros((model.n_rollers, 4, 4))
    for i in range(model.n_rollers):
        first = nq + L.Q_ROLLER0 + L.ROLLER_DOF * i
        rows = [index[first + d] for d in range(L.ROLLER_DOF)]
        phi = th_p + model.rollers[i, L.R_PSI]
        c, s = math.cos(phi), math.sin(phi)
        q = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        blocks[i] = q.T @ jac[np.ix_(rows, rows)] @ q
    return blocks


def rosenbrock(model, y, h, n_steps, w_source, loaded):
    """(status, record) of ``n_steps`` Rosenbrock-W steps from ``y`` (updated in place)."""
    n, nr = model.n_state, model.n_rollers
    out = np.empty((n_steps, L.N_CHANNELS))
    vectors = [np.empty(n) for _ in range(7)]
    status, step = K.integrate(
        y, 0.0, h, n_steps, w_source, model.params, model.rollers, model.mesh_table,
        model.motion, model.load_knots, model.errors, loaded, out, *vectors,
        np.zeros(L.n_aux(nr)), np.zeros((nr, 4, 4)), np.zeros((nr, 4, 4)), np.zeros((4, 4)),
    )  # fmt: skip
    return status, out[:step]


def statistics(record: np.ndarray, h: float) -> np.ndarray:
    """RMS, band power 20 Hz–3 kHz and 3–8 kHz of the nut's true axial acceleration."""
    factor = max(1, round(1.0 / (h * 40_000.0)))
    x = decimate(record[:, L.C_NUT_AXIAL_ACCEL], factor)
    f, psd = signal.welch(x, 1.0 / (h * factor), nperseg=2048)
    return np.array(
        [np.std(x), psd[(f > 20) & (f < 3000)].sum(), psd[(f >= 3000) & (f < 8000)].sum()]
    )


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--duration", type=float, default=0.3)
    args = parser.parse_args()
    print("| duty | contact damping | method | step | RMS | band < 3 kHz | 3–8 kHz | speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    for duty in DUTIES:
        for damping, steps in STEPS.items():
            rows: dict[tuple, list] = {}
            for seed in range(args.seeds):
                s = case_scenario(Case(duty, damping, seed, args.duration), {})
                model = build_model(s.design, s.health, s.profile, s.options, s.seed, s.drive_train)
                loaded = loaded_blocks(model)
                h_rk4 = AUTO_STABLE_FRACTION * max_stable_step(model)[0]
                y0 = settled_state(model, h_rk4, SETTLE)
                t0 = time.perf_counter()
                record = integrate(model, y0.copy(), h_rk4, int(args.duration / h_rk4))
                rows.setdefault(("RK4 (the full model)", 0.0), []).append(
                    (statistics(record, h_rk4), time.perf_counter() - t0, h_rk4)
                )
                for h in steps:
                    for name, source in (
                        ("W at the step's state", K.W_FINITE_DIFFERENCES),
                        ("W loaded, turned", K.W_LOADED),
                    ):
                        rosenbrock(model, y0.copy(), h, 2, source, loaded)  # compiled
                        t0 = time.perf_counter()
                        status, record = rosenbrock(
                            model, y0.copy(), h, int(args.duration / h), source, loaded
                        )
                        wall = time.perf_counter() - t0
                        stats = statistics(record, h) if status == 0 else None
                        rows.setdefault((name, h), []).append((stats, wall, h))
            reference = rows[("RK4 (the full model)", 0.0)]
            base = np.mean([r[0] for r in reference], axis=0)
            base_wall = np.mean([r[1] for r in reference])
            for (name, _), runs in rows.items():
                step = np.mean([r[2] for r in runs])
                if any(r[0] is None for r in runs):
                    cells, speed = "diverged (non-finite state) | | ", "—"
                else:
                    rel = np.mean([r[0] for r in runs], axis=0) / base - 1.0
                    cells = " | ".join(f"{100 * v:+.0f} %" for v in rel)
                    speed = f"{base_wall / np.mean([r[1] for r in runs]):.1f}×"
                print(
                    f"| {duty} | {damping:g} | {name} | {1e6 * step:.2f} µs | {cells} | {speed} |"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
