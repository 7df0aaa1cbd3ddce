"""numba kernel of tools/studies/rosenbrock_trial.py: a Rosenbrock-W step (ROS34PW2) of the
package's right-hand side whose W holds each roller's velocity block only (an experiment, not
the package's integrator)."""

import math

import numpy as np
from numba import njit

from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics._kernels import (
    _clamp_traction,
    _hold_prescribed,
    _record,
    rhs,
)

# ROS34PW2 (Rang & Angermann 2005): a, γ (below the diagonal), b; stage times c
GAMMA = 4.3586652150845900e-01
A21 = 8.7173304301691801e-01
A31, A32 = 8.4457060015369423e-01, -1.1299064236484185e-01
G21 = -8.7173304301691801e-01
G31, G32 = -9.0338057013044082e-01, 5.4180672388095326e-02
G41, G42, G43 = 2.4212380706095346e-01, -1.2232505839045147e00, 5.4526025533510214e-01
B1, B2, B3 = 2.4212380706095346e-01, -1.2232505839045147e00, 1.5452602553351020e00
B4 = 4.3586652150845900e-01
C2, C3 = A21, A31 + A32
#: Velocity perturbation of the finite-difference blocks [m/s, rad/s].
EPS = 1e-6
W_FINITE_DIFFERENCES, W_LOADED = 0, 1


@njit(cache=True)
def _inv4(m, out):
    # 4×4 inverse by Gauss–Jordan with partial pivoting (m is overwritten)
    for i in range(4):
        for j in range(4):
            out[i, j] = 1.0 if i == j else 0.0
    for c in range(4):
        piv = c
        for r in range(c + 1, 4):
            if abs(m[r, c]) > abs(m[piv, c]):
                piv = r
        for j in range(4):
            m[c, j], m[piv, j] = m[piv, j], m[c, j]
            out[c, j], out[piv, j] = out[piv, j], out[c, j]
        d = 1.0 / m[c, c]
        for j in range(4):
            m[c, j] *= d
            out[c, j] *= d
        for r in range(4):
            if r != c:
                f = m[r, c]
                for j in range(4):
                    m[r, j] -= f * m[c, j]
                    out[r, j] -= f * out[c, j]


@njit(cache=True)
def _roller_blocks(k, blocks, scale, n_rollers, nq, add):
    # k's roller-velocity parts times each roller's 4×4 block (times scale): into k itself, or
    # added to k's own when ``add`` (then of the vector ``add``)
    part = np.empty(4)
    for i in range(n_rollers):
        b = nq + L.Q_ROLLER0 + L.ROLLER_DOF * i
        for r in range(4):
            s = 0.0
            for c in range(4):
                s += blocks[i, r, c] * (add[b + c] if add.shape[0] else k[b + c])
            part[r] = s
        for r in range(4):
            k[b + r] = k[b + r] + scale * part[r] if add.shape[0] else part[r]


@njit(cache=True)
def integrate(
    y, t0, h, n_steps, w_source, p, rollers, mesh_table, motion, load_knots, errors, loaded,
    out, f0, k1, k2, k3, k4, tmp, comb, aux, jac, w_inv, work,
):  # fmt: skip
    """``n_steps`` ROS34PW2 steps of ``h`` from ``t0``, recording every step into ``out``;
    returns (status, step) as the package's RK4 kernel. ``w_source``: W_FINITE_DIFFERENCES
    (each roller's velocity block by one-sided differences at the step's state, one column of
    every roller at once) or W_LOADED (``loaded``: the blocks linearised on the loaded flanks,
    in each roller's pocket frame, turned to X, Y at the step's carrier angle)."""
    n_state = y.shape[0]
    n_r = rollers.shape[0]
    nq = L.Q_ROLLER0 + L.ROLLER_DOF * n_r
    prescribed = p[L.P_DRIVE_MODE] == L.DRIVE_PRESCRIBED
    none = np.empty(0)
    for step in range(n_steps):
        t = t0 + step * h
        if prescribed:
            _hold_prescribed(y, t, p, motion, nq)
        rhs(t, y, p, rollers, mesh_table, motion, load_knots, errors, f0, aux)
        for j in range(2 * nq):
            if not math.isfinite(y[j]):
                return 1, step
        _record(y, f0, aux, p, nq, out[step])
        if w_source == W_FINITE_DIFFERENCES:
            for c in range(4):
                for j in range(n_state):
                    tmp[j] = y[j]
                for i in range(n_r):
                    tmp[nq + L.Q_ROLLER0 + L.ROLLER_DOF * i + c] += EPS
                rhs(t, tmp, p, rollers, mesh_table, motion, load_knots, errors, k4, aux)
                for i in range(n_r):
                    b = nq + L.Q_ROLLER0 + L.ROLLER_DOF * i
                    for r in range(4):
                        jac[i, r, c] = (k4[b + r] - f0[b + r]) / EPS
        else:
            for i in range(n_r):
                phi = y[L.Q_THP] + rollers[i, L.R_PSI]
                c, s = math.cos(phi), math.sin(phi)
                work[:, :] = loaded[i]
                for r in range(4):  # D·Qᵀ, Q the pocket frame's rotation in X, Y
                    a0, a1 = work[r, 0], work[r, 1]
                    work[r, 0], work[r, 1] = a0 * c - a1 * s, a0 * s + a1 * c
                for r in range(4):  # Q·(D·Qᵀ)
                    b0, b1 = work[0, r], work[1, r]
                    work[0, r], work[1, r] = c * b0 - s * b1, s * b0 + c * b1
                jac[i] = work
        for i in range(n_r):
            for r in range(4):
                for c in range(4):
                    work[r, c] = (1.0 if r == c else 0.0) - GAMMA * h * jac[i, r, c]
            _inv4(work, w_inv[i])
        for j in range(n_state):
            k1[j] = h * f0[j]
        _roller_blocks(k1, w_inv, 1.0, n_r, nq, none)
        for j in range(n_state):
            tmp[j] = y[j] + A21 * k1[j]
        rhs(t + C2 * h, tmp, p, rollers, mesh_table, motion, load_knots, errors, k2, aux)
        for j in range(n_state):
            k2[j] *= h
            comb[j] = G21 * k1[j]
        _roller_blocks(k2, jac, h, n_r, nq, comb)
        _roller_blocks(k2, w_inv, 1.0, n_r, nq, none)
        for j in range(n_state):
            tmp[j] = y[j] + A31 * k1[j] + A32 * k2[j]
        rhs(t + C3 * h, tmp, p, rollers, mesh_table, motion, load_knots, errors, k3, aux)
        for j in range(n_state):
            k3[j] *= h
            comb[j] = G31 * k1[j] + G32 * k2[j]
        _roller_blocks(k3, jac, h, n_r, nq, comb)
        _roller_blocks(k3, w_inv, 1.0, n_r, nq, none)
        for j in range(n_state):
            tmp[j] = y[j] + k3[j]
        rhs(t + h, tmp, p, rollers, mesh_table, motion, load_knots, errors, k4, aux)
        for j in range(n_state):
            k4[j] *= h
            comb[j] = G41 * k1[j] + G42 * k2[j] + G43 * k3[j]
        _roller_blocks(k4, jac, h, n_r, nq, comb)
        _roller_blocks(k4, w_inv, 1.0, n_r, nq, none)
        for j in range(n_state):
            y[j] += B1 * k1[j] + B2 * k2[j] + B3 * k3[j] + B4 * k4[j]
        _clamp_traction(y, p, rollers, nq, aux)
    return 0, n_steps
