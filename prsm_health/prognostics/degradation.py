"""The Bayesian degradation model (Gebraeel et al. 2005), one of the RUL methods:
:class:`DegradationRUL` and its arithmetic — transforms of the health indicator, per-unit
weighted least squares, the restricted likelihood of sigma^2 (Harville 1977), the fleet prior
and the conjugate posterior; weighted quantiles.

The model: ``S(t) = phi + theta exp(beta t + eps)``, i.e.
``L(t) = ln(S - phi) = ln theta + beta t + eps``, ``eps ~ N(0, sigma^2)`` [1]_, or its linear
form ``S(t) = theta + beta t + eps``. ``(ln theta, beta)`` has a bivariate Gaussian prior
fitted on the training fleet (per-unit weighted least-squares fits, their mean and covariance,
as in [1]_), updated by the unit's history into a Gaussian posterior (the conjugate update of
[1]_, with a known variance per diagnosis: ``sigma^2`` plus the measurement variance implied
by the diagnosis' 90 % interval, ``(half-width / 1.645)^2``, propagated through the log). The
RUL distribution comes from ``n_samples`` posterior draws, each solved for its crossing of the
threshold (one draw of ``eps`` per sample: the signal error at the crossing, as in the
residual-life distribution of [1]_). Which form a fitted model uses is chosen by the
leave-one-unit-out RMSE of RUL on the training fleet.

References
----------
.. [1] N. Z. Gebraeel, M. A. Lawley, R. Li, J. K. Ryan, "Residual-life distributions from
   component degradation signals: a Bayesian approach", IIE Transactions 37 (2005) 543-557.
.. [2] D. A. Harville, "Maximum likelihood approaches to variance component estimation and to
   related problems", JASA 72 (1977) 320-338 (the restricted likelihood used for ``sigma^2``).
"""

from __future__ import annotations

import copy
import math

import numpy as np
from scipy.optimize import minimize_scalar

from .method import (
    CAPPED_WARNING_FRACTION,
    HORIZON_FACTOR,
    Estimate,
    FleetSummary,
    RULMethod,
    TrainingFleet,
    UnitHistory,
)
from .prognosis import QUANTILES

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
    """Restricted-maximum-likelihood ``sigma^2`` [2]_ and the minimized objective."""
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


# --------------------------------------------------------------------------------------------
# The method
# --------------------------------------------------------------------------------------------

#: The two forms of the model: ``S = phi + exp(a + b tau)`` and ``S = threshold (a + b tau)``.
FORMS = ("exponential", "linear")


