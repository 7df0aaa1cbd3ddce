"""What limits a RUL's α–λ accuracy? (docs/prognostics.md, "Below the 0.8 … and why")

Three measurements on the shipped fleet recipe (``--recipe``, default datasets/fleet-check.toml
``[life]``, its ``snapshots`` checks per life unless ``--snapshots``), α = 0.2, the
share of predictions after half of life within ±α of the true RUL:

``oracle``
    The progpy ageing model (:class:`~prsm_health.prognostics.ageing_model.PRSMAgeing`) run
    from each unit's *true* state and lubricant life — its wear factor set (bisection) so that
    its logged usage reproduces its failure age — to the limit, at every snapshot after half
    of life: with the true future usage, and with the future usage unknown (200 draws of the
    model's Ornstein–Uhlenbeck usage from its present level, the median). No estimation: what
    the model's form and the unknown future cost.
``noise``
    The physics method (progpy's particle filter and Monte Carlo predictor,
    :class:`~prsm_health.prognostics.ageing_rul.AgeingRUL`) on the life model's trajectories
    observed with a white Gaussian error of each ``--noise`` σ and the duty log known (14
    units fitted, 12 scored), and the degradation model beside it: what estimation from a
    noisy indicator costs.
``ideal``
    A near-ideal Bayesian estimator in the particle filter's place on the same noisy
    trajectories: importance sampling over the unit's as-built clearance and its two factors
    (``--draws`` prior draws, the filter's empirical-Bayes prior), each draw propagated without
    noise under the logged usage and weighted by every diagnosis so far; 200 resampled draws
    run to the limit under an unknown future usage (the OU process). What the data allow,
    whatever the estimator.
``ukf DIAGNOSES``
    progpy's unscented Kalman filter in the particle filter's place (same model, calibration
    and prior, prediction by progpy's Monte Carlo from 100 draws of its Gaussian posterior) on
    a fleet's cached diagnoses (``<dataset>-diagnoses.parquet`` of
    tools/release/train_prognostics_model.py), its held-out units.

    python tools/studies/prognostics_limits.py oracle [--units 12]          # ≈ 2 min
    python tools/studies/prognostics_limits.py noise [--noise 0.8e-6 1.6e-6]   # ≈ 4 min per σ
    python tools/studies/prognostics_limits.py ideal [--noise 0.1e-6 … 2e-6]   # ≈ 1 min per σ
    python tools/studies/prognostics_limits.py ukf build/fleet-diagnoses.parquet   # ≈ 1 min
"""

from __future__ import annotations

import argparse
import math
import warnings
from dataclasses import replace

import numpy as np
import pandas as pd

from prsm_health.actuator.design import preset
from prsm_health.datasets import load_recipe
from prsm_health.physics.life import fleet_lives
from prsm_health.prognostics import HISTORY_COLUMNS, RULModel, simulated_histories
from prsm_health.prognostics.ageing_model import PRSMAgeing, rate_tables
from prsm_health.prognostics.ageing_rul import FILTER_STEP, AgeingRUL
from prsm_health.prognostics.history import duty_arrays, history_arrays
from prsm_health.prognostics.metrics import evaluate_units, pooled_scores

ALPHA = 0.2
STEP = 5.0  # h, the oracle's integration step


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--recipe", default="datasets/fleet-check.toml")
    parser.add_argument("--snapshots", type=int, help="ages per life (default the recipe's)")
    sub = parser.add_subparsers(dest="study", required=True)
    oracle = sub.add_parser("oracle")
    oracle.add_argument("--units", type=int, default=12)
    noise = sub.add_parser("noise")
    noise.add_argument("--noise", type=float, nargs="+", default=[0.8e-6, 1.6e-6])
    ideal = sub.add_parser("ideal")
    ideal.add_argument("--noise", type=float, nargs="+", default=[0.1e-6, 0.3e-6, 0.8e-6, 2e-6])
    ideal.add_argument("--draws", type=int, default=20000)
    ukf = sub.add_parser("ukf")
    ukf.add_argument("diagnoses")
    args = parser.parse_args(argv)
    recipe = load_recipe(args.recipe)
    design = preset(recipe.design)
    spec = recipe.life_spec
    if args.snapshots:
        spec = replace(spec, snapshots=args.snapshots)
    tables = rate_tables(design, spec)
    if args.study == "oracle":
        run_oracle(design, spec, tables, args.units)
    elif args.study == "noise":
        run_noise(design, spec, tables, args.noise)
    elif args.study == "ideal":
        run_ideal(design, spec, tables, args.noise, args.draws)
    else:
        run_ukf(spec, tables, pd.read_parquet(args.diagnoses))


