"""The PRSM's ageing as a progpy :class:`~progpy.PrognosticsModel` (NASA's prognostics package).

The states, rates and failure are those of the life simulation
(:mod:`prsm_health.physics.life`, :mod:`prsm_health.physics.wear`): the model is built on the
project's own wear functions (:func:`~prsm_health.physics.life.wear_rates`), not a copy of them.
Time is in **operating hours** (the unit of every age in :mod:`prsm_health.prognostics`);
everything else SI.

States
    ``b_screw``, ``b_nut`` [m]: the installed half-clearances of the two thread engagements
    (threads plus the assembly's constant play: their mean is the life's installed clearance,
    :meth:`~prsm_health.physics.life.UnitLife.clearance`; wear rates do not depend on them);
    ``degradation`` [-]: the lubricant's additive depletion d (0 new … 1 used up);
    ``usage`` [-]: the unit's usage intensity, a unit-variance Ornstein–Uhlenbeck process
    (correlation time ``usage_time``): the wear rate is multiplied by exp(σ·usage − σ²/2),
    as in :class:`~prsm_health.physics.life_spec.FleetScatter`;
    ``log_wear`` [-]: ln of the unit's wear-rate factor against the duty's (its wear
    coefficient, its own loads and temperature against the duty's), and
    ``log_lubricant_life`` [-]: ln of its lubricant life against the duty's — the unit's
    uncertain parameters as augmented states, estimated with the clearances.
Inputs
    ``load`` [-]: the duty's loads multiply by it (1: the duty the model was built for; 2: the
    same missions at doubled load) — what the actuator's force or current log gives;
    ``usage_rate`` [-]: the usage intensity over the step, from the unit's duty log (its
    duty hours per operating hour); NaN where unknown (the future): the usage state's
    Ornstein–Uhlenbeck process then drives the wear.
Output
    ``clearance`` [m]: what the diagnosis reads, ``bias + gain·(b_screw + b_nut)/2`` (the
    diagnosis' calibration against the true mean clearance, learnt on training units).
Event
    ``wear``: the mean half-clearance (b_screw + b_nut)/2 reaches ``failure_clearance``, the
    life simulation's failure by wear (a spall's start is random — ISO 281's Weibull scatter —
    and is not predicted here: docs/prognostics.md).

Dynamics (exact per step with the degradation at mid-step): d grows at 1/T_lube until 1;
each half-clearance at ``rate_side(load, d)·exp(log_wear)·exp(σ·usage − σ²/2)``, the rate table
of :func:`~prsm_health.physics.life.wear_rates` at load factors :data:`LOAD_FACTORS`
(interpolated in ln load) and degradations :data:`~prsm_health.physics.life.DEGRADATION_GRID`.
Process noise: the usage's exact OU transition; a small random walk of the two parameters
(``parameter_drift``, per √h; it keeps a particle filter's parameter particles diverse, and is
0 in prediction). The noise is drawn from the model's own generator (``seed``), not NumPy's
global one.

References
----------
- C. Kulkarni, M. Daigle, et al., NASA prognostics python packages (progpy), v1.x:
  PrognosticsModel, ParticleFilter, MonteCarlo.
- M. Daigle, K. Goebel, "Model-based prognostics with concurrent damage progression
  processes", IEEE Trans. SMC: Systems 43 (2013) 535–546 (joint state–parameter estimation
  with a particle filter, the parameters as augmented states).
"""

from __future__ import annotations

import math

import numpy as np
from progpy import PrognosticsModel

from prsm_health.physics.life import DEGRADATION_GRID, lubricant_life_at, wear_rates
from prsm_health.physics.life_spec import LifeSpec
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.wear import PartGeometry

#: Load factors the rate tables are computed at (× the duty's loads).
LOAD_FACTORS = np.geomspace(0.25, 4.0, 17)


