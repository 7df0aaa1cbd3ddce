"""A scenario resolves its profile's loads against its design's ratings: the default share of C_a
when no load is given, shares of each design's own ratings, the peak refused above C_0a, the
load share in the labels."""

import pytest

import prsm_health.simulation.scenario as scenario_module
from prsm_health.actuator.design import preset
from prsm_health.actuator.states import DEFAULT_LOAD_SHARE, OperatingProfile
from prsm_health.core.errors import ParameterError
from prsm_health.physics.load_rating import load_ratings
from prsm_health.simulation.scenario import Scenario, design_ratings, simulate

P01 = load_ratings(preset("paper01"))


def test_no_load_given_is_the_default_share_of_c_a_everywhere(monkeypatch):
    expected = pytest.approx(DEFAULT_LOAD_SHARE * P01.dynamic, rel=1e-12)
    assert Scenario().profile.load == expected
    assert Scenario.from_dict({}).profile.load == expected
    assert Scenario.from_dict({"profile": {"speed": 50.0}}).profile.load == expected
    assert Scenario(profile=OperatingProfile(duration=0.1)).profile.load == expected
    # simulate() with no profile: the scenario it would run (the kernel is not called)
    monkeypatch.setattr(scenario_module, "simulate_scenario", lambda s, progress: s)
    assert simulate().profile.load == expected


def test_a_light_load_given_is_kept():
    light = Scenario(profile=OperatingProfile(load=100.0))
    assert light.profile.load == 100.0
    assert light.labels()["load_share"] == pytest.approx(100.0 / P01.dynamic)
    assert Scenario.from_dict({"profile": {"load": "2 % C_a"}}).labels()[
        "load_share"
    ] == pytest.approx(0.02)


def test_shares_are_of_the_scenarios_own_design():
    for name in ("paper01", "paper03"):
        ratings = load_ratings(preset(name))
        s = Scenario.from_dict(
            {
                "design": name,
                "profile": {
                    "load": "10 % C_a",
                    "load_amplitude": "5 % C_0a",
                    "load_profile": "reversing",
                },
            }
        )
        assert s.profile.is_resolved
        assert s.profile.load == pytest.approx(0.1 * ratings.dynamic, rel=1e-12)
        assert s.profile.load_amplitude == pytest.approx(0.05 * ratings.static, rel=1e-12)
        labels = s.labels()
        assert labels["axial_load"] == s.profile.load  # newtons, as before
        peak = 0.1 * ratings.dynamic + 0.05 * ratings.static
        assert labels["load_share"] == pytest.approx(peak / ratings.dynamic, rel=1e-12)


def test_the_stored_scenario_holds_newtons_and_reads_back_equal(tmp_path):
    s = Scenario.from_dict({"profile": {"load": "15 % C_a", "load_amplitude": "1.2 kN"}})
    data = s.to_dict()
    assert isinstance(data["profile"]["load"], float)
    assert Scenario.from_dict(data) == s
    path = tmp_path / "s.toml"
    path.write_text(s.to_toml())
    assert Scenario.from_toml(path) == s


def test_a_swing_counts_only_where_the_load_swings():
    # A constant profile ignores its amplitude: neither the peak nor the share counts it.
    s = Scenario(profile=OperatingProfile(load="10 % C_a", load_amplitude="90 % C_a"))
    assert s.labels()["load_share"] == pytest.approx(0.1)


@pytest.mark.parametrize(
    ("profile", "value"),
    [
        ({"load": "190 % C_a"}, "190 % C_a"),
        ({"load": "-101 % C_0a"}, "-101 % C_0a"),
        ({"load": 15e3, "load_amplitude": "50 % C_a", "load_profile": "sinusoidal"}, "15000 N"),
    ],
)
def test_a_peak_above_c_0a_is_refused(profile, value):
    with pytest.raises(ParameterError) as err:
        Scenario.from_dict({"profile": profile})
    message = str(err.value)
    assert err.value.field == "profile.load" and value in message
    assert "C_0a" in message and f"{P01.static:.4g}" in message


def test_the_peak_at_c_0a_itself_is_allowed():
    # the direct drive gives no motor limits: the rating alone decides
    s = Scenario.from_dict({"profile": {"load": "99.9 % C_0a"}, "drive_train": "direct"})
    assert s.profile.load == pytest.approx(0.999 * P01.static)


def test_an_unknown_rating_names_the_field():
    with pytest.raises(ParameterError, match="unknown unit or rating 'C_1a'") as err:
        Scenario.from_dict({"profile": {"load_amplitude": "20 % C_1a"}})
    assert err.value.field == "profile.load_amplitude"


def test_ratings_are_computed_once_per_design():
    # Equal designs share one entry; a copy of the dict cannot change the cache.
    ratings = design_ratings(preset("paper01"))
    assert ratings == {"C_a": P01.dynamic, "C_0a": P01.static}
    ratings["C_a"] = 1.0
    assert design_ratings(preset("paper01"))["C_a"] == P01.dynamic


def test_the_resolved_duty_is_checked_against_the_motor():
    # prsm_health.actuator.drive_train.duty_check on the resolved peak load and top speed: a
    # motor below the duty's continuous torque warns, one too slow for it refuses.
    from dataclasses import replace

    from prsm_health.actuator.drive_train import DriveTrain

    weak = replace(DriveTrain(), continuous_torque=0.01)
    with pytest.warns(UserWarning, match="continuous torque"):
        Scenario(drive_train=weak, profile=OperatingProfile(load="20 % C_a"))
    slow = replace(DriveTrain(), max_speed=50.0)
    with pytest.raises(ParameterError, match="max_speed"):
        Scenario(drive_train=slow, profile=OperatingProfile(speed=100.0))
