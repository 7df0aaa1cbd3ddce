"""Forces as written by a user: newtons, units, shares of a load rating."""

import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.core.quantities import ForceSpec, force_newtons, parse_force

RATINGS = {"C_a": 10_000.0, "C_0a": 20_000.0}


@pytest.mark.parametrize(
    ("text", "newtons"),
    [
        (4400, 4400.0),
        (-250.5, -250.5),
        ("4.4 kN", 4400.0),
        ("4400 N", 4400.0),
        ("-300N", -300.0),
        ("1e3 N", 1000.0),
        ("20 % C_a", 2000.0),
        ("20%C_a", 2000.0),
        ("0.2 C_a", 2000.0),
        ("0.2*C_a", 2000.0),
        ("5 % C_0a", 1000.0),
    ],
)
def test_forms_resolve_to_newtons(text, newtons):
    assert force_newtons(text, RATINGS) == pytest.approx(newtons)


@pytest.mark.parametrize("text", ["20 %", "4 lbf", "abc", "20 % C_x", True, float("nan"), [1]])
def test_bad_forms_name_the_field_and_the_accepted_forms(text):
    with pytest.raises(ParameterError, match=r"profile\.load = .*C_a"):
        parse_force(text, "profile.load")


def test_a_share_needs_ratings():
    with pytest.raises(ParameterError, match="needs a design"):
        parse_force("20 % C_a").newtons(None)


def test_text_round_trips():
    for spec in (ForceSpec(0.2, "C_a"), ForceSpec(-1500.0)):
        assert parse_force(spec.text()) == spec
