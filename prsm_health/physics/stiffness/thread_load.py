"""Load distribution over the engaged threads of one roller and its side laws.

Within one roller the nut-side engagement and the screw-side engagement are in series; within
one engagement the ``engaged_threads`` thread pairs carry load in parallel, and the compliance
of the bodies between adjacent threads makes the sharing non-uniform (deformation
compatibility, paper 04). One thread pair is a Hertz point contact (δ ∝ Q^(2/3),
:mod:`.thread_geometry`) in series with the two thread teeth (linear,
:mod:`.thread_compliance`).

Load configuration
    The nut's external load enters at the same end of the nut as the screw's load leaves
    toward its bearing (thread 1): screw compressed, nut stretched across the engagement
    ("tension–compression", the bolt–nut case). Thread 1 then carries the most load.
Combinations (``combination``)
    ``"distributed"`` (default, physical): the compatibility system above, solved by Newton's
    method. ``"uniform"``: rigid bodies, every thread carries W/n (paper 05's F' = F/i1).
    ``"paper01_series"``: paper 01 §2.2 read literally — the n thread pairs of one roller in
    *series*, K_side = (Σ_j 1/K_pair)^(-1), each pair carrying the whole roller load W
    (Hertz + teeth + the side's bodies per pitch). Series springs carry the same force, which
    contradicts the parallel load sharing the same paper describes; it is much softer (about
    n^(5/3) for the contact part) and is offered only to document the difference.

The side laws (:func:`roller_side_force`, :func:`roller_side_stiffness`,
:func:`roller_side_power_law`) are what the dynamic simulator uses.

References
----------
- Paper 04 (docs/references.md) — thread compatibility equation.
- Paper 01 (docs/references.md) §2.2 — K_pair and K_sca = (Σ 1/K_pair)^(-1)·n_r.
- Paper 05 (docs/references.md) — F' = F/i1, contact ∝ F^(2/3).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import ConvergenceError, require

from ._thread_inputs import SIDES, _as_array, _check_combination, _check_side, _fmt_values
from .thread_compliance import body_compliances, tooth_compliances
from .thread_geometry import thread_contact_geometry

#: Newton tolerance of the load-distribution system, on residuals scaled by the mean thread
#: load (or the approach): 1e-13 leaves equilibrium exact to ~1e-12 relative, above the
#: ~1e-15 rounding of sums over a few tens of threads.
_NEWTON_TOL = 1e-13
_NEWTON_MAXITER = 100


# ============================================================================ thread pair
def thread_pair_coefficients(design: PRSMDesign, side: str) -> tuple[float, float]:
    """(c_H, c_T) of one thread pair's axial law u = c_H·F_a^(2/3) + c_T·F_a.

    c_H [m/N^(2/3)] is the axial Hertz coefficient, c_T [m/N] the teeth in series (screw or
    nut tooth + roller tooth).
    """
    _check_side(side)
    geo = thread_contact_geometry(design)[0 if side == "screw" else 1]
    teeth = tooth_compliances(design)
    return geo.axial_compliance_coefficient, teeth[side].total + teeth["roller"].total


def thread_pair_deflection(design: PRSMDesign, axial_load, side: str):
    """Axial approach u [m] of one thread pair (contact + teeth) under ``axial_load`` [N].

    References
    ----------
    Paper 04, δ_H and the tooth terms of the compatibility equation; paper 01, 1/K_pair.
    """
    c_h, c_t = thread_pair_coefficients(design, side)
    q = np.maximum(np.asarray(axial_load, dtype=float), 0.0)
    return c_h * np.cbrt(q) ** 2 + c_t * q


# ============================================================================ one roller
def _invert_law(alpha, beta, delta):
    """W ≥ 0 with α·W^(2/3) + β·W = δ (α > 0, β ≥ 0); 0 for δ ≤ 0. Vectorised."""
    delta = np.asarray(delta, dtype=float)
    alpha = np.broadcast_to(np.asarray(alpha, dtype=float), delta.shape)
    beta = np.broadcast_to(np.asarray(beta, dtype=float), delta.shape)
    pos = delta > 0.0
    d = np.where(pos, delta, 1.0)
    # y = W^(1/3) solves β y³ + α y² = δ. Both √(δ/α) and ∛(δ/β) are upper bounds and the
    # cubic is convex for y > 0, so Newton from their minimum descends monotonically.
    y = np.sqrt(d / alpha)
    with np.errstate(divide="ignore"):
        y = np.where(beta > 0.0, np.minimum(y, np.cbrt(d / np.where(beta > 0, beta, 1.0))), y)
    for _ in range(60):
        f = beta * y**3 + alpha * y**2 - d
        step = f / (3.0 * beta * y**2 + 2.0 * alpha * y)
        y = y - step
        if np.all(np.abs(step) <= 4e-16 * y):
            break
    return np.where(pos, y**3, 0.0)


@dataclass(frozen=True, eq=False)
class _RollerState:
    load: np.ndarray  # (B,) roller axial load W
    screw: np.ndarray  # (B, n) axial thread loads, screw side
    nut: np.ndarray  # (B, n)
    deflection: np.ndarray  # (B, 2) axial approach at thread 1, [screw, nut]
    compliance: np.ndarray  # (B, 2) tangent dδ_side/dW
    split: np.ndarray  # (B, 2, 3) contact / teeth / bodies per side


class _RollerModel:
    """One roller's screw-side and nut-side engagement (module docstring)."""

    def __init__(self, design: PRSMDesign, combination: str, body_scale: float):
        self.n = n = design.engaged_threads
        self.combination = combination
        #: The model's inputs, for the messages of :class:`~prsm_health.core.errors.ConvergenceError`.
        self.context = (
            f"design {design.name!r}, {n} engaged threads, combination {combination!r}, "
            f"body_scale {body_scale:g}"
        )
        c_h, c_t = zip(*(thread_pair_coefficients(design, s) for s in SIDES))
        self.c_h = np.array(c_h)
        self.c_t = np.array(c_t)
        body = {k: v * body_scale for k, v in body_compliances(design).items()}
        self.body_side = np.array([body["screw"] + body["roller"], body["nut"] + body["roller"]])
        if combination == "uniform" or body_scale == 0.0:
            self.matrix = None
        else:
            # δ_S = a_S − (c_s + c_r)·M·Q_S + c_r·M·Q_N,  δ_N = a_N − (c_n + c_r)·M·Q_N + c_r·M·Q_S
            # with M_jk = min(j, k) (0-based): the bar segment between threads m and m+1
            # carries the loads of all threads beyond m (screw compressed, nut stretched).
            idx = np.arange(n)
            m = np.minimum.outer(idx, idx).astype(float)
            a = np.zeros((2 * n, 2 * n))
            a[:n, :n] = -(body["screw"] + body["roller"]) * m
            a[:n, n:] = body["roller"] * m
            a[n:, :n] = body["roller"] * m
            a[n:, n:] = -(body["nut"] + body["roller"]) * m
            self.matrix = a
        # Per-side closed-form law u = α W^(2/3) + β W for the non-distributed readings.
        if combination == "paper01_series":
            self.alpha = n * self.c_h
            self.beta = n * (self.c_t + self.body_side)
        else:
            self.alpha = self.c_h * n ** (-2.0 / 3.0)
            self.beta = self.c_t / n

    def _describe(self, control: str, value) -> str:
        what, unit = ("roller load W", "N") if control == "load" else (f"{control} approach", "m")
        return f"for {what} = {_fmt_values(value)} {unit} ({self.context})"

    # ------------------------------------------------------------------ public entry
    def solve(self, control: str, value) -> _RollerState:
        """control: "load" (W), "roller" (δ_S + δ_N), "screw" (δ_S) or "nut" (δ_N)."""
        value = np.atleast_1d(np.asarray(value, dtype=float))
        n = self.n
        bsz = value.size
        load = np.zeros(bsz)
        screw = np.zeros((bsz, n))
        nut = np.zeros((bsz, n))
        defl = np.zeros((bsz, 2))
        comp = np.full((bsz, 2), np.inf)
        split = np.zeros((bsz, 2, 3))
        active = value > 0.0
        if np.any(active):
            v = value[active]
            if self.matrix is None or self.combination == "paper01_series":
                res = self._closed_form(control, v)
            else:
                res = self._newton(control, v)
            load[active], screw[active], nut[active] = res[0], res[1], res[2]
            defl[active], comp[active], split[active] = res[3], res[4], res[5]
        return _RollerState(load, screw, nut, defl, comp, split)

    # ------------------------------------------------------------------ closed forms
    def _closed_form(self, control, v):
        alpha, beta = self.alpha, self.beta
        if control == "load":
            w = v
        elif control == "roller":
            w = _invert_law(alpha.sum(), beta.sum(), v)
        else:
            k = SIDES.index(control)
            w = _invert_law(alpha[k], beta[k], v)
        w13 = np.cbrt(w)
        defl = alpha[None, :] * (w13**2)[:, None] + beta[None, :] * w[:, None]
        comp = (2.0 / 3.0) * alpha[None, :] / w13[:, None] + beta[None, :]
        n = self.n
        split = np.zeros((w.size, 2, 3))
        if self.combination == "paper01_series":
            per_thread = np.repeat(w[:, None], n, axis=1)
            split[:, :, 0] = n * self.c_h[None, :] * (w13**2)[:, None]
            split[:, :, 1] = n * self.c_t[None, :] * w[:, None]
            split[:, :, 2] = n * self.body_side[None, :] * w[:, None]
        else:
            per_thread = np.repeat((w / n)[:, None], n, axis=1)
            split[:, :, 0] = alpha[None, :] * (w13**2)[:, None]
            split[:, :, 1] = beta[None, :] * w[:, None]
        return w, per_thread, per_thread.copy(), defl, comp, split

    # ------------------------------------------------------------------ Newton
    def _g(self, delta):
        """Thread load Q(δ) and dQ/dδ for the 2n thread pairs (inverse of c_H Q^(2/3) + c_T Q)."""
        n = self.n
        ch = np.repeat(self.c_h, n)[None, :]
        ct = np.repeat(self.c_t, n)[None, :]
        q = _invert_law(ch, ct, delta)
        with np.errstate(divide="ignore"):
            dq = np.where(
                q > 0.0, 1.0 / ((2.0 / 3.0) * ch / np.cbrt(np.where(q > 0, q, 1.0)) + ct), 0.0
            )
        return q, dq

    def _residual(self, x, control, value, jacobian=True):
        n = self.n
        q = x[:, : 2 * n]
        a = x[:, 2 * n :]
        delta = np.repeat(a, n, axis=1) + q @ self.matrix.T
        g, dg = self._g(delta)
        r = np.empty_like(x)
        r[:, : 2 * n] = q - g
        r[:, 2 * n] = q[:, :n].sum(axis=1) - q[:, n:].sum(axis=1)
        last = self._control_row(control)
        r[:, 2 * n + 1] = x @ last - value
        if not jacobian:
            return r, None
        bsz, m = x.shape
        jac = np.zeros((bsz, m, m))
        jac[:, : 2 * n, : 2 * n] = np.eye(2 * n)[None] - dg[:, :, None] * self.matrix[None]
        jac[:, :n, 2 * n] = -dg[:, :n]
        jac[:, n : 2 * n, 2 * n + 1] = -dg[:, n:]
        jac[:, 2 * n, :n] = 1.0
        jac[:, 2 * n, n : 2 * n] = -1.0
        jac[:, 2 * n + 1, :] = last[None, :]
        return r, jac

    def _control_row(self, control):
        n = self.n
        row = np.zeros(2 * n + 2)
        if control == "load":
            row[:n] = 1.0
        elif control == "roller":
            row[2 * n :] = 1.0
        else:
            row[2 * n + SIDES.index(control)] = 1.0
        return row

    def _newton(self, control, value):
        n = self.n
        m = 2 * n + 2
        bsz = value.size
        # Start from the rigid-body (uniform) solution of the same control.
        w0, q0, _, d0, _, _ = self._closed_form(control, value)
        x = np.zeros((bsz, m))
        x[:, :n] = q0
        x[:, n : 2 * n] = q0
        x[:, 2 * n :] = d0
        # Scale loads by the mean thread load and approaches by the total approach so the
        # Jacobian is O(1) (loads in N and approaches in m differ by ~1e8).
        col = np.empty((bsz, m))
        col[:, : 2 * n] = (w0 / n)[:, None]
        col[:, 2 * n :] = d0.sum(axis=1)[:, None]
        row = 1.0 / col.copy()
        row[:, 2 * n] = n / w0
        if control == "load":
            row[:, 2 * n + 1] = n / w0
        else:
            row[:, 2 * n + 1] = 1.0 / d0.sum(axis=1)
        r, jac = self._residual(x, control, value)
        for _ in range(_NEWTON_MAXITER):
            rs = r * row
            err = np.max(np.abs(rs), axis=1)
            if np.all(err < _NEWTON_TOL):
                break
            js = row[:, :, None] * jac * col[:, None, :]
            dx = -np.linalg.solve(js, rs[:, :, None])[:, :, 0] * col
            dx[err < _NEWTON_TOL] = 0.0
            merit0 = np.sum(rs**2, axis=1)
            t = np.ones(bsz)
            accepted = err < _NEWTON_TOL
            x_new = x.copy()
            r_new = r.copy()
            jac_new = jac.copy()
            for _ in range(40):
                todo = ~accepted
                if not np.any(todo):
                    break
                xt = x[todo] + t[todo, None] * dx[todo]
                rt, jt = self._residual(xt, control, value[todo])
                merit = np.sum((rt * row[todo]) ** 2, axis=1)
                # Approaches at thread 1 stay positive at every solution with W > 0.
                ok = (merit < (1.0 - 1e-4 * t[todo]) * merit0[todo]) & np.all(
                    xt[:, 2 * n :] > 0, axis=1
                )
                idx = np.flatnonzero(todo)[ok]
                x_new[idx], r_new[idx], jac_new[idx] = xt[ok], rt[ok], jt[ok]
                accepted[idx] = True
                t[np.flatnonzero(todo)[~ok]] *= 0.5
            if not np.all(accepted):  # pragma: no cover - a failure here is a bug, not input
                raise ConvergenceError(
                    "thread load distribution: Newton line search found no descent "
                    + self._describe(control, value[~accepted])
                )
            x, r, jac = x_new, r_new, jac_new
        else:  # pragma: no cover
            err = np.max(np.abs(r * row), axis=1)
            raise ConvergenceError(
                f"thread load distribution: Newton did not converge in {_NEWTON_MAXITER} "
                f"iterations (scaled residual {err.max():.3g} > {_NEWTON_TOL:g}) "
                + self._describe(control, value[err >= _NEWTON_TOL])
            )
        # Tangent: R(x, v) = 0 → J·dx/dv = e_last.
        rhs = np.zeros((bsz, m, 1))
        rhs[:, -1, 0] = 1.0
        dxdv = np.linalg.solve(jac, rhs)[:, :, 0]
        dw = dxdv[:, :n].sum(axis=1)
        comp = dxdv[:, 2 * n :] / dw[:, None]
        q_s, q_n = x[:, :n], x[:, n : 2 * n]
        w = q_s.sum(axis=1)
        defl = x[:, 2 * n :]
        # Deformation split: u_1 = Σ_j (Q_j/W)·[contact_j + teeth_j + (u_1 − u_j)], the load-
        # weighted (Clapeyron) split; the last term is the body stretch between thread 1 and j.
        split = np.zeros((bsz, 2, 3))
        for k, q in enumerate((q_s, q_n)):
            weight = q / w[:, None]
            split[:, k, 0] = np.sum(weight * self.c_h[k] * np.cbrt(q) ** 2, axis=1)
            split[:, k, 1] = np.sum(weight * self.c_t[k] * q, axis=1)
            split[:, k, 2] = defl[:, k] - split[:, k, 0] - split[:, k, 1]
        return w, q_s, q_n, defl, comp, split


