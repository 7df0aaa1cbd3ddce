"""The nut's lost motion across a reversal: its lag behind the rigid kinematics (position sensor
against the angle sensor), with the position sensor's nonlinearity and the screw's lead error
removed, read as a percentile spread (the window indicator ``lost_motion``) or as the fitted jump
between the flank sides (the health check's ``check_reversal_lost_motion_step``).
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import step_polynomial_normal_equations, subtract_polynomial
from .percentiles import percentiles

#: The share of the speed amplitude beyond which a reversal's samples are *settled*: the nut
#: rests on one set of flanks. Below it the nut may still be crossing the play, its lag
#: between the two sides, and a step fitted over every sample reads a share of the play only:
#: on the built-in check's ±25 % C_a reversal the step over all samples reads 3.88 µm per µm
#: of half-clearance b, over the settled ones (≥ 0.5) 4.05 — the 4 of the play crossed
#: (:data:`~prsm_health.physics.lost_motion_chain.CLEARANCE_SLOPE`); at ±10 % C_a 3.76
#: against 4.03 (``python tools/studies/clearance_gauge.py --factors``).
SETTLED_SHARE = 0.5


def lost_motion_spread(
    position: np.ndarray, angle: np.ndarray, lead: float, side: np.ndarray
) -> float:
    """Spread (1st–99th percentile) of the nut's lag behind the rigid kinematics [m]
    (:func:`_lag_fit`: the lag with the sensor's nonlinearity and the lead error removed)."""
    residual, _ = _lag_fit(position, angle, lead, side)
    low, high = percentiles(residual, [1, 99])
    return float(high - low)


def lost_motion_step(position, angle, lead: float, side) -> float:
    """The jump of the nut's lag between the two flank sides, from the step fitted with
    :func:`_lag_fit` [m]: 2·|c_s|, the step being ±c_s on ``side`` = ±1.

    Every sample of the reversal enters the fit, so the position sensor's noise averages out;
    the percentile spread of :func:`lost_motion_spread` (the window indicator ``lost_motion``) grows
    with it instead — measured on one unit's health check: 103 µm at 2 µm RMS of LVDT noise,
    126 µm at 10 µm, while the play and the elastic lag did not change. NaN when the nut did
    not move or the run holds one side only.
    """
    side = np.asarray(side, float)
    if not (np.any(side > 0) and np.any(side < 0)):
        return math.nan
    _, step = _lag_fit(np.asarray(position, float), np.asarray(angle, float), lead, side)
    return 2.0 * abs(step)


def settled_samples(speed, min_share: float = SETTLED_SHARE) -> tuple[np.ndarray, float]:
    """(which samples of a reversal are settled, its speed amplitude): |speed| ≥ ``min_share``
    of the amplitude, the 98th percentile of |speed| (:data:`SETTLED_SHARE`); none when the
    speed has no amplitude."""
    speed = np.abs(np.asarray(speed, float))
    amplitude = float(np.percentile(speed, 98)) if len(speed) else 0.0
    if not amplitude > 0.0:
        return np.zeros(speed.shape, dtype=bool), 0.0
    return speed >= min_share * amplitude, amplitude


def settled_lost_motion_step(
    position, angle, speed, lead: float, min_share: float = SETTLED_SHARE
) -> tuple[float, np.ndarray]:
    """The lost-motion step over the *settled* samples of a reversal (:func:`settled_samples`),
    and the shares |speed|/amplitude of those samples, clipped to 1 (the load follows the speed
    in a check's reversal, so they are the shares of its load amplitude the elastic lag was
    read at: :func:`~prsm_health.physics.lost_motion_chain.compliance_chain`'s
    ``load_shares``).

    Returns (NaN, empty) when the speed has no amplitude or the settled samples hold one side
    only."""
    speed = np.asarray(speed, float)
    settled, amplitude = settled_samples(speed, min_share)
    if not amplitude > 0.0:
        return math.nan, np.empty(0)
    step = lost_motion_step(
        np.asarray(position, float)[settled],
        np.asarray(angle, float)[settled],
        lead,
        np.sign(speed[settled]),
    )
    shares = np.minimum(np.abs(speed[settled]) / amplitude, 1.0)
    return step, (shares if math.isfinite(step) else np.empty(0))


def _lag_fit(position: np.ndarray, angle: np.ndarray, lead: float, side: np.ndarray):
    """(lag, step): the nut's lag behind the rigid kinematics (position − lead·angle) with a
    smooth function of the position removed, and the fitted step on the flank side [m].

    The lag jumps by the play at each reversal. A smooth function of the position — the
    position sensor's nonlinearity (an LVDT's ±0.25 % of full scale is hundreds of µm over a
    stroke) and the screw's cumulative lead error — is removed: a 7th-degree polynomial in the
    position, fitted together with a step on the flank side (``side`` = ±1: the sign of the
    speed or of the load) so that it does not absorb the jumps, and only the polynomial
    subtracted. NaN step when the nut did not move.
    """
    residual = position - lead * angle
    lo, hi = float(np.min(position)), float(np.max(position))
    step = math.nan
    if hi > lo:
        # Chebyshev polynomials of the position mapped onto [-1, 1]: the same degree-7 space as
        # plain powers, but nearly orthogonal, so the 9 × 9 normal equations are well
        # conditioned and cost a fraction of an SVD least-squares solve of 20,000 rows; summed
        # block by block by a kernel (a 20,000 × 9 basis was most of the time)
        position = np.ascontiguousarray(position, float)
        side = np.ascontiguousarray(side, float)
        gram, rhs = np.empty((9, 9)), np.empty(9)
        step_polynomial_normal_equations(position, side, residual, lo, hi, 7, gram, rhs)
        # (least squares on the small system: a step collinear with the polynomial stays solvable)
        coef = np.linalg.lstsq(gram, rhs, rcond=None)[0]
        subtract_polynomial(position, residual, lo, hi, coef[:8], residual)
        step = float(coef[8])
    return residual, step
