"""The physics method of RUL (:class:`PhysicsRUL`): the PRSM's ageing model, progpy's particle
filter on a unit's diagnoses, progpy's Monte Carlo predictor to the wear limit.

:class:`AgeingRUL` holds the model's physics (the rate tables of
:func:`~prsm_health.prognostics.ageing_model.rate_tables`, from the fleet recipe's ``[life]``),
what it learnt from a training fleet — the diagnosis' calibration against the true clearance
and the prior of the units' two uncertain parameters — and predicts a unit's RUL:

1. **Estimation** (progpy ``ParticleFilter``; Daigle & Goebel 2013's joint state–parameter
   estimation): ``n_particles`` particles drawn from the prior (installed clearance uniform on
   the training units' range, :func:`installed_range`; the usage at its stationary law, ``log_wear`` and
   ``log_lubricant_life`` Gaussian) start at age 0 and are propagated to each diagnosis,
   weighted by its likelihood — the diagnosis' 90 % interval, scaled by the calibration's
   ``noise_scale``, as the measurement's standard deviation — and resampled.
2. **Prediction** (progpy ``MonteCarlo``): ``n_samples`` of the particles simulated under the
   unit's expected duty (``load``, × the recipe's loads) until their mean half-clearance
   reaches the limit; RUL = time of event − age; median and 5–95 % quantiles; samples that do
   not reach it within the horizon get the horizon.

Fitting (:meth:`AgeingRUL.fit`): the calibration is an ordinary least-squares line of the
diagnosed clearance on the true mean clearance over the training snapshots (``bias``,
``gain``) and the RMS of its standardised residuals (``noise_scale``); the prior is empirical
Bayes — each training unit filtered from a broad prior over its whole history, the prior's
mean and covariance those of the units' posterior means plus their mean posterior covariance.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from prsm_health.core.errors import require

from .history import duty_arrays, history_arrays
from .method import CAPPED_WARNING_FRACTION, Estimate, RULMethod, TrainingFleet, UnitHistory
from .prognosis import QUANTILES

#: Broad prior of (log_wear, log_lubricant_life) the training units are filtered from.
BROAD_PRIOR_SD = (1.0, 0.7)
#: Random-walk rate of the parameter particles in the filter [1/√h] (they would otherwise
#: collapse onto a few values after resampling; 0.005·√1000 h ≈ 0.16 in ln per 1000 h).
PARAMETER_DRIFT = 0.005
#: Particles of the filter and, of them, samples of the prediction. On the health-check fleet
#: (10 checks per life, 4-fold over 20 units) 1000 particles and 300 samples scored α–λ after
#: half of life 0.85 / 0.84 (10 / 20 checks) against 0.81 / 0.77 with 300 particles — the
#: parameter posterior of a short, precise history is narrow, and 300 particles resolve it
#: coarsely (docs/prognostics.md).
N_PARTICLES = 1000
N_SAMPLES = 300
#: Longest step [h] the filter propagates its particles by between diagnoses (the lubricant's
#: depletion, which sets the wear rate, changes by ≤ 50/T_lube ≈ 1 % per step).
FILTER_STEP = 50.0


def _systematic_resample(rng):
    """Systematic resampling (Kitagawa 1996) from ``rng``: progpy's default draws from NumPy's
    global generator, which would make a prediction depend on the caller's other draws."""

    def resample(weights):
        n = len(weights)
        positions = (rng.random() + np.arange(n)) / n
        cumulative = np.cumsum(weights)
        cumulative[-1] = 1.0
        return np.searchsorted(cumulative, positions)

    return resample