@functools.lru_cache(maxsize=64)
def _roller_model(design: PRSMDesign, combination: str, body_scale: float = 1.0) -> _RollerModel:
    return _RollerModel(design, combination, body_scale)


# ============================================================================ distribution
@dataclass(frozen=True, eq=False)
class LoadDistribution:
    """Per-thread axial loads of one roller.

    Attributes
    ----------
    roller_load : ndarray [N]
        Axial load W of the roller (shape of the input).
    screw, nut : ndarray [N]
        Axial load of each engaged thread pair, thread 1 (load entry) first; shape
        (..., engaged_threads).
    screw_deflection, nut_deflection : ndarray [m]
        Axial approach of the screw-side / nut-side engagement, measured at thread 1.
    screw_stiffness, nut_stiffness, roller_stiffness : ndarray [N/m]
        Tangent stiffness dW/dδ of each side and of the roller (sides in series).
    combination : str
    """

    roller_load: np.ndarray
    screw: np.ndarray
    nut: np.ndarray
    screw_deflection: np.ndarray
    nut_deflection: np.ndarray
    screw_stiffness: np.ndarray
    nut_stiffness: np.ndarray
    roller_stiffness: np.ndarray
    combination: str


def _stiffness_from_compliance(comp):
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(comp), 1.0 / comp, 0.0)


