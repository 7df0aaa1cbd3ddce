"""Scenario: the one object a run is built from — dict/TOML round trips, errors, labels."""

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, load_instrumentation, simulate
from prsm_health.core.errors import ParameterError
from prsm_health.simulation.scenario import Scenario


def test_dict_and_toml_round_trip(tmp_path):
    scenario = Scenario.from_dict(
        {
            "design": "paper01",
            "health": {"clearance": 20e-6, "clearance_gear": 5e-6, "friction_scale": 1.5},
            "profile": {"duration": 0.05, "load_profile": "reversing", "load_amplitude": 300.0},
            "instrumentation": {"profile": "lab-rig", "nut_axial_accel": {"range_g": 20.0}},
            "options": {"contact_law": "hertz", "ideal": True},
            "seed": 4,
        }
    )
    assert scenario.health.clearance_screw == scenario.health.clearance_nut == 20e-6
    assert scenario.health.clearance_gear == 5e-6
    assert scenario.options.variation.is_ideal
    assert scenario.instrumentation.nut_axial_accel.range == pytest.approx(20 * 9.80665)
    assert isinstance(scenario.to_dict()["instrumentation"], dict)  # modified: stored in full
    assert Scenario.from_dict(scenario.to_dict()) == scenario
    path = tmp_path / "s.toml"
    path.write_text(scenario.to_toml())
    assert Scenario.from_toml(path) == scenario


def test_instrumentation_by_name_or_file(tmp_path):
    default = Scenario()
    assert default.instrumentation == load_instrumentation("flight-ema")
    assert default.to_dict()["instrumentation"] == "flight-ema"
    assert 'instrumentation = "flight-ema"' in default.to_toml()
    # a profile file next to the scenario file, named relative to it
    (tmp_path / "rig.toml").write_text('profile = "lab-rig"\nsample_rate = 40000.0\n')
    (tmp_path / "s.toml").write_text('instrumentation = "rig.toml"\nseed = 2\n')
    scenario = Scenario.from_toml(tmp_path / "s.toml")
    assert scenario.instrumentation.sample_rate == 40_000.0
    assert scenario.instrumentation.fitted == load_instrumentation("lab-rig").fitted


def test_the_old_sensors_table_says_what_replaced_it():
    with pytest.raises(ParameterError) as err:
        Scenario.from_dict({"sensors": {"accel_noise": 0.05}})
    assert err.value.field == "scenario.sensors"
    assert "instrumentation" in str(err.value) and "flight-ema" in str(err.value)


def test_labels_come_from_the_scenario():
    scenario = Scenario(health=HealthState.uniform(15e-6), profile=OperatingProfile(speed=60.0))
    labels = scenario.labels()
    assert labels["clearance_screw"] == 15e-6 and labels["screw_speed"] == 60.0
    assert labels["design"] == "paper01" and labels["seed"] == 0


def test_scenario_simulate_equals_simulate():
    profile = OperatingProfile(duration=0.02)
    sensors = load_instrumentation({"profile": "flight-ema", "sample_rate": 10_000})
    scenario = Scenario(profile=profile, instrumentation=sensors, seed=2)
    a, b = scenario.simulate(), simulate("paper01", None, profile, sensors, 2)
    assert np.array_equal(a["nut_axial_accel"], b["nut_axial_accel"])
    assert a.labels == b.labels
    # nominal labels from the scenario, realised clearances from the simulated model
    assert {k: v for k, v in a.labels.items() if "_realised_" not in k} == scenario.labels()
    assert a.scenario["health"] == scenario.to_dict()["health"]


@pytest.mark.parametrize(
    "data, field",
    [
        ({"heath": {}}, "scenario.heath"),
        ({"health": {"clearence": 1e-6}}, "health.clearence"),
        ({"profile": {"speed": -1.0}}, "profile.speed"),
        ({"options": {"variation": {"pitch": 1e-6}}}, "options.variation.pitch"),
        ({"design": "paper99"}, "design"),
        ({"seed": -1}, "seed"),
        ({"instrumentation": "flight-emma"}, "instrumentation"),
        (
            {"instrumentation": {"profile": "ideal", "nut_axial_accel": {"nois": 1.0}}},
            "instrumentation.nut_axial_accel.nois",
        ),
    ],
)
def test_errors_name_the_field(data, field):
    with pytest.raises(ParameterError) as err:
        Scenario.from_dict(data)
    assert err.value.field == field, str(err.value)