# ------------------------------------------------------------------------------------ oracle
def _advance(model, x, dt, load, usage_rate):
    nxt = model.next_state(
        model.StateContainer(x), model.InputContainer({"load": load, "usage_rate": usage_rate}), dt
    )
    return {k: np.ravel(nxt[k]).copy() for k in x}


def _time_to_limit(model, state, age, until, load, rng, n=1, logged=None):
    """Ages [h] at which n copies of ``state`` (scalars or arrays of n) reach the limit,
    stepping the model from ``age``; the usage from a unit's duty log (``logged``, a
    :class:`~prsm_health.physics.life.UnitLife`) or else the model's OU process, its noise
    drawn from ``rng``."""
    x = {k: np.broadcast_to(np.asarray(v, dtype=float), n).copy() for k, v in state.items()}
    spread = math.sqrt(1.0 - math.exp(-2.0 * STEP / model.parameters["usage_time"]))
    t, reached = age, np.full(n, math.inf)
    while t < until and np.isinf(reached).any():
        rate = math.nan
        if logged is not None:
            rate = (
                float(np.diff(np.interp([t, t + STEP], logged.ages, logged.duty_hours))[0]) / STEP
            )
        x = _advance(model, x, STEP, load, rate)
        if logged is None:
            x["usage"] = x["usage"] + spread * rng.standard_normal(n)  # OU: next_state decays it
        t += STEP
        hit = (
            0.5 * (x["b_screw"] + x["b_nut"]) >= model.parameters["failure_clearance"]
        ) & np.isinf(reached)
        reached[hit] = t
    return reached


def run_oracle(design, spec, tables, n_units: int) -> None:
    model = PRSMAgeing(**tables)
    sigma = tables["usage_sigma"]
    within = {"true future usage": [], "future usage unknown": []}
    for unit in fleet_lives(design, replace(spec, units=n_units), 12):
        if unit.failure_mode != "wear":
            continue
        life = math.log(unit.lubricant_life / tables["lubricant_life"])
        load = unit.load_scale
        start = {
            # installed half-clearances: the threads' plus the assembly's play (the life's truth)
            "b_screw": unit.initial_clearance + unit.assembly_play,
            "b_nut": unit.initial_clearance + unit.assembly_play,
            "degradation": 0.0,
            "usage": 0.0,
            "log_wear": 0.0,
            "log_lubricant_life": life,
        }
        low, high = math.log(unit.wear_scale) - 0.5, math.log(unit.wear_scale) + 0.5
        for _ in range(25):  # the wear factor whose logged usage fails the unit at its age
            mid = 0.5 * (low + high)
            state = {**start, "log_wear": mid}
            end = _time_to_limit(model, state, 0.0, 4 * unit.failure_age, load, None, logged=unit)
            low, high = (mid, high) if end[0] > unit.failure_age else (low, mid)
        wear = 0.5 * (low + high)
        for age in unit.snapshot_ages(spec.snapshots):
            if age < 0.5 * unit.failure_age:
                continue
            rul = unit.failure_age - age
            screw, nut = (float(v) + unit.assembly_play for v in unit.clearances(age))
            recent = np.diff(np.interp([age - 50.0, age], unit.ages, unit.duty_hours))[0] / 50.0
            state = {
                **start,
                "b_screw": screw,
                "b_nut": nut,
                "degradation": min(age / unit.lubricant_life, 1.0),
                "usage": (math.log(max(recent, 1e-9)) + 0.5 * sigma**2) / sigma,
                "log_wear": wear,
            }
            until = age + 4 * rul + 500.0
            known = _time_to_limit(model, state, age, until, load, None, logged=unit)[0] - age
            rng = np.random.default_rng(0)  # each prediction its own 200 usage futures
            drawn = np.median(_time_to_limit(model, state, age, until, load, rng, 200)) - age
            within["true future usage"].append(abs(known - rul) <= ALPHA * rul)
            within["future usage unknown"].append(abs(drawn - rul) <= ALPHA * rul)
    for label, hits in within.items():
        print(
            f"oracle, {label}: α–λ after half of life {np.mean(hits):.3f} ({len(hits)} predictions)"
        )