def thread_load_distribution(
    design: PRSMDesign,
    roller_load,
    *,
    combination: str = "distributed",
    body_scale: float = 1.0,
) -> LoadDistribution:
    """Loads of the engaged threads of one roller, screw side and nut side.

    Solves the deformation compatibility of paper 04 for the n = ``engaged_threads`` thread
    pairs of each side: for thread j and j + 1 (0-based m = j),

        u_S(Q^S_j) − u_S(Q^S_{j+1}) = (c_s + c_r)·Σ_{k>j} Q^S_k − c_r·Σ_{k>j} Q^N_k
        u_N(Q^N_j) − u_N(Q^N_{j+1}) = (c_n + c_r)·Σ_{k>j} Q^N_k − c_r·Σ_{k>j} Q^S_k

    with u(Q) = c_H Q^(2/3) + c_T Q the thread-pair law (:func:`thread_pair_deflection`) and
    c_s, c_r, c_n the body compliances per pitch (:func:`body_compliances`), together with
    ΣQ^S = ΣQ^N = W. Newton's method with a line search, from the uniform solution.

    Parameters
    ----------
    design : PRSMDesign
    roller_load : float or array_like [N]
        Axial load W of one roller, ≥ 0.
    combination : {"distributed", "uniform", "paper01_series"}
        See the module docstring of :mod:`.thread_load`.
    body_scale : float [-]
        Multiplies the body compliances (1 = physical, 0 = rigid bodies → uniform sharing).

    Returns
    -------
    LoadDistribution

    References
    ----------
    Paper 04, compatibility equation of the i-th engaged thread (its printed form adds
    stiffnesses where compliances add and writes Q_i for the cumulative load; the form above
    is the standard bolt–nut compatibility it paraphrases); paper 01 §2.2 (series reading).
    """
    _check_combination(combination)
    w = _as_array("roller_load", roller_load)
    require(
        isinstance(body_scale, (int, float)) and math.isfinite(body_scale) and body_scale >= 0,
        "body_scale",
        body_scale,
        "must be a finite number ≥ 0",
    )
    state = _roller_model(design, combination, float(body_scale)).solve("load", w.ravel())
    shape = w.shape
    n = design.engaged_threads
    k = _stiffness_from_compliance(state.compliance)
    kr = _stiffness_from_compliance(state.compliance.sum(axis=1))
    return LoadDistribution(
        roller_load=w,
        screw=state.screw.reshape(shape + (n,)),
        nut=state.nut.reshape(shape + (n,)),
        screw_deflection=state.deflection[:, 0].reshape(shape),
        nut_deflection=state.deflection[:, 1].reshape(shape),
        screw_stiffness=k[:, 0].reshape(shape),
        nut_stiffness=k[:, 1].reshape(shape),
        roller_stiffness=kr.reshape(shape),
        combination=combination,
    )


