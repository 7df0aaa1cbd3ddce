"""The PRSM's ageing as a progpy model (prsm_health.prognostics.ageing_model) against the life
simulation it is written on, and its particle-filter RUL (ageing_rul) on the life model's own
trajectories."""

import json
import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design import preset
from prsm_health.physics.life import fleet_lives, unit_life
from prsm_health.physics.life_spec import FleetScatter, LifeSpec

pytest.importorskip("progpy")

from prsm_health.prognostics.ageing_model import LOAD_FACTORS, PRSMAgeing, rate_tables  # noqa: E402
from prsm_health.prognostics.ageing_rul import AgeingRUL  # noqa: E402
from prsm_health.prognostics.fleet import simulated_histories  # noqa: E402

DESIGN = preset("paper01")
#: A fleet without unit-to-unit scatter or usage wandering: every unit is the duty's own.
EXACT = LifeSpec(
    units=1,
    scatter=FleetScatter(
        initial_clearance=(5e-6, 5e-6),
        wear_coefficient=0.0,
        load_scale=(1.0, 1.0),
        temperature=(0.0, 0.0),
        lubricant_life=0.0,
        wear_spread=(0.0, 0.0),
        usage=0.0,
    ),
)


@pytest.fixture(scope="module")
def tables():
    return rate_tables(DESIGN, EXACT)


def _run_to_failure(tables, load=1.0, load_after=None, change_age=math.inf):
    model = PRSMAgeing(**tables)
    x = model.initialize()
    # the installed clearance: the unit's threads plus its assembly's play
    x["b_screw"] = x["b_nut"] = 5e-6 + unit_life(DESIGN, EXACT, 0, 1).assembly_play
    result = model.simulate_to_threshold(
        lambda t, x=None: model.InputContainer(
            {"load": load if t < change_age or load_after is None else load_after}
        ),
        x=x,
        dt=model.prediction_step,
        save_freq=1e9,
    )
    return result.times[-1], result.states[-1]


def test_failure_age_is_the_life_simulations(tables):
    # Same duty, no scatter: the progpy model's wear-out age equals the life simulation's. The
    # life simulation integrates on a grid of 2 000 ages, the model in steps of ≤ 1/3 of the
    # time left (its crossing is timed to the last, ≤ 1 h step): 1 % covers both.
    life = unit_life(DESIGN, EXACT, 0, 1)
    age, _ = _run_to_failure(tables)
    assert life.failure_mode == "wear"
    assert age == pytest.approx(life.failure_age, rel=0.01)


def test_the_clearances_follow_the_life_simulations_screw_and_nut_rates(tables):
    life = unit_life(DESIGN, EXACT, 0, 1)
    model = PRSMAgeing(**tables)
    x = model.initialize()
    x["b_screw"] = x["b_nut"] = 5e-6
    age = 0.0
    for _ in range(40):
        dt = 0.5 * life.failure_age / 40
        x = model.next_state(x, model.InputContainer({"load": 1.0}), dt)
        age += dt
    screw, nut = life.clearances(age)
    # midpoint rule on d against the life model's trapezoid on its degradation grid
    assert float(x["b_screw"]) == pytest.approx(float(screw), rel=0.005)
    assert float(x["b_nut"]) == pytest.approx(float(nut), rel=0.005)


def test_a_doubled_load_shortens_the_rest_of_life(tables):
    # Archard wear ∝ Q·v_s/a with the Hertz semi-axis a ∝ Q^⅓: doubling the load from
    # mid-life speeds the wear by ≈ 2^⅔ ≈ 1.6 (less the spin sliding, which grows with the
    # contact: 1.3–1.7×), so the rest of life shrinks by that factor (LOAD_FACTORS spans
    # 0.25–4 × the duty).
    assert LOAD_FACTORS[0] <= 0.5 and LOAD_FACTORS[-1] >= 2.0
    base, _ = _run_to_failure(tables)
    change = 0.5 * base
    doubled, _ = _run_to_failure(tables, load_after=2.0, change_age=change)
    assert (base - change) / 1.7 < doubled - change < (base - change) / 1.3


def test_the_model_is_vectorized_over_particles(tables):
    model = PRSMAgeing(**tables)
    n = 7
    x = model.StateContainer(
        {
            "b_screw": np.full(n, 5e-6),
            "b_nut": np.full(n, 5e-6),
            "degradation": np.linspace(0, 1, n),
            "usage": np.zeros(n),
            "log_wear": np.linspace(-1, 1, n),
            "log_lubricant_life": np.zeros(n),
        }
    )
    after = model.next_state(x, model.InputContainer({"load": 1.0}), 10.0)
    grown = np.asarray(after["b_screw"]).ravel() - 5e-6
    # faster with more wear (log_wear) and a more depleted lubricant: strictly increasing
    assert grown.shape == (n,) and np.all(np.diff(grown) > 0)


