"""``HealthState.from_dict(values, table, base=…)``: a health table laid over another (or over a
state) key by key, the ``clearance`` shorthand expanded by the rules of a single table first."""

import pytest

from prsm_health.actuator.faults import Spall
from prsm_health.actuator.states import HealthState
from prsm_health.core.errors import ParameterError

FILE = {
    "clearance_screw": 30e-6,
    "clearance_nut": 35e-6,
    "clearance_gear": 45e-6,
    "wear_spread": 0.3,
    "faults": [{"kind": "spall", "location": "screw", "depth": 20e-6}],
}


def clearances(h: HealthState) -> tuple:
    return h.clearance_screw, h.clearance_nut, h.clearance_gear


@pytest.mark.parametrize(
    "values, expected",
    [
        ({"clearance": 12e-6}, (12e-6, 12e-6, 12e-6)),
        ({"clearance": 12e-6, "clearance_gear": 50e-6}, (12e-6, 12e-6, 50e-6)),
        ({"clearance_gear": 50e-6}, (30e-6, 35e-6, 50e-6)),
        ({}, (30e-6, 35e-6, 45e-6)),
    ],
    ids=["shorthand replaces all", "shorthand and gear", "gear alone", "nothing"],
)
def test_values_replace_the_base_keys_they_name(values, expected):
    h = HealthState.from_dict(values, base=FILE)
    assert clearances(h) == expected
    assert h.wear_spread == 0.3 and h.faults == (Spall(location="screw", depth=20e-6),)


def test_a_base_shorthand_is_expanded_before_the_overlay():
    # the base's clearance = 20 µm stands for the three clearances; the overlay's gear one
    # replaces only the gear's
    h = HealthState.from_dict({"clearance_gear": 50e-6}, base={"clearance": 20e-6})
    assert clearances(h) == (20e-6, 20e-6, 50e-6)
    h = HealthState.from_dict(
        {"clearance": 5e-6}, base={"clearance": 20e-6, "clearance_nut": 40e-6}
    )
    assert clearances(h) == (5e-6, 5e-6, 5e-6)


def test_a_state_as_base_and_a_value_equal_to_the_default_still_replaces():
    base = HealthState.from_dict(FILE)
    h = HealthState.from_dict({"wear_spread": 0.0, "faults": []}, base=base)
    assert h.wear_spread == 0.0 and h.faults == ()
    assert clearances(h) == clearances(base)
    # without a base, from_dict is what it was
    assert HealthState.from_dict({"clearance": 12e-6}) == HealthState.uniform(12e-6)
    assert HealthState.from_dict(base) is base


def test_errors_name_the_table_in_values_and_base():
    with pytest.raises(ParameterError, match="health"):
        HealthState.from_dict({"clearence": 1e-6}, base=FILE)
    with pytest.raises(ParameterError, match="health"):
        HealthState.from_dict({"clearance": 1e-6}, base={"clearance_foo": 1e-6})
    with pytest.raises(ParameterError, match="health.clearance_gear"):
        HealthState.from_dict({"clearance_gear": -1e-6}, base=FILE)