# ============================================================================ simulator API
def roller_side_force(
    design: PRSMDesign, axial_deflection, side: str, *, combination: str = "distributed"
):
    """Axial force [N] of one roller's engagement on ``side`` at an axial deflection [m].

    Parameters
    ----------
    design : PRSMDesign
    axial_deflection : float or array_like [m]
        Axial approach of the side's engagement, measured at the loaded end (thread 1);
        ≤ 0 means separated (force 0).
    side : {"screw", "nut"}
    combination : {"distributed", "uniform", "paper01_series"}

    Returns
    -------
    ndarray [N]
        Same shape as ``axial_deflection``.

    Notes
    -----
    Consistent with :func:`thread_load_distribution`: the force W for which the side's
    approach equals the deflection, both sides of the roller loaded by W (displacement-
    controlled solve of the same compatibility system). The two sides in series reproduce
    the roller law of :func:`axial_stiffness`.

    References
    ----------
    Paper 01, F_sai = K_sca·f(δ, b) (here nonlinear); paper 04, load distribution.
    """
    _check_side(side)
    _check_combination(combination)
    d = _as_array("axial_deflection", axial_deflection, nonnegative=False)
    st = _roller_model(design, combination).solve(side, np.maximum(d.ravel(), 0.0))
    return st.load.reshape(d.shape) if d.ndim else st.load[0]