# ------------------------------------------------------------------------------------- noise
def run_noise(design, spec, tables, levels) -> None:
    train_lives = fleet_lives(design, replace(spec, units=14), 11)
    test_lives = fleet_lives(design, replace(spec, units=12), 12)
    for noise in levels:
        train = simulated_histories(
            train_lives, spec.snapshots, noise, np.random.default_rng(1), min_half_width=0.2e-6
        )
        test = simulated_histories(
            test_lives, spec.snapshots, noise, np.random.default_rng(2), min_half_width=0.2e-6
        )
        failure = train.groupby("unit_id")["failure_age_hours"].first().to_dict()
        model = RULModel(threshold=spec.failure_clearance).fit(
            train[["unit_id", *HISTORY_COLUMNS]], failure
        )
        model.ageing_ = AgeingRUL.fit(tables, spec, train, horizon=model.horizon_)
        lives = test.groupby("unit_id")["failure_age_hours"].first().to_dict()
        _, summary = evaluate_units(
            test, lives, model, alpha=ALPHA, methods=("degradation", "physics")
        )
        print(
            f"σ = {noise * 1e6:.2g} µm, duty log known: "
            + ", ".join(
                f"{m} α–λ {s['alpha_lambda']:.3f} (coverage {s['coverage_after']:.2f})"
                for m, s in summary.items()
            )
        )


# ------------------------------------------------------------------------------------- ideal
def _ideal_unit(model, unit, history, fitted, draws, noise, rng) -> list[bool]:
    """Within ±α of the true RUL, each prediction after half of the unit's life (``fitted``:
    the particle filter's :class:`AgeingRUL`, whose prior the draws come from)."""
    t = history["age_hours"].to_numpy()
    z = history["clearance"].to_numpy()
    duty = duty_arrays(history)
    rates = np.where(np.isfinite(duty["usage_rate"]), duty["usage_rate"], 1.0)
    loads = duty["load"]
    sigma = model.parameters["usage_sigma"]
    x = fitted.prior_particles(rng, fitted.prior_mean, fitted.prior_cov, draws)
    log_lik, now, hits = np.zeros(draws), 0.0, []
    for k in range(len(t)):
        while now < t[k] - 1e-9:  # the logged usage over the interval before diagnosis k
            step = min(FILTER_STEP, t[k] - now)
            x = _advance(model, x, step, float(loads[k]), float(rates[k]))
            now += step
        log_lik -= 0.5 * ((z[k] - 0.5 * (x["b_screw"] + x["b_nut"])) / noise) ** 2
        if not 0.5 * unit.failure_age <= t[k] < unit.failure_age:
            continue
        weight = np.exp(log_lik - log_lik.max())
        pick = rng.choice(draws, 200, p=weight / weight.sum())
        picked = {key: value[pick] for key, value in x.items()}
        picked["usage"] = (math.log(max(rates[k], 1e-9)) + 0.5 * sigma**2) / sigma
        until = t[k] + 5 * unit.failure_age
        reached = _time_to_limit(model, picked, t[k], until, float(loads[k]), rng, 200)
        rul = unit.failure_age - t[k]
        hits.append(abs(np.median(reached) - t[k] - rul) <= ALPHA * rul)
    return hits


def run_ideal(design, spec, tables, levels, draws: int) -> None:
    model = PRSMAgeing(**tables)
    test_lives = fleet_lives(design, replace(spec, units=12), 12)
    for noise in levels:
        train = simulated_histories(
            fleet_lives(design, replace(spec, units=14), 11),
            spec.snapshots,
            noise,
            np.random.default_rng(1),
            min_half_width=0.2e-6,
        )
        fitted = AgeingRUL.fit(tables, spec, train)
        test = simulated_histories(
            test_lives, spec.snapshots, noise, np.random.default_rng(2), min_half_width=0.2e-6
        )
        rng = np.random.default_rng(0)
        hits = []
        for unit in test_lives:
            history = test[test["unit_id"] == unit.unit_id].sort_values("age_hours")
            hits += _ideal_unit(model, unit, history, fitted, draws, noise, rng)
        print(
            f"σ = {noise * 1e6:.2g} µm, near-ideal estimator: α–λ after half of life "
            f"{np.mean(hits):.3f} ({len(hits)} predictions)"
        )