@pytest.fixture(scope="module")
def synthetic_fleet():
    """The shipped fleet's scatter, observed without the dynamics: each unit's true mean
    clearance at 12 ages plus a Gaussian diagnosis error of 1 µm (interval ±1.645 µm)."""
    spec = replace(LifeSpec(), units=10)
    lives = fleet_lives(DESIGN, spec, 3)
    histories = simulated_histories(lives, 12, 1e-6, np.random.default_rng(4))
    return spec, lives, histories


def test_the_filter_learns_the_prior_and_predicts_held_out_units(synthetic_fleet):
    spec, lives, histories = synthetic_fleet
    train = histories[histories["unit_id"] < 7]
    est = AgeingRUL.fit(
        rate_tables(DESIGN, spec), spec, train, seed=1, n_particles=120, n_samples=40
    )
    # the calibration of an unbiased diagnosis of σ = 1 µm: gain ≈ 1, bias ≈ 0, scale ≈ 1
    # (84 snapshots: the slope's and the scale's sampling errors are a few %)
    assert est.gain == pytest.approx(1.0, abs=0.05)
    assert abs(est.bias) < 0.5e-6
    assert est.noise_scale == pytest.approx(1.0, abs=0.25)
    inside, errors = [], []
    for u in lives[7:]:
        unit = histories[histories["unit_id"] == u.unit_id]
        sd = (unit["clearance_upper"] - unit["clearance_lower"]).to_numpy() / (2 * 1.645)
        t = unit["age_hours"].to_numpy()
        preds = est.predict_prefix_arrays(t, unit["clearance"].to_numpy(), sd, min_rows=9)
        for k, p in zip(range(9, len(t) + 1), preds):
            true_rul = u.failure_age - t[k - 1]
            inside.append(p["lower"] <= true_rul <= p["upper"])
            errors.append(abs(p["estimate"] - true_rul) / u.failure_age)
    # 3 units × 4 late predictions: the 90 % intervals hold most true RULs, and the medians
    # are within a fifth of the unit's life (usage wanders ±15 %: a tighter bound would test
    # the draw, not the filter)
    assert np.mean(inside) >= 0.6
    assert np.median(errors) < 0.2


def test_a_rul_model_keeps_its_physics_through_its_file(tables, synthetic_fleet):
    from prsm_health.core.errors import PRSMHealthError
    from prsm_health.prognostics import HISTORY_COLUMNS, RULModel

    _, lives, histories = synthetic_fleet
    train = histories[histories["unit_id"] < 7]
    failure = {u.unit_id: u.failure_age for u in lives}
    model = RULModel(threshold=30e-6).fit(
        train[["unit_id", *HISTORY_COLUMNS]], {u: failure[u] for u in range(7)}
    )
    unit = histories[histories["unit_id"] == 8][list(HISTORY_COLUMNS)].iloc[:6]
    with pytest.raises(PRSMHealthError, match="no physics part"):
        model.predict(unit, method="physics")
    model.ageing_ = AgeingRUL(tables, n_particles=60, n_samples=20, horizon=model.horizon_)
    first = model.predict(unit, method="physics")
    back = RULModel.from_dict(json.loads(json.dumps(model.to_dict())))
    again = back.predict(unit, method="physics")
    # the same seed and particles: the same answer, to the bit
    assert first.rul_hours == again.rul_hours
    assert first.model["name"] == "physics" and 0 <= first.rul_hours["lower"]
    assert first.rul_hours["lower"] <= first.rul_hours["estimate"] <= first.rul_hours["upper"]


def test_the_duty_log_is_labelled_and_read_as_the_models_inputs():
    from prsm_health.prognostics.history import HistoryError, duty_arrays

    exact = unit_life(DESIGN, EXACT, 0, 1)
    labels = exact.labels(500.0)
    # no usage wandering: a duty hour per operating hour, at the duty's own load
    assert labels["duty_hours"] == pytest.approx(500.0) and labels["duty_load"] == 1.0
    wandering = unit_life(DESIGN, LifeSpec(), 2, 1)
    ages = wandering.snapshot_ages(10)
    hours = np.array([wandering.labels(a)["duty_hours"] for a in ages])
    # the intensity is exp(σX − σ²/2), of mean 1: over a life of ~10 correlation times the
    # mean rate is 1 within a few σ/√10
    assert np.all(np.diff(hours) > 0)
    assert hours[-1] / ages[-1] == pytest.approx(1.0, abs=0.25)
    history = pd.DataFrame(
        {"age_hours": [100.0, 300.0], "duty_hours": [120.0, 220.0], "duty_load": [1.2, 1.2]}
    )
    duty = duty_arrays(history)
    assert np.allclose(duty["usage_rate"], [1.2, 0.5]) and np.allclose(duty["load"], 1.2)
    assert duty_arrays(history[["age_hours"]]) == {"load": None, "usage_rate": None}
    with pytest.raises(HistoryError, match="row 1: duty_hours"):
        duty_arrays(history.assign(duty_hours=[120.0, 110.0]))