def roller_side_stiffness(
    design: PRSMDesign, roller_axial_load, side: str, *, combination: str = "distributed"
):
    """Tangent axial stiffness dW/dδ_side [N/m] of one roller's engagement on ``side``.

    Parameters
    ----------
    design : PRSMDesign
    roller_axial_load : float or array_like [N]
        Axial load W of the roller, ≥ 0 (0 gives 0: the Hertz law is infinitely soft there).
    side : {"screw", "nut"}
    combination : {"distributed", "uniform", "paper01_series"}

    Returns
    -------
    ndarray [N/m]

    References
    ----------
    Paper 01 §2.2, K_sca and K_Nca; paper 04, k_H = dQ/dδ_H.
    """
    _check_side(side)
    _check_combination(combination)
    w = _as_array("roller_axial_load", roller_axial_load)
    st = _roller_model(design, combination).solve("load", w.ravel())
    k = _stiffness_from_compliance(st.compliance[:, SIDES.index(side)])
    return k.reshape(w.shape) if w.ndim else k[0]


class PowerLawFit(NamedTuple):
    """F = coefficient·δ^exponent fitted over a load range.

    Attributes
    ----------
    coefficient : float [N/m^exponent]
    exponent : float [-]
    max_relative_error : float [-]
        max |c·δ^n − F|/F over the fitted points.
    """

    coefficient: float
    exponent: float
    max_relative_error: float