# --------------------------------------------------------------------------------------- ukf
def run_ukf(spec, tables, histories: pd.DataFrame) -> None:
    from progpy.predictors import MonteCarlo
    from progpy.state_estimators import UnscentedKalmanFilter
    from progpy.uncertain_data import MultivariateNormalDist

    train = histories[histories["split"] == "train"]
    estimator = AgeingRUL.fit(tables, spec, train)
    low, high = estimator.initial_clearance
    keys = PRSMAgeing.states
    rows = []
    for uid, unit in histories[histories["split"] == "test"].groupby("unit_id"):
        unit = unit.sort_values("age_hours")
        failure = float(unit["failure_age_hours"].iloc[0])
        t, z, sd = history_arrays(unit)
        duty = duty_arrays(unit)
        loads = np.ones(len(t)) if duty["load"] is None else duty["load"]
        rates = np.full(len(t), np.nan) if duty["usage_rate"] is None else duty["usage_rate"]
        model = PRSMAgeing(
            **estimator.tables,
            bias=estimator.bias,
            gain=estimator.gain,
            reference_clearance=0.5 * (low + high),
            process_noise=dict.fromkeys(keys, 0.0),  # the UKF adds its own Q
        )
        cov = np.zeros((6, 6))
        cov[:2, :2] = (high - low) ** 2 / 12 * np.array([[1.0, 0.999], [0.999, 1.0]])
        cov[2, 2], cov[3, 3], cov[4:, 4:] = 1e-12, 1.0, estimator.prior_cov
        mean = [0.5 * (low + high)] * 2 + [0.0, 0.0, *estimator.prior_mean]
        filt = UnscentedKalmanFilter(
            model,
            MultivariateNormalDist(keys, mean, cov),
            Q=np.diag([1e-16, 1e-16, 1e-10, 0.05, 1e-4, 1e-4]),
            R=np.array([[1e-12]]),
            t0=0.0,
        )
        for k, (age, value, s) in enumerate(zip(t, z, sd)):
            age = max(float(age), filt.t + 1e-6)
            filt.filter.R = np.array([[(max(s, 1e-9) * estimator.noise_scale) ** 2]])
            u = model.InputContainer({"load": float(loads[k]), "usage_rate": float(rates[k])})
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                filt.estimate(
                    age, u, {"clearance": float(value)}, dt=min(FILTER_STEP, age - filt.t)
                )
                if k < 1:
                    continue
                future = model.InputContainer({"load": float(loads[k]), "usage_rate": math.nan})
                result = MonteCarlo(model).predict(
                    filt.x.sample(100),
                    lambda _t, _x=None, future=future: future,
                    n_samples=100,
                    dt=model.prediction_step,
                    horizon=1e4,
                    save_freq=1e4,
                    t0=filt.t,
                )
            toe = np.array(
                [math.inf if e["wear"] is None else e["wear"] for e in result.time_of_event]
            )
            rul = np.clip(toe - filt.t, 0.0, 1e4)
            low_q, mid, high_q = np.quantile(rul, (0.05, 0.5, 0.95))
            rows.append((uid, float(t[k]), failure - float(t[k]), mid, low_q, high_q))
    predictions = pd.DataFrame(
        rows, columns=["unit_id", "age_hours", "true_rul", "estimate", "lower", "upper"]
    )
    scores = pooled_scores(predictions, 0.5, ALPHA)
    print(
        f"UKF on {predictions['unit_id'].nunique()} held-out units: α–λ after half of life "
        f"{scores['alpha_lambda']:.3f}, 90 % coverage after half {scores['coverage_after']:.3f}, "
        f"RMSE after half {scores['rmse_after']:.0f} h"
    )


if __name__ == "__main__":
    main()
