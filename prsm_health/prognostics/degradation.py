"""The arithmetic of the Bayesian degradation model (Gebraeel et al. 2005): transforms of the
health indicator, per-unit weighted least squares, the restricted likelihood of sigma^2
(Harville 1977), the fleet prior and the conjugate posterior; weighted quantiles."""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

# Floor of sigma^2 in the model's own units (log units; fractions of the threshold): keeps the
# posterior finite for noiseless histories while being negligible against any real scatter.
SIGMA2_FLOOR = 1e-16
# Ridge added to the prior covariance (scaled parameters, order one): a fleet of identical
# units still has an invertible prior.
PRIOR_RIDGE = 1e-12
# Candidate margins of phi below the fleet's initial clearance, as fractions of the rise from
# that level to the threshold (profile-likelihood search, then refined between neighbours).
PHI_MARGINS = np.geomspace(1e-3, 1.0, 31)
# Floor of S - phi in the exponential form, as a fraction of (threshold - phi), for diagnoses
# without an interval; with an interval the floor is one measurement standard deviation.
LOG_FLOOR_FRACTION = 1e-3


def weighted_quantiles(values: np.ndarray, weights: np.ndarray, q) -> np.ndarray:
    """Quantiles of a weighted sample (linear interpolation between the weight midpoints)."""
    order = np.argsort(values, kind="stable")
    v, w = values[order], weights[order]
    cumulative = (np.cumsum(w) - 0.5 * w) / np.sum(w)
    return np.interp(q, cumulative, v)


# --------------------------------------------------------------------------------------------
# Degradation model helpers (scaled time tau = t / t_scale)
# --------------------------------------------------------------------------------------------


def transform(form: str, value, sd, phi: float, threshold: float):
    """Signal ``y``, its measurement variance and the below-baseline mask for one form.

    Exponential: ``y = ln(max(S - phi, floor))`` with ``floor`` one measurement standard
    deviation (at least ``LOG_FLOOR_FRACTION`` of ``threshold - phi``), variance
    ``(sd / (S - phi))^2`` (delta method). Linear: ``y = S / threshold``.
    """
    if form == "linear":
        return value / threshold, (sd / threshold) ** 2, np.zeros(value.shape, bool)
    rise = value - phi
    floor = np.maximum(sd, LOG_FLOOR_FRACTION * (threshold - phi))
    x = np.maximum(rise, floor)
    return np.log(x), (sd / x) ** 2, rise <= 0


def y_threshold(form: str, phi: float, threshold: float) -> float:
    return 1.0 if form == "linear" else math.log(threshold - phi)


def curve(form: str, a, b, tau, phi: float, threshold: float):
    """Clearance [m] of the degradation curve ``(a, b)`` at scaled time ``tau``."""
    if form == "linear":
        return threshold * (a + b * tau)
    return phi + np.exp(np.minimum(a + b * tau, 700.0))


def wls_by_unit(tau, y, w, codes, n_units):
    """Per-unit weighted least squares of ``y = a + b tau``: a, b and det(X'WX) per unit."""
    sw = np.bincount(codes, w, n_units)
    st = np.bincount(codes, w * tau, n_units)
    stt = np.bincount(codes, w * tau * tau, n_units)
    sy = np.bincount(codes, w * y, n_units)
    sty = np.bincount(codes, w * tau * y, n_units)
    det = sw * stt - st * st
    b = (sw * sty - st * sy) / det
    a = (sy - b * st) / sw
    return a, b, det


def _neg_reml(sigma2, tau, y, m, codes, n_units) -> float:
    """-log restricted likelihood (up to a constant) of per-unit lines with variance sigma2+m."""
    v = sigma2 + m
    w = 1.0 / v
    a, b, det = wls_by_unit(tau, y, w, codes, n_units)
    r = y - a[codes] - b[codes] * tau
    return 0.5 * float(np.sum(np.log(v)) + np.sum(r * r * w) + np.sum(np.log(det)))


def fit_sigma2(tau, y, m, codes, n_units) -> tuple[float, float]:
    """Restricted-maximum-likelihood ``sigma^2`` [3]_ and the minimized objective."""
    high = max(float(np.var(y)) + 10 * SIGMA2_FLOOR, 100 * SIGMA2_FLOOR)
    at_floor = _neg_reml(SIGMA2_FLOOR, tau, y, m, codes, n_units)
    result = minimize_scalar(
        lambda s: _neg_reml(math.exp(s), tau, y, m, codes, n_units),
        bounds=(math.log(SIGMA2_FLOOR), math.log(high)),
        method="bounded",
        options={"xatol": 1e-3},
    )
    if at_floor <= result.fun:
        return SIGMA2_FLOOR, at_floor
    return math.exp(float(result.x)), float(result.fun)


def profile_phi(tau, value, sd, codes, n_units, c_ref, threshold) -> float:
    """The baseline phi [m] maximizing the profile likelihood of the clearances ``S``.

    phi = c_ref - margin: for each margin the per-unit lines and sigma^2 are fitted to
    ``ln(S - phi)`` and the likelihood is transformed back to the clearance with the Jacobian
    ``1 / (S - phi)``, so margins are compared on the same data.
    """

    def objective(margin):
        phi = c_ref - margin
        y, m, _ = transform("exponential", value, sd, phi, threshold)
        _, nll = fit_sigma2(tau, y, m, codes, n_units)
        return nll + float(np.sum(y))  # + sum ln(S - phi): the Jacobian of S -> ln(S - phi)

    rise = threshold - c_ref
    margins = PHI_MARGINS * rise
    scores = np.array([objective(mg) for mg in margins])
    best = int(np.argmin(scores))
    low = margins[max(best - 1, 0)]
    high = margins[min(best + 1, len(margins) - 1)]
    if high > low:
        refined = minimize_scalar(
            lambda s: objective(math.exp(s)),
            bounds=(math.log(low), math.log(high)),
            method="bounded",
            options={"xatol": 1e-3},
        )
        if refined.fun < scores[best]:
            return c_ref - math.exp(float(refined.x))
    return c_ref - float(margins[best])


def prior(params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and covariance (+ ridge) of per-unit parameters (rows: units)."""
    mean = params.mean(axis=0)
    cov = np.cov(params, rowvar=False, ddof=1) + PRIOR_RIDGE * np.eye(2)
    return mean, cov


def posterior(mean0, cov0, tau, y, v) -> tuple[np.ndarray, np.ndarray]:
    """Conjugate Gaussian posterior of (a, b) for ``y = a + b tau + e``, ``e ~ N(0, v)``."""
    precision0 = np.linalg.inv(cov0)
    w = 1.0 / v
    xtwx = np.array([[w.sum(), (w * tau).sum()], [(w * tau).sum(), (w * tau * tau).sum()]])
    xtwy = np.array([(w * y).sum(), (w * tau * y).sum()])
    precision = precision0 + xtwx
    cov = np.linalg.inv(precision)
    cov = 0.5 * (cov + cov.T)
    return cov @ (precision0 @ mean0 + xtwy), cov


def sample_gaussian(rng, mean, cov, n) -> np.ndarray:
    values, vectors = np.linalg.eigh(cov)
    root = vectors * np.sqrt(np.clip(values, 0.0, None))
    return mean + rng.standard_normal((n, 2)) @ root.T