def rate_tables(design, spec: LifeSpec, ratings: dict | None = None) -> dict:
    """The model's physics parameters for a fleet recipe's ``[life]``: half-clearance growth
    rates [m/h] of the screw and nut engagements at :data:`LOAD_FACTORS` × the duty's loads
    and at every lubricant degradation, the duty's lubricant life at its temperature [h]."""
    if ratings is None:
        r = load_ratings(design)
        ratings = {"C_a": float(r.dynamic), "C_0a": float(r.static)}
    duty = spec.duty.resolved(ratings)
    geometry = PartGeometry.of(design)
    screw, nut = [], []
    for factor in LOAD_FACTORS:
        rates = wear_rates(
            design,
            duty,
            lubricant_name=spec.lubricant,
            wear=spec.wear,
            load_scale=float(factor),
            geometry=geometry,
        )
        screw.append(rates.clearance["screw"])
        nut.append(rates.clearance["nut"])
    return {
        "rate_screw": np.array(screw),
        "rate_nut": np.array(nut),
        "lubricant_life": lubricant_life_at(duty.lubricant_life, duty.temperature),
        "failure_clearance": spec.failure_clearance,
        "usage_sigma": spec.scatter.usage,
        "usage_time": spec.scatter.usage_time,
    }


def _mean_clearance(x):
    """The mean half-clearance (b_screw + b_nut)/2 [m]: what fails and what is measured."""
    return 0.5 * (x["b_screw"] + x["b_nut"])


def ageing_process_noise(model, x, dt=1.0):
    """The model's process noise (progpy's callable ``process_noise``): the usage's exact
    Ornstein–Uhlenbeck transition, and the parameters' random walk of ``parameter_drift``
    per √h, drawn from the model's own generator."""
    p = model.parameters
    keep = math.exp(-dt / p["usage_time"])
    shape = np.shape(x["usage"])
    x["usage"] = x["usage"] + math.sqrt(1.0 - keep * keep) * model.rng.standard_normal(shape)
    if p["parameter_drift"] > 0:
        step = p["parameter_drift"] * math.sqrt(dt)
        for key in ("log_wear", "log_lubricant_life"):
            x[key] = x[key] + step * model.rng.standard_normal(np.shape(x[key]))
    return x


