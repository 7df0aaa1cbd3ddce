"""The shipped default model (models/default.skops) on freshly simulated runs it never saw."""

import json
from pathlib import Path

import numpy as np
import pytest

from prsm_health.dataset import load_recipe
from prsm_health.diagnosis import DEFAULT_MODEL, diagnose, load_bundle
from prsm_health.dynamics.simulate import simulate
from prsm_health.states import HealthState, OperatingProfile

# Simulates fourteen recordings for the shipped model.
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]

#: The shipped model is trained on the reference recipe as a flight EMA measures it (the default
#: instrumentation, flight-ema); these recordings are measured the same way.
SENSORS = None


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


def test_size_and_card():
    assert DEFAULT_MODEL.stat().st_size < 5e6
    assert (ROOT / "models" / "MODEL_CARD.md").exists()
    metrics = json.loads((ROOT / "models" / "default.metrics.json").read_text())
    # The training script's held-out numbers (measured, not asserted elsewhere): recorded.
    assert {"clearance_test", "fault_test", "off_grid", "clearance_importance"} <= set(metrics)


def test_held_out_runs_of_the_reference_recipe(bundle):
    # Eight runs of the recipe's test split, regenerated from their recipe seeds (the model saw
    # none of them). The model card reports the full split; here: MAE ≤ 2 µm (issue), at least
    # 6 of 8 inside their 90 % interval (P(≤ 5 of 8 | p = 0.9) = 3.8 %), ≥ 7 of 8 classes right.
    recipe = load_recipe(ROOT / "datasets" / "clearance-study.toml")
    specs = [s for s in recipe.runs() if s.split == "test"][::10][:8]
    errors, inside, correct = [], 0, 0
    for spec in specs:
        scenario = spec.scenario()
        result = diagnose(scenario.simulate(), bundle).to_json()
        truth = 0.5 * (scenario.health.clearance_screw + scenario.health.clearance_nut)
        c = result["clearance"]
        errors.append(abs(c["estimate"] - truth))
        inside += c["lower"] <= truth <= c["upper"]
        correct += result["fault_class"] == spec.labels()["fault_class"]
    assert np.mean(errors) <= 2e-6
    assert inside >= 6 and correct >= 7


def test_off_grid_speeds_and_loads_with_noise(bundle):
    # Speeds and loads inside the training ranges but off its grid (50/80/110 rad/s, 0/100/200 N),
    # measured by the training's instrumentation: MAE ≤ 4 µm (issue).
    cases = [
        (65.0, 50.0, 7e-6),
        (95.0, 150.0, 19e-6),
        (100.0, 30.0, 33e-6),
        (57.0, 170.0, 26e-6),
        (88.0, 120.0, 3e-6),
    ]
    errors = []
    for k, (speed, load, clearance) in enumerate(cases):
        profile = OperatingProfile(
            duration=0.4,
            speed=speed,
            load=load,
            load_profile="reversing",
            load_amplitude=300.0,
            load_frequency=10.0,
            accel_time=0.002,
        )
        from prsm_health.dynamics.model import SimulationOptions

        run = simulate(
            "paper01",
            HealthState.uniform(clearance),
            profile,
            SENSORS,
            1000 + k,
            options=SimulationOptions(contact_law="hertz"),
        )
        errors.append(abs(diagnose(run, bundle).clearance["estimate"] - clearance))
    assert np.mean(errors) <= 4e-6, errors


def test_interval_widens_where_the_regime_hides_clearance(bundle):
    # Same actuator, steady 100 N (no reversal: clearance not observable) vs a reversing load.
    from prsm_health.dynamics.model import SimulationOptions

    def width(profile):
        run = simulate(
            "paper01",
            HealthState.uniform(20e-6),
            profile,
            SENSORS,
            3,
            options=SimulationOptions(contact_law="hertz"),
        )
        c = diagnose(run, bundle).clearance
        return c["upper"] - c["lower"]

    hidden = width(OperatingProfile(duration=0.4, load=100.0))
    revealed = width(
        OperatingProfile(
            duration=0.4,
            load=0.0,
            load_profile="reversing",
            load_amplitude=300.0,
            load_frequency=10.0,
            accel_time=0.002,
        )
    )
    assert hidden >= 35e-6  # the whole trained range 0–40 µm
    assert revealed <= 5e-6