class AgeingRUL:
    """The ageing model's RUL predictor (module docstring).

    Parameters
    ----------
    tables : dict
        :func:`~prsm_health.prognostics.ageing_model.rate_tables` of the fleet recipe.
    initial_clearance : (float, float) [m]
        The range of installed clearances at age 0 (:func:`installed_range`).
    prior_mean, prior_cov
        Gaussian prior of (log_wear, log_lubricant_life).
    bias, gain, noise_scale
        The diagnosis' calibration (module docstring).
    horizon : float [h]
        RUL cap.
    n_particles, n_samples : int
        Particles of the filter; of them, samples of the prediction.
    seed : int
        Every prediction restarts from it.
    """

    def __init__(
        self,
        tables: dict,
        *,
        initial_clearance=(3e-6, 8e-6),
        prior_mean=(0.0, 0.0),
        prior_cov=((BROAD_PRIOR_SD[0] ** 2, 0.0), (0.0, BROAD_PRIOR_SD[1] ** 2)),
        bias: float = 0.0,
        gain: float = 1.0,
        noise_scale: float = 1.0,
        horizon: float = 1e5,
        n_particles: int = N_PARTICLES,
        n_samples: int = N_SAMPLES,
        seed: int = 0,
    ):
        self.tables = {
            k: (np.asarray(v) if k.startswith("rate_") else v) for k, v in tables.items()
        }
        self.initial_clearance = tuple(float(v) for v in initial_clearance)
        self.prior_mean = np.asarray(prior_mean, dtype=float).reshape(2)
        self.prior_cov = np.asarray(prior_cov, dtype=float).reshape(2, 2)
        self.bias, self.gain, self.noise_scale = float(bias), float(gain), float(noise_scale)
        self.horizon = float(horizon)
        self.n_particles, self.n_samples, self.seed = int(n_particles), int(n_samples), int(seed)

    # ------------------------------------------------------------------ the model and filter
    def model(self, seed: int):
        from .ageing_model import PRSMAgeing

        return PRSMAgeing(
            **self.tables,
            bias=self.bias,
            gain=self.gain,
            reference_clearance=float(np.mean(self.initial_clearance)),
            seed=seed,
        )

    def prior_particles(self, rng, mean, cov, n: int | None = None) -> dict:
        """``n`` (default ``n_particles``) draws of the filter's state from the prior: the
        clearances uniform in ``initial_clearance``, (log wear, log lubricant life) normal with
        ``mean`` and ``cov``, no degradation yet; a dict of arrays by state name."""
        n = self.n_particles if n is None else int(n)
        b0 = rng.uniform(*self.initial_clearance, n)
        params = rng.multivariate_normal(mean, cov, n)
        return {
            "b_screw": b0,
            "b_nut": b0.copy(),
            "degradation": np.zeros(n),
            "usage": rng.standard_normal(n),
            "log_wear": params[:, 0],
            "log_lubricant_life": params[:, 1],
        }

    def filtered(self, t, value, sd, *, load=None, usage_rate=None):
        """Filter a history: yields ``(k, model, filter)`` after each diagnosis k (ages ``t``
        [h], diagnosed clearances ``value`` [m], their standard deviations ``sd`` [m]; the
        duty log over the interval before each diagnosis, where known — the load factor
        ``load`` (default 1) and the ``usage_rate``, :func:`~prsm_health.prognostics.history.duty_arrays`)."""
        from progpy.state_estimators import ParticleFilter
        from progpy.uncertain_data import UnweightedSamples

        rng = np.random.default_rng(self.seed)
        model = self.model(int(rng.integers(2**31)))
        model.parameters["parameter_drift"] = PARAMETER_DRIFT
        x0 = self.prior_particles(rng, self.prior_mean, self.prior_cov)
        samples = UnweightedSamples(
            [{k: float(v[i]) for k, v in x0.items()} for i in range(self.n_particles)],
            _type=model.StateContainer,
        )
        filt = ParticleFilter(
            model,
            samples,
            t0=0.0,  # no num_particles: progpy would redraw them from NumPy's global generator
            resample_fcn=_systematic_resample(rng),
            measurement_noise={"clearance": 1e-6},
        )
        loads = np.ones(len(t)) if load is None else np.asarray(load, dtype=float)
        rates = np.full(len(t), np.nan) if usage_rate is None else np.asarray(usage_rate, float)
        for k, (age, z, s) in enumerate(zip(t, value, sd)):
            noise = max(float(s) * self.noise_scale, 1e-9)
            filt.parameters["measurement_noise"] = {"clearance": noise}
            if age <= filt.t:  # a diagnosis at age 0, or two at one age: weight only
                age = filt.t + 1e-6
            step = min(FILTER_STEP, age - filt.t)
            u = {"load": float(loads[k]), "usage_rate": float(rates[k])}
            filt.estimate(float(age), u, {"clearance": float(z)}, dt=step)
            yield k, model, filt

    def _predict_from(self, model, filt, age: float, load: float) -> dict:
        from progpy.predictors import MonteCarlo
        from progpy.uncertain_data import UnweightedSamples

        # the samples drawn from the model's generator: progpy's own draw uses NumPy's global one
        keep = model.rng.choice(self.n_particles, min(self.n_samples, self.n_particles), False)
        particles = filt.particles
        samples = UnweightedSamples(
            [{k: float(np.ravel(particles[k])[i]) for k in particles.keys()} for i in keep],
            _type=model.StateContainer,
        )
        model.parameters["parameter_drift"] = 0.0  # the unit's parameters, not their jitter
        try:
            with warnings.catch_warnings():  # progpy's MonteCarlo calls its own deprecated pop
                warnings.simplefilter("ignore", DeprecationWarning)
                result = MonteCarlo(model).predict(
                    samples,
                    lambda t, x=None: model.InputContainer({"load": load, "usage_rate": math.nan}),
                    n_samples=len(keep),
                    dt=model.prediction_step,
                    horizon=self.horizon,
                    save_freq=self.horizon,
                    t0=float(age),
                )
        finally:
            model.parameters["parameter_drift"] = PARAMETER_DRIFT
        toe = np.array(
            [math.inf if s["wear"] is None else float(s["wear"]) for s in result.time_of_event]
        )
        rul = np.clip(toe - age, 0.0, self.horizon)
        low, mid, high = np.quantile(rul, QUANTILES)
        return {
            "estimate": float(mid),
            "lower": float(low),
            "upper": float(high),
            "capped_fraction": float(np.mean(rul >= self.horizon)),
        }

    def predict_arrays(self, t, value, sd, *, load=None, usage_rate=None, future_load=None) -> dict:
        """The RUL after the whole history (:meth:`predict_prefix_arrays`' last)."""
        return self.predict_prefix_arrays(
            t,
            value,
            sd,
            load=load,
            usage_rate=usage_rate,
            future_load=future_load,
            min_rows=len(t),
        )[-1]

    def predict_prefix_arrays(
        self, t, value, sd, *, load=None, usage_rate=None, future_load=None, min_rows: int = 2
    ) -> list[dict]:
        """The RUL after each prefix of ≥ ``min_rows`` diagnoses, in one pass of the filter
        (each prediction sees the diagnoses up to it only). The future duty: ``future_load``,
        default the latest logged load (1 without a log); its usage, the usage state's
        process."""
        require(len(t) >= 1, "history", len(t), "needs at least one diagnosis")
        out = []
        for k, model, filt in self.filtered(t, value, sd, load=load, usage_rate=usage_rate):
            if k + 1 >= min_rows:
                ahead = future_load
                if ahead is None:
                    ahead = 1.0 if load is None else float(np.asarray(load)[k])
                rul = self._predict_from(model, filt, float(filt.t), ahead)
                rul["posterior"] = self._posterior_summary(filt)
                out.append(rul)
        return out

    @staticmethod
    def _posterior_summary(filt) -> dict:
        from .ageing_model import _mean_clearance

        p = filt.particles
        mean = _mean_clearance({k: np.asarray(p[k]) for k in ("b_screw", "b_nut")})
        return {
            "clearance_mean_m": float(np.mean(mean)),
            "log_wear": [float(np.mean(p["log_wear"])), float(np.std(p["log_wear"]))],
            "log_lubricant_life": [
                float(np.mean(p["log_lubricant_life"])),
                float(np.std(p["log_lubricant_life"])),
            ],
        }

    # ------------------------------------------------------------------ fitting
    @classmethod
    def fit(
        cls,
        tables: dict,
        spec,
        histories,
        *,
        seed: int = 0,
        horizon: float | None = None,
        n_particles: int = N_PARTICLES,
        n_samples: int = N_SAMPLES,
    ):
        """Calibration and empirical-Bayes prior from training units (module docstring).

        ``histories``: the training units' diagnoses (``unit_id``, ``age_hours``,
        ``clearance``, ``clearance_lower``, ``clearance_upper``; ``clearance_mean_true`` for
        the calibration — without it the diagnosis is taken as unbiased) and
        ``failure_age_hours``.
        """
        if horizon is None:
            horizon = 3.0 * float(histories["failure_age_hours"].max())
        _, z, sd = history_arrays(histories)
        bias, gain, scale = 0.0, 1.0, 1.0
        initial = installed_range(histories, spec.scatter.initial_clearance)
        if "clearance_mean_true" in histories.columns:
            true = histories["clearance_mean_true"].to_numpy(float)
            gain, bias = np.polyfit(true, z, 1)
            residual = (z - (bias + gain * true)) / np.maximum(sd, 1e-9)
            scale = float(np.sqrt(np.mean(residual**2)))
        est = cls(
            tables,
            initial_clearance=initial,
            bias=bias,
            gain=gain,
            noise_scale=scale,
            horizon=horizon,
            n_particles=n_particles,
            n_samples=n_samples,
            seed=seed,
        )
        means, covs = [], []
        for _, unit in histories.sort_values(["unit_id", "age_hours"]).groupby("unit_id"):
            *_, (_, _, filt) = est.filtered(*history_arrays(unit), **duty_arrays(unit))
            params = np.column_stack(
                [
                    np.asarray(filt.particles["log_wear"]),
                    np.asarray(filt.particles["log_lubricant_life"]),
                ]
            )
            means.append(params.mean(axis=0))
            covs.append(np.cov(params.T))
        means = np.array(means)
        est.prior_mean = means.mean(axis=0)
        est.prior_cov = np.cov(means.T) + np.mean(covs, axis=0)
        return est

    # ------------------------------------------------------------------ persistence
    def to_dict(self) -> dict:
        return {
            "tables": {
                k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.tables.items()
            },
            "initial_clearance": list(self.initial_clearance),
            "prior_mean": self.prior_mean.tolist(),
            "prior_cov": self.prior_cov.tolist(),
            "bias": self.bias,
            "gain": self.gain,
            "noise_scale": self.noise_scale,
            "horizon": self.horizon,
            "n_particles": self.n_particles,
            "n_samples": self.n_samples,
            "seed": self.seed,
        }

    @classmethod
    def from_dict(cls, d: dict) -> AgeingRUL:
        d = dict(d)
        return cls(d.pop("tables"), **d)