class DegradationRUL(RULMethod):
    """The Bayesian degradation model as a RUL method (module docstring, [1]_).

    Fitting:

    1. The exponential form's baseline ``phi`` [m] is the fleet's initial clearance level
       ``c_ref`` minus a margin (between 0.1 % and 100 % of ``threshold - c_ref``) chosen by
       the profile likelihood of the diagnosed clearances. Diagnoses within one measurement
       standard deviation of ``phi`` are clipped to ``phi`` + one standard deviation (their
       log carries no wear information; their variance is then 1 in log units); a history
       with values at or below ``phi`` gets a warning.
    2. ``sigma^2`` is the pooled residual variance of per-unit lines, estimated by restricted
       maximum likelihood [2]_ with each diagnosis' measurement variance added (floored at
       ``SIGMA2_FLOOR`` in model units).
    3. Per-unit weighted least-squares ``(a, b)`` = ``(ln theta, beta)`` (exponential) or
       ``(theta, beta)`` (linear) give the prior mean and covariance (sample covariance, which
       includes the per-unit estimation error: a slightly wide, conservative prior).
    4. The form is the one with the lower leave-one-unit-out RMSE of RUL over all history
       prefixes of >= 2 diagnoses of the training units (each unit predicted with the prior
       of the others; ``phi`` and ``sigma^2`` kept from the whole fleet; the point
       prediction is the posterior mean's crossing). Ties go to exponential.

    Prediction: the posterior of ``(a, b)`` given the history (conjugate update),
    ``n_samples`` draws of it and of ``eps``, each solved for the crossing age
    ``(y_D - a - eps) / b`` with ``y_D = ln(threshold - phi)`` or ``threshold``; RUL =
    crossing age - current age, clipped to [0, horizon] (samples with ``b <= 0`` never cross
    and get the horizon).

    Parameters
    ----------
    n_samples : int
        Posterior samples per prediction.
    random_state : int or None
        Seed of the sampling (every prediction restarts from it); None: a fresh seed each.
    form : {"exponential", "linear"} or None
        The form :meth:`predict` uses; None: the one chosen at fit time (:meth:`with_form`).

    Attributes
    ----------
    fleet_ : FleetSummary
    forms_ : dict
        Per form: ``phi`` [m], ``sigma2``, prior ``mean`` and ``cov``, per-unit ``params`` and
        ``residual_var`` [m^2] (scaled time; linear form in units of the threshold).
    form_ : {"exponential", "linear"}
        The form chosen at fit time.
    loo_rmse_ : dict
        Leave-one-unit-out RMSE of RUL [h] of each form.
    """

    def __init__(self, n_samples: int = 4000, random_state=0, form: str | None = None):
        self.n_samples = n_samples
        self.random_state = random_state
        self.form = form

    @property
    def name(self) -> str:
        return f"degradation-{self.form or self.form_}"

    def with_form(self, form: str) -> DegradationRUL:
        """The same fitted model predicting with ``form`` whatever the fit chose."""
        forced = copy.copy(self)
        forced.form = form
        return forced

    def restored(self, fleet: FleetSummary, forms: dict, form: str, loo_rmse: dict):
        """Self with a fitted state read back from a model file."""
        self.fleet_, self.forms_, self.form_, self.loo_rmse_ = fleet, forms, form, loo_rmse
        return self

    # ---------------------------------------------------------------------------- fitting

    def fit(self, fleet: TrainingFleet) -> DegradationRUL:
        s = fleet.summary
        tau = fleet.t / s.t_scale
        n_units = len(s.units)
        codes, value, sd, thr = fleet.codes, fleet.value, fleet.sd, s.threshold
        phi = profile_phi(tau, value, sd, codes, n_units, s.c_ref, thr)
        self.fleet_ = s
        self.forms_ = {}
        for form in FORMS:
            form_phi = phi if form == "exponential" else 0.0
            y, m, _ = transform(form, value, sd, form_phi, thr)
            sigma2, _ = fit_sigma2(tau, y, m, codes, n_units)
            a, b, _ = wls_by_unit(tau, y, 1.0 / (sigma2 + m), codes, n_units)
            params = np.column_stack([a, b])
            mean, cov = prior(params)
            residual = value - curve(form, a[codes], b[codes], tau, form_phi, thr)
            excess = np.bincount(codes, residual**2 - sd**2, n_units) / np.bincount(
                codes, None, n_units
            )
            self.forms_[form] = {
                "phi": form_phi,
                "sigma2": sigma2,
                "mean": mean,
                "cov": cov,
                "params": params,
                "residual_var": np.clip(excess, 0.0, None),
            }
        self.loo_rmse_ = {form: self._loo_rmse(form, fleet) for form in FORMS}
        self.form_ = min(FORMS, key=lambda f: (self.loo_rmse_[f], FORMS.index(f)))
        return self

    def _loo_rmse(self, form: str, fleet: TrainingFleet) -> float:
        """Leave-one-unit-out RMSE of RUL [h] of one form over every prefix of >= 2 rows."""
        s = fleet.summary
        state = self.forms_[form]
        thr = s.threshold
        tau, t, value = fleet.t / s.t_scale, fleet.t, fleet.value
        y, m, _ = transform(form, value, fleet.sd, state["phi"], thr)
        w = 1.0 / (state["sigma2"] + m)
        y_d = y_threshold(form, state["phi"], thr)
        errors = []
        for u in range(len(s.units)):
            keep = np.arange(len(s.units)) != u
            mean0, cov0 = prior(state["params"][keep])
            p0 = np.linalg.inv(cov0)
            r0 = p0 @ mean0
            rows = fleet.codes == u
            wu, tu, yu = w[rows], tau[rows], y[rows]
            a00 = p0[0, 0] + np.cumsum(wu)
            a01 = p0[0, 1] + np.cumsum(wu * tu)
            a11 = p0[1, 1] + np.cumsum(wu * tu * tu)
            b0 = r0[0] + np.cumsum(wu * yu)
            b1 = r0[1] + np.cumsum(wu * tu * yu)
            det = a00 * a11 - a01 * a01
            a = (a11 * b0 - a01 * b1) / det
            b = (a00 * b1 - a01 * b0) / det
            with np.errstate(divide="ignore", invalid="ignore"):
                crossing = np.where(b > 0, (y_d - a) / b, np.inf) * s.t_scale
            ages = t[rows]
            rul = np.clip(crossing - ages, 0.0, s.horizon)
            rul = np.where(value[rows] >= thr, 0.0, rul)
            true = s.lives[u] - ages
            use = (np.arange(rows.sum()) >= 1) & (true >= 0)
            errors.append(rul[use] - true[use])
        errors = np.concatenate(errors)
        return float(np.sqrt(np.mean(errors**2))) if errors.size else math.inf

    # ---------------------------------------------------------------------------- prediction

    def predict(self, history: UnitHistory) -> Estimate:
        form = self.form or self.form_
        state = self.forms_[form]
        s = self.fleet_
        thr, phi, t, value = s.threshold, state["phi"], history.t, history.value
        y, m, below = transform(form, value, history.sd, phi, thr)
        warnings = []
        if below.any():
            warnings.append(
                f"{int(below.sum())} of {len(value)} diagnoses at or below the model's baseline "
                f"phi = {phi:.4g} m (the fleet's initial clearance level minus a margin): "
                "clipped; this unit starts tighter than the training fleet"
            )
        tau = t / s.t_scale
        mean, cov = posterior(state["mean"], state["cov"], tau, y, state["sigma2"] + m)
        rng = np.random.default_rng(self.random_state)
        draws = sample_gaussian(rng, mean, cov, int(self.n_samples))
        eps = rng.standard_normal(int(self.n_samples)) * math.sqrt(state["sigma2"])
        a, b = draws[:, 0], draws[:, 1]
        y_d = y_threshold(form, phi, thr)
        with np.errstate(divide="ignore", invalid="ignore"):
            crossing = np.where(b > 0, (y_d - a - eps) / b, np.inf) * s.t_scale
        rul = crossing - t[-1]
        capped = float(np.mean(rul >= s.horizon))
        rul = np.clip(rul, 0.0, s.horizon)
        low, mid, high = np.quantile(rul, QUANTILES)
        if capped > CAPPED_WARNING_FRACTION:
            warnings.append(
                f"{capped:.0%} of the posterior samples never reach the threshold (wear rate "
                f"<= 0) or reach it beyond the horizon; their RUL is capped at {s.horizon:.4g} "
                f"h ({HORIZON_FACTOR:g}x the fleet's longest life)"
            )
        scale = (
            np.array([1.0, 1.0 / s.t_scale])
            if form == "exponential"
            else np.array([thr, thr / s.t_scale])
        )
        model = {
            "name": f"degradation-{form}",
            "parameters": ["ln_theta", "beta_per_hour"]
            if form == "exponential"
            else ["theta_m", "beta_m_per_hour"],
            "posterior_mean": (mean * scale).tolist(),
            "posterior_cov": (cov * np.outer(scale, scale)).tolist(),
            "phi": phi,
            "sigma2": state["sigma2"],
            "n_samples": int(self.n_samples),
            "capped_fraction": capped,
            "selection": {"form": self.form_, "loo_rmse_hours": dict(self.loo_rmse_)},
        }
        rul_hours = {"estimate": float(mid), "lower": float(low), "upper": float(high)}
        return Estimate(rul_hours, model, warnings)