def roller_side_power_law(
    design: PRSMDesign,
    side: str,
    load_range: tuple[float, float],
    *,
    combination: str = "distributed",
    points: int = 41,
) -> PowerLawFit:
    """Fit F = c·δ^n to one roller's engagement on ``side`` over ``load_range``.

    Parameters
    ----------
    design : PRSMDesign
    side : {"screw", "nut"}
    load_range : (float, float) [N]
        Roller axial loads (lo, hi), 0 < lo < hi.
    combination : {"distributed", "uniform", "paper01_series"}
    points : int
        Log-spaced loads used for the least-squares fit in log–log space (≥ 3).

    Returns
    -------
    PowerLawFit
        (coefficient, exponent, max_relative_error). A pure Hertz law gives n = 1.5 exactly;
        the teeth and bodies (linear) pull n below 1.5 at high load.

    References
    ----------
    Paper 05 (contact ∝ F^(2/3)); paper 04 (nonlinear δ_H); Johnson (1985) §4.2.
    """
    _check_side(side)
    _check_combination(combination)
    ok = (
        isinstance(load_range, (tuple, list))
        and len(load_range) == 2
        and all(isinstance(v, (int, float)) and math.isfinite(v) for v in load_range)
        and 0 < load_range[0] < load_range[1]
    )
    require(ok, "load_range", load_range, "must be (lo, hi) [N] with 0 < lo < hi")
    require(isinstance(points, int) and points >= 3, "points", points, "must be an integer ≥ 3")
    w = np.geomspace(load_range[0], load_range[1], points)
    st = _roller_model(design, combination).solve("load", w)
    delta = st.deflection[:, SIDES.index(side)]
    slope, intercept = np.polyfit(np.log(delta), np.log(w), 1)
    coef = math.exp(intercept)
    err = float(np.max(np.abs(coef * delta**slope - w) / w))
    return PowerLawFit(coef, float(slope), err)
