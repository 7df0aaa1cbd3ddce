"""Which states a linearly implicit step must treat implicitly to outrun the full model's RK4, and
what that step does to the measured band (issue [5/5] item 2: the design the condensed fidelity
cannot have — quasi-static rollers lose 4–6 in-band roller modes, tools/studies/mode_map.py —
replaced by one that keeps every state and integrates the stiff ones implicitly).

    python tools/studies/implicit_partition.py

The method: ROS34PW2, a four-stage, third-order Rosenbrock-W method (Rang & Angermann 2005,
BIT 45, 761–787; its coefficients as in PETSc's TSROSW and Hairer & Wanner's notation):

    (I − γ·h·Jᵢ)·kᵢ = h·f(y + Σⱼ aᵢⱼ·kⱼ) + h·Jᵢ·Σⱼ γᵢⱼ·kⱼ,   y⁺ = y + Σᵢ bᵢ·kᵢ

A W-method keeps its order with any matrix Jᵢ in place of the Jacobian, so Jᵢ can be the
Jacobian's blocks of the stiff states only (cheap to factor) and be kept over many steps. On the
model linearised at the acceptance check's steady case (``simulate.linearised_jacobian``: all
clearances closed, the stiffest state a run meets), f(y) = J·y, one step is y⁺ = R(h)·y with

    Kᵢ = (I − γhJᵢ)⁻¹·[h·J·(I + Σⱼ aᵢⱼKⱼ) + h·Jᵢ·Σⱼ γᵢⱼKⱼ],   R = I + Σᵢ bᵢKᵢ,

and for each partition (which states' blocks Jᵢ holds) this prints:

- **stable step**: the largest h with spectral radius ρ(R(h)) ≤ max(1, |e^{hλ}|) (bisection
  after a scan, as ``simulate.max_stable_step`` does for RK4), and the step the full model's
  rule would take (``AUTO_STABLE_FRACTION`` × ``STABILITY_MARGIN`` of it), at most 25 µs (the
  default output's 1/(2·f_s)), lowered until the band holds:
- **in-band error** at that step: every mode of J from 3 to 8 kHz (the acceptance check's upper
  band that rings (ζ < 0.5) against the eigenvalue of R nearest to it (as a rate, log μ / h): added damping ratio and
  frequency error, each within :data:`BAND_TOLERANCE`;
- **cost** per simulated second relative to the full model's RK4 at its own step, counting four
  right-hand sides per step, the block solves at 2 GFLOP/s (:func:`partitions` counts their
  flops) against the kernel's measured ≈ 1.07 µs per right-hand side, and the blocks refreshed
  by finite differences every
  ``--reuse`` steps (one right-hand side per column group: rollers do not couple directly, so
  one column of every roller's block is taken at once);
- **the bound**: the speed-up if the solves and Jacobians cost nothing (four right-hand sides a
  step, as RK4): the ratio of the steps; and the same for a method as accurate as RK4 in the
  band with no stability limit at all (the step at which RK4's own error on the band's modes
  reaches the tolerance).

The linear analysis leaves out what makes the model hard: contacts opening and closing ≈ 5500
times a second (tools/studies/contact_switching.py) change J within a step. It bounds what an
implicit partition can give; it does not show that one passes the acceptance check.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from condensed_budget import steady_model  # noqa: E402

from prsm_health.simulation.dynamics import layout as L  # noqa: E402
from prsm_health.simulation.dynamics.model import AUTO_STABLE_FRACTION  # noqa: E402
from prsm_health.simulation.dynamics.simulate import (  # noqa: E402
    STABILITY_MARGIN,
    linearised_jacobian,
    max_stable_step,
)
from prsm_health.validation.fidelity import DAMPINGS  # noqa: E402

# ROS34PW2 (Rang & Angermann 2005, table 4.2)
GAMMA = 4.3586652150845900e-01
A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0],
        [8.7173304301691801e-01, 0.0, 0.0, 0.0],
        [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ]
)
G = np.array(
    [
        [0.0, 0.0, 0.0, 0.0],
        [-8.7173304301691801e-01, 0.0, 0.0, 0.0],
        [-9.0338057013044082e-01, 5.4180672388095326e-02, 0.0, 0.0],
        [2.4212380706095346e-01, -1.2232505839045147e00, 5.4526025533510214e-01, 0.0],
    ]
)
B = np.array(
    [2.4212380706095346e-01, -1.2232505839045147e00, 1.5452602553351020e00, 4.3586652150845900e-01]
)
RHS_COST = 1.07e-6  # [s] one right-hand side, tools/studies/condensed_budget.py
FLOPS = 2e9  # [1/s] small dense block solves in a numba loop (an assumption, stated)
BAND = (3000.0, 8000.0)  # [Hz] the acceptance check's upper band
#: Added damping ratio and relative frequency error a 3–8 kHz mode may take: a resonance's band
#: power goes as 1/ζ, so +0.5 % of critical damping on a 5 %-damped mode is −9 % of its power
#: (the check allows ±20 %); 0.5 % of frequency is the check's tolerance on eigenfrequencies.
BAND_TOLERANCE = 0.005
#: Damping ratio below which a mode rings (mode_map.py counts the in-band roller modes so).
RINGING = 0.5
#: The largest step the output allows: 1/(m·f_s) with m = 2 at the default 20 kHz.
MAX_STEP = 25e-6


def amplification(jac: np.ndarray, implicit: np.ndarray, h: float) -> np.ndarray:
    """R(h) of ROS34PW2 on y' = jac·y with ``implicit`` as its W-matrix Jacobian."""
    n = len(jac)
    eye = np.eye(n)
    w_inv = np.linalg.inv(eye - GAMMA * h * implicit)
    ks: list[np.ndarray] = []
    for i in range(4):
        stage = eye + sum((A[i, j] * ks[j] for j in range(i)), np.zeros((n, n)))
        coupling = sum((G[i, j] * ks[j] for j in range(i)), np.zeros((n, n)))
        ks.append(w_inv @ (h * jac @ stage + h * implicit @ coupling))
    return eye + sum(B[i] * ks[i] for i in range(4))


