"""An operating profile's loads in every written form (prsm_health.core.quantities): newtons kept,
shares of a rating kept until resolved against the design's ratings, no knots before that."""

import numpy as np
import pytest

from prsm_health.actuator.states import DEFAULT_LOAD, DEFAULT_LOAD_SHARE, OperatingProfile
from prsm_health.core.errors import ParameterError
from prsm_health.core.quantities import ForceSpec

RATINGS = {"C_a": 10_000.0, "C_0a": 20_000.0}


@pytest.mark.parametrize(
    ("written", "newtons"),
    [(4400, 4400.0), ("4.4 kN", 4400.0), ("-300N", -300.0), ("4400 N", 4400.0)],
)
def test_newtons_are_kept_as_a_float(written, newtons):
    profile = OperatingProfile(load=written, load_amplitude="0.5kN")
    assert profile.load == newtons and isinstance(profile.load, float)
    assert profile.load_amplitude == 500.0 and profile.is_resolved


@pytest.mark.parametrize(
    ("written", "newtons"),
    [("20 % C_a", 2000.0), ("0.2 C_a", 2000.0), ("5 % C_0a", 1000.0), ("-10 % C_a", -1000.0)],
)
def test_a_share_is_kept_until_resolved(written, newtons):
    profile = OperatingProfile(load=written, load_amplitude="3 % C_a", load_profile="reversing")
    assert isinstance(profile.load, ForceSpec) and not profile.is_resolved
    resolved = profile.resolved(RATINGS)
    assert resolved.is_resolved
    assert resolved.load == pytest.approx(newtons, rel=1e-12)
    assert resolved.load_amplitude == pytest.approx(300.0, rel=1e-12)
    assert resolved.peak_load == pytest.approx(abs(newtons) + 300.0, rel=1e-12)
    # everything else untouched
    assert resolved.load_profile == "reversing" and resolved.duration == profile.duration


def test_the_default_load_is_the_default_share_of_c_a():
    profile = OperatingProfile()
    assert profile.load == DEFAULT_LOAD == ForceSpec(DEFAULT_LOAD_SHARE, "C_a")
    assert 0.1 <= DEFAULT_LOAD_SHARE <= 0.4  # the service range of an EMA (issue 26)
    assert profile.resolved(RATINGS).load == pytest.approx(DEFAULT_LOAD_SHARE * 10_000.0)


def test_ratings_may_be_a_designs_load_ratings():
    from prsm_health.actuator.design import preset
    from prsm_health.physics.load_rating import load_ratings

    ratings = load_ratings(preset("paper01"))
    profile = OperatingProfile(load="10 % C_a", load_amplitude="1 % C_0a").resolved(ratings)
    assert profile.load == pytest.approx(0.1 * ratings.dynamic, rel=1e-12)
    assert profile.load_amplitude == pytest.approx(0.01 * ratings.static, rel=1e-12)


@pytest.mark.parametrize("what", ["load_knots", "has_reversals", "peak_load"])
def test_an_unresolved_share_gives_no_knots(what):
    profile = OperatingProfile(load="20 % C_a", load_profile="sinusoidal")
    with pytest.raises(ParameterError, match="resolved") as err:
        attr = getattr(profile, what)
        attr() if callable(attr) else None
    assert err.value.field == "profile.load"
    swing = OperatingProfile(load=0.0, load_amplitude="5 % C_a", load_profile="sinusoidal")
    with pytest.raises(ParameterError) as err:
        swing.load_knots()
    assert err.value.field == "profile.load_amplitude"


def test_a_resolved_profile_gives_the_same_knots_as_newtons():
    shares = OperatingProfile(load="10 % C_a", load_amplitude="20 % C_a", load_profile="reversing")
    newtons = OperatingProfile(load=1000.0, load_amplitude=2000.0, load_profile="reversing")
    (knots_a, *rest_a), (knots_b, *rest_b) = (
        shares.resolved(RATINGS).load_knots(),
        newtons.load_knots(),
    )
    # the shares' products round differently from the typed newtons: 1e-12 relative
    assert np.allclose(knots_a, knots_b, rtol=1e-12, atol=0.0) and rest_a == rest_b
    assert np.ptp(knots_a[1]) == pytest.approx(4000.0)  # it does swing by ±2 kN


@pytest.mark.parametrize(
    ("fields", "field", "needle"),
    [
        ({"load": "20 % C_x"}, "profile.load", "unknown unit or rating"),
        ({"load": "4 lbf"}, "profile.load", "unknown unit"),
        ({"load": "20 %"}, "profile.load", "needs its rating"),
        ({"load": "heavy"}, "profile.load", "20 % C_a"),
        ({"load_amplitude": "-5 % C_a"}, "profile.load_amplitude", "[0, 100]"),
        ({"load_amplitude": -5.0}, "profile.load_amplitude", "[0"),
        ({"load": "20000 % C_a"}, "profile.load", "[-100, 100]"),
        ({"load": 2e6}, "profile.load", "1e+06"),
        ({"load": True}, "profile.load", "a force"),
    ],
)
def test_bad_loads_name_the_field(fields, field, needle):
    with pytest.raises(ParameterError) as err:
        OperatingProfile(**fields)
    assert err.value.field == field and needle in str(err.value)


def test_a_share_needs_its_rating():
    with pytest.raises(ParameterError, match="C_0a"):
        OperatingProfile(load="5 % C_0a").resolved({"C_a": 1e4})


def test_as_dict_writes_a_share_as_its_text_and_reads_back():
    profile = OperatingProfile(load="12.5 % C_a", load_amplitude=300.0)
    data = profile.as_dict()
    assert data["load"] == "12.5 % C_a" and data["load_amplitude"] == 300.0
    assert OperatingProfile(**data) == profile
    resolved = profile.resolved(RATINGS)
    assert resolved.as_dict()["load"] == pytest.approx(1250.0)
