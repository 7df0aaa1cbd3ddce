"""Prognostics: remaining useful life (RUL) of a unit from the history of its diagnoses.

A **history** is a table of diagnoses of one asset over its operating hours (columns
:data:`HISTORY_COLUMNS`: the age [h] and the diagnosed clearance [m] with its 90 % interval;
optionally ``design``, ``fault_class``, ``unit_id``). The health indicator is the clearance; a
unit fails when its true clearance reaches ``threshold`` [m]. A :class:`RULModel` is
fitted on a training fleet (the histories of units run to failure and their failure ages) and
predicts a :class:`Prognosis`: the RUL [h] with a 90 % interval (5 % and 95 % quantiles).

Two methods:

- ``"degradation"`` (default), after Gebraeel et al. [1]_: the exponential degradation model
  ``S(t) = phi + theta exp(beta t + eps)``, i.e. ``L(t) = ln(S - phi) = ln theta + beta t + eps``,
  ``eps ~ N(0, sigma^2)`` [1]_, or its linear form ``S(t) = theta + beta t + eps``.
  ``(ln theta, beta)`` has a bivariate Gaussian prior fitted on the training fleet (per-unit
  weighted least-squares fits, their mean and covariance, as in [1]_), updated by the unit's
  history into a Gaussian posterior (the conjugate update of [1]_, with a known variance per
  diagnosis: ``sigma^2`` plus the measurement variance implied by the diagnosis' 90 % interval,
  ``(half-width / 1.645)^2``, propagated through the log). The RUL distribution comes from
  ``n_samples`` posterior draws, each solved for its crossing of the threshold (one draw of
  ``eps`` per sample: the signal error at the crossing, as in the residual-life distribution
  of [1]_). Which form a fitted model uses is chosen by the leave-one-unit-out RMSE of RUL on
  the training fleet.
- ``"similarity"``, after Wang et al. [2]_: each training unit's smoothed trajectory (its fitted
  degradation curve) and failure age form a library; the history is aligned to each library
  curve by the time shift that minimizes its measurement-weighted squared distance, the library
  units are weighted by a (tempered) Gaussian kernel of that distance, and the RUL is the
  weighted median (interval: weighted 5 % and 95 % quantiles) of the library units' remaining
  lives past the aligned age.

Metrics and the fleet evaluation are in :mod:`prsm_health.prognostics.metrics`.

References
----------
.. [1] N. Z. Gebraeel, M. A. Lawley, R. Li, J. K. Ryan, "Residual-life distributions from
   component degradation signals: a Bayesian approach", IIE Transactions 37 (2005) 543-557.
.. [2] T. Wang, J. Yu, D. Siegel, J. Lee, "A similarity-based prognostics approach for
   remaining useful life estimation of engineered systems", Int. Conf. on Prognostics and
   Health Management (PHM 2008), Denver, 2008.
.. [3] D. A. Harville, "Maximum likelihood approaches to variance component estimation and to
   related problems", JASA 72 (1977) 320-338 (the restricted likelihood used for ``sigma^2``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from prsm_health.core.errors import (
    ModelVersionError,
    ParameterError,
    PRSMHealthError,
    require,
    require_positive,
)
from prsm_health.core.jsonable import json_ready
from prsm_health.core.version import __version__

from .degradation import (
    curve,
    fit_sigma2,
    posterior,
    prior,
    profile_phi,
    sample_gaussian,
    transform,
    wls_by_unit,
    y_threshold,
)
from .history import (
    Z90,
    HistoryError,
    duty_arrays,
    history_arrays,
    model_design,
    one_line,
    validate_history,
)
from .prognosis import QUANTILES, Prognosis
from .similarity import similarity_rul

#: Methods :meth:`RULModel.predict` accepts. ``"degradation"`` uses the form chosen at
#: fit time; ``"degradation-exponential"`` / ``"degradation-linear"`` force a form.
METHODS = (
    "degradation",
    "degradation-exponential",
    "degradation-linear",
    "similarity",
    "physics",
)
#: RUL is capped at this multiple of the training fleet's longest life [-] (the horizon):
#: posterior samples that never reach the threshold (wear rate <= 0) or reach it later get it.
HORIZON_FACTOR = 3.0
#: A capped fraction of samples above this moves the 95 % quantile: then a warning says so.
CAPPED_WARNING_FRACTION = 0.05
#: A history spanning less than this fraction of the fleet's median life gets a warning.
SHORT_HISTORY_FRACTION = 0.1
#: Fewest training units: the leave-one-unit-out prior needs a covariance of at least 2 others.
MIN_TRAINING_UNITS = 3

_FORMAT = "prsm_health-prognostics"
_FORMAT_VERSION = 1
_FORMS = ("exponential", "linear")


# --------------------------------------------------------------------------------------------
# Prognosis
# --------------------------------------------------------------------------------------------


# --------------------------------------------------------------------------------------------
# The model
# --------------------------------------------------------------------------------------------


class RULModel:
    """RUL from a history of diagnoses: Bayesian degradation model and similarity baseline.

    ``__init__`` stores its arguments; :meth:`fit` learns from a training fleet (attributes
    ending in ``_``); :meth:`predict` returns a :class:`Prognosis`.

    Fitting, degradation model [1]_:

    1. The exponential form's baseline ``phi`` [m] is the fleet's initial clearance level
       ``c_ref`` (the smallest first diagnosis of a training unit) minus a margin, the margin
       (between 0.1 % and 100 % of ``threshold - c_ref``) chosen by the profile likelihood of
       the diagnosed clearances. Diagnoses within one measurement standard deviation of
       ``phi`` are clipped to ``phi`` + one standard deviation (their log carries no wear
       information; their variance is then 1 in log units); a history with values at or below
       ``phi`` gets a warning.
    2. ``sigma^2`` is the pooled residual variance of per-unit lines, estimated by restricted
       maximum likelihood [3]_ with each diagnosis' measurement variance added (floored at
       1e-16 in model units).
    3. Per-unit weighted least-squares ``(a, b)`` = ``(ln theta, beta)`` (exponential) or
       ``(theta, beta)`` (linear) give the prior mean and covariance (sample covariance, which
       includes the per-unit estimation error: a slightly wide, conservative prior).
    4. The form (exponential or linear) is the one with the lower leave-one-unit-out RMSE of
       RUL over all history prefixes of >= 2 diagnoses of the training units (each unit
       predicted with the prior of the others; ``phi`` and ``sigma^2`` kept from the whole
       fleet; the point prediction is the posterior mean's crossing). Ties go to exponential.

    Prediction: the posterior of ``(a, b)`` given the history (conjugate update), ``n_samples``
    draws of it and of ``eps``, each solved for the crossing age ``(y_D - a - eps) / b`` with
    ``y_D = ln(threshold - phi)`` or ``threshold``; RUL = crossing age - current age, clipped
    to [0, horizon], the horizon being ``3 x`` the fleet's longest life (samples with
    ``b <= 0`` never cross and get the horizon). When the latest clearance estimate is at or
    above the threshold the RUL is 0 with a warning.

    Similarity model [2]_: :mod:`prsm_health.prognostics.similarity` (the alignment, the kernel).

    Physics model (``"physics"``, when fitted by :func:`~prsm_health.prognostics.fit_prognostics_model`
    on a fleet dataset, whose ``[life]`` recipe gives the physics): the PRSM's ageing as a
    progpy model, a particle filter on the diagnoses, progpy's Monte Carlo prediction
    (:mod:`prsm_health.prognostics.ageing_rul`).

    Parameters
    ----------
    method : {"degradation", "similarity", "physics", "degradation-exponential", "degradation-linear"}
        Default method of :meth:`predict`.
    threshold : float, default 30e-6
        Clearance at which a unit fails [m], > 0.
    design : str, default "paper01"
        Name of the design the model is for (any design, not only a preset).
    design_fingerprint : str or None, default None
        :func:`~prsm_health.actuator.design_files.design_fingerprint` of that design; None
        for a preset named by ``design`` (its fingerprint) or a design known by name only.
        A history must be of the model's design: its ``design_fingerprint`` column equal to
        this where both exist, else its ``design`` column equal to the name
        (:func:`~prsm_health.prognostics.validate_history`).
    n_samples : int, default 4000
        Posterior samples per degradation prediction, >= 100.
    random_state : int or None, default 0
        Seed of the posterior sampling (every prediction restarts from it, so a prediction
        does not depend on the ones before it); None draws a fresh seed per prediction.

    Attributes
    ----------
    form_ : {"exponential", "linear"}
        Degradation form chosen at fit time.
    loo_rmse_ : dict
        Leave-one-unit-out RMSE of RUL [h] of each form.
    forms_ : dict
        Per form: ``phi`` [m], ``sigma2``, prior ``mean`` and ``cov``, per-unit ``params``
        and ``residual_var`` [m^2] (scaled time; linear form in units of the threshold).
    units_ : list
        Training unit ids; ``failure_ages_`` [h] in the same order.
    t_scale_ : float
        Time scale [h] (median failure age); parameters are fitted against ``age / t_scale_``.
    horizon_ : float
        RUL cap [h]: ``HORIZON_FACTOR`` x the longest training life.
    c_ref_ : float
        The fleet's initial clearance level [m].

    References
    ----------
    .. [1] N. Z. Gebraeel, M. A. Lawley, R. Li, J. K. Ryan, IIE Transactions 37 (2005) 543-557.
    .. [2] T. Wang, J. Yu, D. Siegel, J. Lee, PHM 2008.
    .. [3] D. A. Harville, JASA 72 (1977) 320-338.
    """

    def __init__(
        self,
        method="degradation",
        threshold=30e-6,
        design="paper01",
        n_samples=4000,
        random_state=0,
        design_fingerprint=None,
    ):
        self.method = method
        self.threshold = threshold
        self.design = design
        self.design_fingerprint = design_fingerprint
        self.n_samples = n_samples
        self.random_state = random_state

    # ---------------------------------------------------------------------------- parameters

    def _check_params(self) -> None:
        require(
            self.method in METHODS, "method", self.method, f"must be one of {', '.join(METHODS)}"
        )
        require_positive("threshold", self.threshold)
        require(
            isinstance(self.design, str) and self.design != "",
            "design",
            self.design,
            "must be a non-empty design name",
        )
        require(
            self.design_fingerprint is None
            or (isinstance(self.design_fingerprint, str) and self.design_fingerprint != ""),
            "design_fingerprint",
            self.design_fingerprint,
            "must be None or a design fingerprint (hex text)",
        )
        require(
            isinstance(self.n_samples, (int, np.integer))
            and not isinstance(self.n_samples, bool)
            and self.n_samples >= 100,
            "n_samples",
            self.n_samples,
            "must be an integer >= 100",
        )
        require(
            self.random_state is None
            or (
                isinstance(self.random_state, (int, np.integer))
                and not isinstance(self.random_state, bool)
                and self.random_state >= 0
            ),
            "random_state",
            self.random_state,
            "must be None or an integer >= 0",
        )

    @property
    def design_id(self) -> tuple[str, str | None]:
        """(name, fingerprint) of the model's design; a preset's fingerprint when only a
        preset name was given (model files from before fingerprints)."""
        return model_design(self.design, self.design_fingerprint)

    def _is_fitted(self) -> bool:
        return hasattr(self, "forms_")

    def _require_fitted(self) -> None:
        if not self._is_fitted():
            raise PRSMHealthError(
                "the prognostics model is not fitted: call fit(histories, failure_ages) first"
            )

    # ---------------------------------------------------------------------------- fitting

    def fit(self, histories: pd.DataFrame, failure_ages: Mapping) -> RULModel:
        """Fit both methods on a training fleet run to failure.

        Parameters
        ----------
        histories : pandas.DataFrame
            Column ``unit_id`` plus :data:`HISTORY_COLUMNS`: each training unit's diagnoses
            over its life (ages [h], clearances [m]); each unit needs >= 2 diagnoses.
        failure_ages : Mapping
            Unit id -> true age at failure [h] (when its true clearance reached
            ``threshold``), > 0 for every unit in ``histories``.

        Returns
        -------
        RULModel
            self.

        Raises
        ------
        ParameterError
            Invalid parameters, fewer than 3 units, a unit without a failure age, a unit's
            history failing :func:`validate_history` (the message names the unit), a fleet
            that starts at or above the threshold.
        """
        self._check_params()
        require(
            isinstance(histories, pd.DataFrame) and "unit_id" in histories.columns,
            "histories",
            type(histories).__name__,
            "must be a pandas DataFrame with a unit_id column",
        )
        if isinstance(failure_ages, pd.Series):
            failure_ages = failure_ages.to_dict()
        require(
            isinstance(failure_ages, Mapping),
            "failure_ages",
            type(failure_ages).__name__,
            "must be a mapping unit_id -> age at failure [h]",
        )
        units, parts, lives = [], [], []
        for uid, rows in histories.groupby("unit_id", sort=True):
            uid = uid.item() if isinstance(uid, np.generic) else uid
            try:
                part = validate_history(rows, self)
            except HistoryError as err:
                raise HistoryError(f"unit {uid!r}: {err}", err.field, err.value) from None
            require(uid in failure_ages, "failure_ages", uid, "has no failure age for this unit")
            life = failure_ages[uid]
            require(
                isinstance(life, (int, float, np.number)) and math.isfinite(life) and life > 0,
                f"failure_ages[{uid!r}]",
                life,
                "must be a finite age > 0 [h]",
            )
            units.append(uid)
            parts.append(part)
            lives.append(float(life))
        require(
            len(units) >= MIN_TRAINING_UNITS,
            "histories",
            f"{len(units)} unit(s)",
            f"a prognostics model needs at least {MIN_TRAINING_UNITS} training units",
        )
        lives = np.array(lives)
        c_ref = float(min(p["clearance"].iloc[0] for p in parts))
        require(
            self.threshold > c_ref,
            "threshold",
            float(self.threshold),
            f"must exceed the fleet's initial clearance {c_ref:.6g} m",
        )
        self.units_ = units
        self.failure_ages_ = lives
        self.t_scale_ = float(np.median(lives))
        self.horizon_ = HORIZON_FACTOR * float(lives.max())
        self.c_ref_ = c_ref

        codes = np.concatenate([np.full(len(p), i) for i, p in enumerate(parts)])
        t, value, sd = (np.concatenate(x) for x in zip(*(history_arrays(p) for p in parts)))
        tau = t / self.t_scale_
        n_units = len(units)
        thr = float(self.threshold)

        phi = profile_phi(tau, value, sd, codes, n_units, c_ref, thr)
        self.forms_ = {}
        for form in _FORMS:
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
        self.loo_rmse_ = {form: self._loo_rmse(form, codes, tau, t, value, sd) for form in _FORMS}
        self.form_ = min(_FORMS, key=lambda f: (self.loo_rmse_[f], _FORMS.index(f)))
        return self

    def _loo_rmse(self, form, codes, tau, t, value, sd) -> float:
        """Leave-one-unit-out RMSE of RUL [h] of one form over every prefix of >= 2 rows."""
        state = self.forms_[form]
        thr = float(self.threshold)
        y, m, _ = transform(form, value, sd, state["phi"], thr)
        w = 1.0 / (state["sigma2"] + m)
        y_d = y_threshold(form, state["phi"], thr)
        errors = []
        for u in range(len(self.units_)):
            keep = np.arange(len(self.units_)) != u
            mean0, cov0 = prior(state["params"][keep])
            p0 = np.linalg.inv(cov0)
            r0 = p0 @ mean0
            rows = codes == u
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
                crossing = np.where(b > 0, (y_d - a) / b, np.inf) * self.t_scale_
            ages = t[rows]
            rul = np.clip(crossing - ages, 0.0, self.horizon_)
            rul = np.where(value[rows] >= thr, 0.0, rul)
            true = self.failure_ages_[u] - ages
            use = (np.arange(rows.sum()) >= 1) & (true >= 0)
            errors.append(rul[use] - true[use])
        errors = np.concatenate(errors)
        return float(np.sqrt(np.mean(errors**2))) if errors.size else math.inf

    # ---------------------------------------------------------------------------- prediction

    def predict(self, history: pd.DataFrame, method=None) -> Prognosis:
        """RUL of the unit whose diagnoses ``history`` holds.

        Parameters
        ----------
        history : pandas.DataFrame
            One unit's diagnoses (:data:`HISTORY_COLUMNS`; checked by
            :func:`validate_history`).
        method : str, optional
            One of :data:`METHODS`; default ``self.method``.

        Returns
        -------
        Prognosis
            RUL [h] with its 90 % interval, the health indicator, the model, warnings.

        Raises
        ------
        HistoryError
            A history :func:`validate_history` refuses.
        ParameterError
            An unknown method.
        PRSMHealthError
            An unfitted model.
        """
        self._require_fitted()
        method = self._resolve_method(method)
        clean = validate_history(history, self)
        return self._predict_arrays(*history_arrays(clean), method, duty_arrays(clean))

    def predict_prefixes(self, history: pd.DataFrame, method=None, min_rows: int = 2) -> list:
        """Prognoses at every prefix of the history, each from the rows up to it only.

        Parameters
        ----------
        history : pandas.DataFrame
            One unit's diagnoses, validated once by :func:`validate_history`.
        method : str, optional
            One of :data:`METHODS`; default ``self.method``.
        min_rows : int, default 2
            Shortest prefix predicted from (>= 2).

        Returns
        -------
        list of Prognosis
            One per prefix of ``min_rows`` … ``len(history)`` rows, in age order.
        """
        self._require_fitted()
        method = self._resolve_method(method)
        require(
            isinstance(min_rows, (int, np.integer)) and min_rows >= 2,
            "min_rows",
            min_rows,
            "must be an integer >= 2",
        )
        clean = validate_history(history, self)
        t, value, sd = history_arrays(clean)
        if method == "physics":  # one pass of the filter gives every prefix's prediction
            ruls = self._ageing().predict_prefix_arrays(
                t, value, sd, min_rows=min_rows, **duty_arrays(clean)
            )
            return [
                self._prognosis(t[:k], value[:k], sd[:k], *self._physics(rul))
                for k, rul in zip(range(min_rows, len(t) + 1), ruls)
            ]
        return [
            self._predict_arrays(t[:k], value[:k], sd[:k], method)
            for k in range(min_rows, len(t) + 1)
        ]

    def _resolve_method(self, method) -> str:
        method = self.method if method is None else method
        require(method in METHODS, "method", method, f"must be one of {', '.join(METHODS)}")
        return method

    def _predict_arrays(self, t, value, sd, method, duty=None) -> Prognosis:
        if method == "similarity":
            rul, model = self._similarity(t, value, sd)
            more = []
        elif method == "physics":
            result = self._ageing().predict_arrays(t, value, sd, **(duty or {}))
            rul, model, more = self._physics(result)
        else:
            form = self.form_ if method == "degradation" else method.split("-", 1)[1]
            rul, model, more = self._degradation(form, t, value, sd)
        return self._prognosis(t, value, sd, rul, model, more)

    def _prognosis(self, t, value, sd, rul, model, more) -> Prognosis:
        thr = float(self.threshold)
        warnings = self._history_warnings(t, value, sd) + list(more)
        indicator = {
            "name": "clearance",
            "unit": "m",
            "threshold": thr,
            "ages_hours": t.tolist(),
            "values": value.tolist(),
            "lower": (value - Z90 * sd).tolist(),
            "upper": (value + Z90 * sd).tolist(),
            "current": float(value[-1]),
        }
        if value[-1] >= thr:
            warnings.insert(
                0,
                f"threshold already crossed: the latest clearance {value[-1]:.4g} m is at or "
                f"above the threshold {thr:.4g} m; RUL 0",
            )
            rul = {"estimate": 0.0, "lower": 0.0, "upper": 0.0}
        return Prognosis(rul_hours=rul, health_indicator=indicator, model=model, warnings=warnings)

    def _base_model_dict(self, name: str) -> dict:
        return {
            "name": name,
            "version": __version__,
            "design": self.design,
            "design_fingerprint": self.design_id[1],
            "units_trained": len(self.units_),
            "threshold": float(self.threshold),
            "horizon_hours": self.horizon_,
        }

    def _history_warnings(self, t, value, sd) -> list:
        warnings = []
        span = float(t[-1] - t[0])
        median_life = float(np.median(self.failure_ages_))
        if span < SHORT_HISTORY_FRACTION * median_life:
            warnings.append(
                f"history shorter than the model's minimum span: {span:.4g} h < "
                f"{SHORT_HISTORY_FRACTION:.0%} of the training fleet's median life "
                f"({median_life:.4g} h); the RUL mostly reflects the fleet"
            )
        if t[-1] > self.failure_ages_.max():
            warnings.append(
                f"unit age {t[-1]:.4g} h is beyond the longest training life "
                f"{self.failure_ages_.max():.4g} h: the RUL is extrapolated"
            )
        w = 1.0 / (sd**2 + (1e-8 * float(self.threshold)) ** 2)
        tm = np.sum(w * t) / np.sum(w)
        slope = np.sum(w * (t - tm) * value)
        if slope <= 0:
            warnings.append(
                "health indicator decreasing: no wear trend yet, interval is the fleet's"
            )
        return warnings

    def _degradation(self, form, t, value, sd):
        state = self.forms_[form]
        thr = float(self.threshold)
        phi = state["phi"]
        y, m, below = transform(form, value, sd, phi, thr)
        warnings = []
        if below.any():
            warnings.append(
                f"{int(below.sum())} of {len(value)} diagnoses at or below the model's baseline "
                f"phi = {phi:.4g} m (the fleet's initial clearance level minus a margin): "
                "clipped; this unit starts tighter than the training fleet"
            )
        tau = t / self.t_scale_
        mean, cov = posterior(state["mean"], state["cov"], tau, y, state["sigma2"] + m)
        rng = np.random.default_rng(self.random_state)
        draws = sample_gaussian(rng, mean, cov, int(self.n_samples))
        eps = rng.standard_normal(int(self.n_samples)) * math.sqrt(state["sigma2"])
        a, b = draws[:, 0], draws[:, 1]
        y_d = y_threshold(form, phi, thr)
        with np.errstate(divide="ignore", invalid="ignore"):
            crossing = np.where(b > 0, (y_d - a - eps) / b, np.inf) * self.t_scale_
        rul = crossing - t[-1]
        capped = float(np.mean(rul >= self.horizon_))
        rul = np.clip(rul, 0.0, self.horizon_)
        low, mid, high = np.quantile(rul, QUANTILES)
        if capped > CAPPED_WARNING_FRACTION:
            warnings.append(
                f"{capped:.0%} of the posterior samples never reach the threshold (wear rate "
                f"<= 0) or reach it beyond the horizon; their RUL is capped at {self.horizon_:.4g} "
                f"h ({HORIZON_FACTOR:g}x the fleet's longest life)"
            )
        scale = (
            np.array([1.0, 1.0 / self.t_scale_])
            if form == "exponential"
            else np.array([thr, thr / self.t_scale_])
        )
        model = self._base_model_dict(f"degradation-{form}")
        model.update(
            {
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
        )
        rul_hours = {"estimate": float(mid), "lower": float(low), "upper": float(high)}
        return rul_hours, model, warnings

    def _ageing(self):
        ageing = getattr(self, "ageing_", None)
        if ageing is None:
            raise PRSMHealthError(
                "this prognostics model has no physics part: fit it with "
                "fit_prognostics_model on a fleet dataset (its [life] recipe gives the physics)"
            )
        return ageing

    def _physics(self, result: dict):
        """A physics prediction (:class:`~prsm_health.prognostics.ageing_rul.AgeingRUL`) as
        (RUL, model dict, warnings)."""
        from .ageing_model import PRSMAgeing  # progpy: imported only where prognostics run

        ageing = self._ageing()
        rul = {k: result[k] for k in ("estimate", "lower", "upper")}
        model = self._base_model_dict("physics")
        model.update(
            {
                "states": list(PRSMAgeing.states),
                "posterior": result["posterior"],
                "failure_clearance": ageing.tables["failure_clearance"],
                "n_particles": ageing.n_particles,
                "n_samples": ageing.n_samples,
                "capped_fraction": result["capped_fraction"],
            }
        )
        warnings = []
        if result["capped_fraction"] > CAPPED_WARNING_FRACTION:
            warnings.append(
                f"{result['capped_fraction']:.0%} of the predicted units do not reach the wear "
                f"limit within the horizon; their RUL is capped at {ageing.horizon:.4g} h"
            )
        return rul, model, warnings

    def _similarity(self, t, value, sd):
        state = self.forms_[self.form_]
        rul, details = similarity_rul(
            state["params"],
            state["residual_var"],
            form=self.form_,
            phi=state["phi"],
            threshold=float(self.threshold),
            lives=self.failure_ages_,
            t_scale=self.t_scale_,
            horizon=self.horizon_,
            t=t,
            value=value,
            sd=sd,
        )
        model = self._base_model_dict("similarity")
        model.update(details)
        model["nearest_unit"] = self.units_[model.pop("nearest")]
        return rul, model

    # ---------------------------------------------------------------------------- persistence

    def to_dict(self) -> dict:
        """Plain JSON-able dict of the parameters and the fitted state (no pickle)."""
        out = {
            "format": _FORMAT,
            "format_version": _FORMAT_VERSION,
            "version": __version__,
            "params": {
                "method": self.method,
                "threshold": self.threshold,
                "design": self.design,
                "design_fingerprint": self.design_fingerprint,
                "n_samples": self.n_samples,
                "random_state": self.random_state,
            },
            "fitted": None,
        }
        if self._is_fitted():
            out["fitted"] = {
                "units": list(self.units_),
                "failure_ages": self.failure_ages_,
                "t_scale": self.t_scale_,
                "horizon": self.horizon_,
                "c_ref": self.c_ref_,
                "form": self.form_,
                "selection_rule": "lower leave-one-unit-out RMSE of RUL on the training fleet",
                "loo_rmse": dict(self.loo_rmse_),
                "forms": self.forms_,
                "ageing": None
                if getattr(self, "ageing_", None) is None
                else self.ageing_.to_dict(),
            }
        return json_ready(out)

    @classmethod
    def from_dict(cls, d: dict) -> RULModel:
        """Rebuild a model from :meth:`to_dict` output.

        Raises
        ------
        PRSMHealthError
            Not a prognostics-model dict, or a malformed one (one line naming the problem).
        ModelVersionError
            A dict of another format version.
        """
        if not isinstance(d, dict) or d.get("format") != _FORMAT:
            raise PRSMHealthError("not a prsm_health prognostics model (unknown format)")
        if d.get("format_version") != _FORMAT_VERSION:
            raise ModelVersionError(
                f"prognostics model format version {d.get('format_version')!r}; this "
                f"prsm_health {__version__} reads version {_FORMAT_VERSION}"
            )
        try:
            model = cls(**d["params"])
            model._check_params()
            fitted = d["fitted"]
            if fitted is not None:
                model.units_ = list(fitted["units"])
                model.failure_ages_ = np.asarray(fitted["failure_ages"], dtype=np.float64)
                model.t_scale_ = float(fitted["t_scale"])
                model.horizon_ = float(fitted["horizon"])
                model.c_ref_ = float(fitted["c_ref"])
                model.loo_rmse_ = {f: float(fitted["loo_rmse"][f]) for f in _FORMS}
                form = fitted["form"]
                if form not in _FORMS:
                    raise ValueError(f"unknown form {form!r}")
                model.form_ = form
                forms = {}
                for name in _FORMS:
                    s = fitted["forms"][name]
                    forms[name] = {
                        "phi": float(s["phi"]),
                        "sigma2": float(s["sigma2"]),
                        "mean": np.asarray(s["mean"], dtype=np.float64).reshape(2),
                        "cov": np.asarray(s["cov"], dtype=np.float64).reshape(2, 2),
                        "params": np.asarray(s["params"], dtype=np.float64).reshape(-1, 2),
                        "residual_var": np.asarray(s["residual_var"], dtype=np.float64),
                    }
                    units = len(model.units_)
                    if len(forms[name]["params"]) != units or len(model.failure_ages_) != units:
                        raise ValueError("unit count mismatch")
                    if not all(np.all(np.isfinite(v)) for v in forms[name].values()):
                        raise ValueError("non-finite parameter")
                model.forms_ = forms
                if fitted.get("ageing") is not None:
                    from .ageing_rul import AgeingRUL

                    model.ageing_ = AgeingRUL.from_dict(fitted["ageing"])
        except ParameterError as err:
            raise PRSMHealthError(f"malformed prognostics model ({one_line(err)})") from None
        except (KeyError, TypeError, ValueError, AttributeError) as err:
            what = f"missing {err}" if isinstance(err, KeyError) else one_line(err)
            raise PRSMHealthError(f"malformed prognostics model ({what})") from None
        return model


def prognose(history: pd.DataFrame, model: RULModel, method=None) -> Prognosis:
    """RUL of one unit: :func:`validate_history` then :meth:`RULModel.predict`.

    Parameters
    ----------
    history : pandas.DataFrame
        One unit's diagnoses (:data:`HISTORY_COLUMNS`).
    model : RULModel
        A fitted model.
    method : str, optional
        One of :data:`METHODS`; default ``model.method``.

    Returns
    -------
    Prognosis
    """
    require(
        isinstance(model, RULModel),
        "model",
        type(model).__name__,
        "must be a RULModel",
    )
    clean = validate_history(history, model)
    return model.predict(clean, method=method)