def stable_step(jac: np.ndarray, implicit: np.ndarray, eig: np.ndarray) -> float:
    """Largest h with ρ(R(h)) ≤ max(1, max |e^{hλ}|): a log scan, then bisection."""

    def stable(h: float) -> bool:
        allowed = max(1.0, float(np.max(np.exp(h * eig.real)))) * (1.0 + 1e-9)
        return float(np.max(np.abs(np.linalg.eigvals(amplification(jac, implicit, h))))) <= allowed

    lo, hi = 0.0, None
    for h in np.geomspace(1e-8, 1e-3, 41):
        if stable(h):
            lo = h
        else:
            hi = h
            break
    if hi is None:
        return math.inf
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def band_error(jac: np.ndarray, implicit: np.ndarray, eig: np.ndarray, h: float):
    """(worst added damping ratio, worst |frequency error|) of the 3–8 kHz modes at step h."""
    mu = np.linalg.eigvals(amplification(jac, implicit, h))
    lam_num = np.log(mu.astype(complex)) / h
    worst_zeta = worst_freq = 0.0
    for lam in eig:
        f = abs(lam.imag) / (2 * math.pi)
        # the modes that ring in the band (an overdamped contact mode of tens of kHz can have
        # an imaginary part there, and no resonance for a band to hold)
        if not BAND[0] <= f <= BAND[1] or lam.imag < 0 or -lam.real / abs(lam) > RINGING:
            continue
        # the numerical eigenvalue nearest the exact one as a continuous rate (near e^{hλ} many
        # slow modes crowd around 1; as rates they are kHz apart)
        k = int(np.argmin(np.minimum(np.abs(lam_num - lam), np.abs(np.conj(lam_num) - lam))))
        num = lam_num[k] if lam_num[k].imag >= 0 else np.conj(lam_num[k])
        worst_zeta = max(worst_zeta, (lam.real - num.real) / abs(lam))
        worst_freq = max(worst_freq, abs(num.imag / lam.imag - 1.0))
    return worst_zeta, worst_freq


def rk4_accurate_step(eig: np.ndarray) -> float:
    """Largest h (2 % grid down from :data:`MAX_STEP`) at which RK4's own amplification of each
    ringing 3–8 kHz mode stays within :data:`BAND_TOLERANCE`: what a method with RK4's accuracy
    and no stability limit (everything implicit, for free) could take."""
    band = [
        lam
        for lam in eig
        if BAND[0] <= abs(lam.imag) / (2 * math.pi) <= BAND[1]
        and lam.imag > 0
        and -lam.real / abs(lam) <= RINGING
    ]
    h = MAX_STEP
    while h > 1e-8:
        z = h * np.array(band)
        num = np.log(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) / h
        lam = np.array(band)
        zeta = np.max((lam.real - num.real) / np.abs(lam))
        freq = np.max(np.abs(num.imag / lam.imag - 1.0))
        if zeta <= BAND_TOLERANCE and freq <= BAND_TOLERANCE:
            return h
        h *= 0.98
    return h