class PRSMAgeing(PrognosticsModel):
    """A PRSM's thread wear over operating hours (module docstring: states, input, output,
    event, dynamics). Build its rate tables with :func:`rate_tables` and pass them as keyword
    parameters; vectorized (every state may be an array of particles)."""

    inputs = ["load", "usage_rate"]  # noqa: RUF012 (progpy's class attributes)
    states = [  # noqa: RUF012
        "b_screw",
        "b_nut",
        "degradation",
        "usage",
        "log_wear",
        "log_lubricant_life",
    ]
    outputs = ["clearance"]  # noqa: RUF012
    events = ["wear"]  # noqa: RUF012
    is_vectorized = True

    default_parameters = {  # noqa: RUF012
        "x0": {
            "b_screw": 5e-6,
            "b_nut": 5e-6,
            "degradation": 0.0,
            "usage": 0.0,
            "log_wear": 0.0,
            "log_lubricant_life": 0.0,
        },
        "rate_screw": np.zeros((len(LOAD_FACTORS), len(DEGRADATION_GRID))),
        "rate_nut": np.zeros((len(LOAD_FACTORS), len(DEGRADATION_GRID))),
        "lubricant_life": 2000.0,  # [h]
        "failure_clearance": 30e-6,  # [m]
        "usage_sigma": 0.15,
        "usage_time": 200.0,  # [h]
        "parameter_drift": 0.0,  # [1/√h]
        "bias": 0.0,  # [m]
        "gain": 1.0,
        "reference_clearance": 5e-6,  # [m]: event state 1 here, 0 at failure
        "measurement_noise": {"clearance": 2e-6},
        "process_noise": None,  # set below: ageing_process_noise (progpy's callable form)
        "seed": 0,
    }

    def __init__(self, **kwargs):
        self.rng = np.random.default_rng(kwargs.get("seed", 0))
        kwargs.setdefault("process_noise", ageing_process_noise)
        super().__init__(**kwargs)

    def _rates(self, load, degradation):
        """(ḃ_screw, ḃ_nut) [m/h] at load factor ``load`` and degradation d (broadcast)."""
        p = self.parameters
        position = np.interp(
            np.log(np.clip(load, LOAD_FACTORS[0], LOAD_FACTORS[-1])),
            np.log(LOAD_FACTORS),
            np.arange(len(LOAD_FACTORS)),
        )
        low = np.minimum(np.floor(position).astype(int), len(LOAD_FACTORS) - 2)
        frac = position - low
        d = np.clip(degradation, 0.0, 1.0) * (len(DEGRADATION_GRID) - 1)
        i = np.minimum(np.floor(d).astype(int), len(DEGRADATION_GRID) - 2)
        g = d - i
        out = []
        for table in (np.asarray(p["rate_screw"]), np.asarray(p["rate_nut"])):
            at = [table[row, i] * (1 - g) + table[row, i + 1] * g for row in (low, low + 1)]
            out.append(at[0] * (1 - frac) + at[1] * frac)
        return out

    def next_state(self, x, u, dt):
        p = self.parameters
        life = p["lubricant_life"] * np.exp(x["log_lubricant_life"])
        d_mid = np.minimum(x["degradation"] + 0.5 * dt / life, 1.0)
        sigma = p["usage_sigma"]
        keep = math.exp(-dt / p["usage_time"])
        measured = float(u["usage_rate"])
        if math.isfinite(measured):  # the duty log's intensity: the usage state follows it
            intensity = max(measured, 0.0)
            usage = np.full_like(np.asarray(x["usage"], dtype=float), 0.0)
            if sigma > 0 and intensity > 0:
                usage += (math.log(intensity) + 0.5 * sigma * sigma) / sigma
        else:
            intensity = np.exp(sigma * x["usage"] - 0.5 * sigma * sigma)
            usage = x["usage"] * keep
        factor = np.exp(x["log_wear"]) * intensity
        screw, nut = self._rates(u["load"], d_mid)
        return self.StateContainer(
            np.array(
                [
                    np.atleast_1d(x["b_screw"] + screw * factor * dt),
                    np.atleast_1d(x["b_nut"] + nut * factor * dt),
                    np.atleast_1d(np.minimum(x["degradation"] + dt / life, 1.0)),
                    np.atleast_1d(usage),
                    np.atleast_1d(x["log_wear"]),
                    np.atleast_1d(x["log_lubricant_life"]),
                ]
            )
        )

    def prediction_step(self, t, x) -> float:
        """A time step [h] for progpy's simulations (``dt=model.prediction_step``): a third
        of the time the unit would take to wear out at its present rate, within 1–200 h —
        long strides while the clearance is far from the limit, short ones near it, where the
        crossing is timed (to the 1 h of the last step; ≈ 20 steps to a limit 2 000 h away:
        progpy's Monte Carlo steps each sample in Python)."""
        p = self.parameters
        mean = _mean_clearance(x)
        screw, nut = self._rates(1.0, x["degradation"])
        rate = 0.5 * (screw + nut) * np.exp(x["log_wear"])
        with np.errstate(divide="ignore"):
            remaining = (p["failure_clearance"] - mean) / rate
        return float(np.clip(np.min(remaining / 3.0), 1.0, 200.0))

    def output(self, x):
        p = self.parameters
        mean = _mean_clearance(x)
        return self.OutputContainer(np.atleast_2d(p["bias"] + p["gain"] * mean))

    def event_state(self, x):
        p = self.parameters
        mean = _mean_clearance(x)
        span = p["failure_clearance"] - p["reference_clearance"]
        return {"wear": np.clip((p["failure_clearance"] - mean) / span, 0.0, 1.0)}

    def threshold_met(self, x):
        mean = _mean_clearance(x)
        return {"wear": mean >= self.parameters["failure_clearance"]}
