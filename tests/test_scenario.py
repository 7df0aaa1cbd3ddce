"""Scenario: the one object a run is built from — dict/TOML round trips, errors, labels."""

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, SensorModel, simulate
from prsm_health.errors import ParameterError
from prsm_health.scenario import Scenario


def test_dict_and_toml_round_trip(tmp_path):
    scenario = Scenario.from_dict(
        {
            "design": "paper01",
            "health": {"clearance": 20e-6, "clearance_gear": 5e-6, "friction_scale": 1.5},
            "profile": {"duration": 0.05, "load_profile": "reversing", "load_amplitude": 300.0},
            "sensors": {"accel_noise": 0.05},
            "options": {"contact_law": "hertz", "ideal": True},
            "seed": 4,
        }
    )
    assert scenario.health.clearance_screw == scenario.health.clearance_nut == 20e-6
    assert scenario.health.clearance_gear == 5e-6
    assert scenario.options.variation.is_ideal
    assert Scenario.from_dict(scenario.to_dict()) == scenario
    path = tmp_path / "s.toml"
    path.write_text(scenario.to_toml())
    assert Scenario.from_toml(path) == scenario


def test_labels_come_from_the_scenario():
    scenario = Scenario(health=HealthState.uniform(15e-6), profile=OperatingProfile(speed=60.0))
    labels = scenario.labels()
    assert labels["clearance_screw"] == 15e-6 and labels["screw_speed"] == 60.0
    assert labels["design"] == "paper01" and labels["seed"] == 0


def test_scenario_simulate_equals_simulate():
    profile = OperatingProfile(duration=0.02)
    sensors = SensorModel(sample_rate=10_000)
    scenario = Scenario(profile=profile, sensors=sensors, seed=2)
    a, b = scenario.simulate(), simulate("paper01", None, profile, sensors, 2)
    assert np.array_equal(a["nut_axial_accel"], b["nut_axial_accel"])
    assert a.labels == b.labels
    # nominal labels from the scenario, realised clearances from the simulated model
    assert {k: v for k, v in a.labels.items() if "_realised_" not in k} == scenario.labels()
    assert a.scenario["health"] == scenario.to_dict()["health"]


@pytest.mark.parametrize(
    "data, field",
    [
        ({"heath": {}}, "scenario"),
        ({"health": {"clearence": 1e-6}}, "health.clearence"),
        ({"profile": {"speed": -1.0}}, "profile.speed"),
        ({"options": {"variation": {"pitch": 1e-6}}}, "options.variation.pitch"),
        ({"design": "paper99"}, "design"),
        ({"seed": -1}, "seed"),
    ],
)
def test_errors_name_the_field(data, field):
    with pytest.raises(ParameterError) as err:
        Scenario.from_dict(data)
    assert err.value.field == field, str(err.value)