def accurate_step(jac: np.ndarray, implicit: np.ndarray, eig: np.ndarray, h_max: float) -> float:
    """Largest h ≤ h_max (on a 2 % grid down from it) whose 3–8 kHz modes stay within
    :data:`BAND_TOLERANCE`."""
    h = h_max
    while h > 1e-8:
        zeta, freq = band_error(jac, implicit, eig, h)
        if zeta <= BAND_TOLERANCE and freq <= BAND_TOLERANCE:
            return h
        h *= 0.98
    return h


def partitions(model, free: list[int]) -> dict[str, tuple[list[list[int]], float, int]]:
    """Partition name → (blocks of state indices, flops per stage of its solves and products
    with Jᵢ, column groups per finite-difference refresh).

    An m×m block's factored solve and its product with Jᵢ cost 2m² flops each; the rollers and
    carrier form an arrowhead (every roller block coupled to the carrier's 6 states only,
    rollers not to each other), solved by the carrier's Schur complement: the roller blocks,
    their couplings (2·10·6 flops each way) and a 6×6 solve."""
    nq, n = model.n_coordinates, model.n_rollers
    s0 = 2 * nq + L.N_EXTRA
    pos = {j: k for k, j in enumerate(free)}

    def roller(i: int, positions: bool) -> list[int]:
        b = L.Q_ROLLER0 + L.ROLLER_DOF * i
        states = [nq + b + d for d in range(L.ROLLER_DOF)]
        if positions:
            states += [b + d for d in range(L.ROLLER_DOF)] + [s0 + i, s0 + n + i]
        return [pos[j] for j in states if j in pos]

    carrier = [pos[j] for q in (L.Q_XP, L.Q_YP, L.Q_THP) for j in (q, nq + q) if j in pos]
    velocity_blocks = [roller(i, False) for i in range(n)]
    roller_blocks = [roller(i, True) for i in range(n)]
    whole = [sum(roller_blocks, []) + carrier]
    return {
        "explicit (Jᵢ = 0)": ([], 0.0, 0),
        "roller velocities (contact damping)": (velocity_blocks, n * 4.0 * 4**2, 4),
        "rollers (positions, velocities, traction)": (roller_blocks, n * 4.0 * 10**2, 10),
        "rollers and carrier": (whole, n * (4.0 * 10**2 + 4.0 * 10 * 6) + 4.0 * 6**2, 16),
        "every state (Jᵢ = J)": ([list(range(len(free)))], 4.0 * len(free) ** 2, len(free)),
    }


def block_matrix(jac: np.ndarray, blocks: list[list[int]]) -> np.ndarray:
    implicit = np.zeros_like(jac)
    for block in blocks:
        implicit[np.ix_(block, block)] = jac[np.ix_(block, block)]
    return implicit


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--reuse", type=int, default=8, help="steps per Jacobian refresh")
    args = parser.parse_args()
    print(
        "| contact damping | Jᵢ holds | stable step | step taken | 3–8 kHz: added ζ, "
        "frequency error | cost per simulated s vs the full model's RK4 | speed-up bound "
        "(solves and Jacobians free) |"
    )
    print("|---|---|---|---|---|---|---|")
    for damping in DAMPINGS:
        model = steady_model(damping)
        jac, free = linearised_jacobian(model)
        eig = np.linalg.eigvals(jac)
        h_rk4 = AUTO_STABLE_FRACTION * max_stable_step(model)[0]
        rk4_cost = 4 * RHS_COST / h_rk4
        print(f"| {damping:g} | full model, RK4 | | {1e6 * h_rk4:.2f} µs | | 1 | 1× |")
        h_ideal = rk4_accurate_step(eig)
        print(
            f"| {damping:g} | every state, at RK4's accuracy (no such method measured) | | "
            f"{1e6 * h_ideal:.2f} µs | ≤ +0.5 %, ≤ 0.5 % | | {h_ideal / h_rk4:.1f}× |"
        )
        for name, (blocks, flops, groups) in partitions(model, free).items():
            implicit = block_matrix(jac, blocks)
            h_max = stable_step(jac, implicit, eig)
            stable = f"{1e6 * h_max:.2f} µs" if math.isfinite(h_max) else "unlimited"
            h = min(AUTO_STABLE_FRACTION * STABILITY_MARGIN * h_max, MAX_STEP)
            h = accurate_step(jac, implicit, eig, h)
            zeta, freq = band_error(jac, implicit, eig, h)
            solves = 4 * flops / FLOPS
            per_step = 4 * RHS_COST + solves + groups * RHS_COST / args.reuse
            print(
                f"| {damping:g} | {name} | {stable} | {1e6 * h:.2f} µs | "
                f"+{100 * zeta:.2f} %, {100 * freq:.2f} % | "
                f"{per_step / h / rk4_cost:.2f} (speed-up {rk4_cost / (per_step / h):.1f}×) | "
                f"{h / h_rk4:.1f}× |"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