def installed_range(histories, as_built: tuple) -> tuple[float, float]:
    """The prior's range of installed clearances at age 0 [m]: the training units' true
    installed clearance at their first diagnosis (the recipe's as-built threads plus each
    unit's assembly play, :meth:`~prsm_health.physics.life.UnitLife.clearance`), widened by a
    tenth of its span and 0.2 µm each side; the recipe's ``as_built`` range where the
    histories carry no truth."""
    if "clearance_mean_true" not in histories.columns:
        return tuple(float(v) for v in as_built)
    first = histories.sort_values("age_hours").groupby("unit_id")["clearance_mean_true"].first()
    lo, hi = float(first.min()), float(first.max())
    pad = 0.1 * (hi - lo) + 0.2e-6
    return max(lo - pad, 0.0), hi + pad


class PhysicsRUL(RULMethod):
    """The physics method: an :class:`AgeingRUL` behind the RUL-method interface.

    Parameters
    ----------
    tables : dict or None
        :func:`~prsm_health.prognostics.ageing_model.rate_tables` of the fleet recipe, for
        :meth:`fit`.
    spec : LifeSpec or None
        The fleet recipe's ``[life]``, for :meth:`fit`.
    seed : int
        Seed of the fitted estimator.
    estimator : AgeingRUL or None
        An estimator already fitted (e.g. read from a model file): ``estimator_``.
    """

    name = "physics"

    def __init__(self, tables=None, spec=None, *, seed: int = 0, estimator=None):
        self.tables, self.spec, self.seed = tables, spec, seed
        if estimator is not None:
            self.estimator_ = estimator

    def fit(self, fleet: TrainingFleet) -> PhysicsRUL:
        require(
            self.tables is not None and self.spec is not None,
            "physics",
            None,
            "needs the fleet recipe's rate tables and [life] to be fitted",
        )
        self.estimator_ = AgeingRUL.fit(
            self.tables,
            self.spec,
            fleet.histories,
            seed=self.seed,
            horizon=fleet.summary.horizon,
        )
        return self

    def predict(self, history: UnitHistory) -> Estimate:
        return self._estimate(
            self.estimator_.predict_arrays(history.t, history.value, history.sd, **history.duty)
        )

    def predict_prefixes(self, history: UnitHistory, min_rows: int) -> list[Estimate]:
        # one pass of the filter gives every prefix's prediction
        ruls = self.estimator_.predict_prefix_arrays(
            history.t, history.value, history.sd, min_rows=min_rows, **history.duty
        )
        return [self._estimate(rul) for rul in ruls]

    def _estimate(self, result: dict) -> Estimate:
        from .ageing_model import PRSMAgeing  # progpy: imported only where prognostics run

        ageing = self.estimator_
        model = {
            "name": self.name,
            "states": list(PRSMAgeing.states),
            "posterior": result["posterior"],
            "failure_clearance": ageing.tables["failure_clearance"],
            "n_particles": ageing.n_particles,
            "n_samples": ageing.n_samples,
            "capped_fraction": result["capped_fraction"],
        }
        warnings = []
        if result["capped_fraction"] > CAPPED_WARNING_FRACTION:
            warnings.append(
                f"{result['capped_fraction']:.0%} of the predicted units do not reach the wear "
                f"limit within the horizon; their RUL is capped at {ageing.horizon:.4g} h"
            )
        rul = {k: result[k] for k in ("estimate", "lower", "upper")}
        return Estimate(rul, model, warnings)
