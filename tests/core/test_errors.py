"""User errors: unknown and missing keys of a table name the typo and suggest the right key."""

import pickle

import pytest

from prsm_health.core.errors import (
    MissingKeyError,
    ParameterError,
    PRSMHealthError,
    RecipeError,
    UnknownKeyError,
    nearest_key,
    require_known_keys,
)

SCENARIO_KEYS = ["design", "instrumentation", "seed", "sensor_seed", "health", "profile"]


def test_a_typo_is_named_with_the_nearest_key():
    with pytest.raises(UnknownKeyError) as info:
        require_known_keys("scenario", {"sead": 3}, SCENARIO_KEYS)
    message = str(info.value)
    assert message.startswith("unknown key 'sead' in [scenario] (did you mean 'seed'?); allowed: ")
    assert "sensor_seed" in message and "\n" not in message
    assert info.value.field == "scenario.sead" and info.value.suggestion == "seed"
    assert isinstance(info.value, ParameterError)  # callers catching ParameterError still do


def test_a_design_field_typo():
    with pytest.raises(
        UnknownKeyError, match=r"'n_roller' in \[design\] \(did you mean 'n_rollers'"
    ):
        require_known_keys("design", {"n_roller": 7, "pitch": 2e-3}, ["pitch", "n_rollers"])


def test_a_misspelt_table_is_named_as_a_table_not_printed_as_a_dict():
    with pytest.raises(UnknownKeyError) as info:
        require_known_keys("scenario", {"helth": {"clearance": 2e-5}}, SCENARIO_KEYS)
    message = str(info.value)
    assert "unknown table [helth] in [scenario] (did you mean [health]?)" in message
    assert "{" not in message and "clearance" not in message


def test_a_table_header_repeating_its_own_table():
    # a health file holds the fields at its top level; a [helth] header there is a typo'd
    # copy of the scenario's [health] table
    with pytest.raises(UnknownKeyError, match=r"keys belong directly in \[health\]"):
        require_known_keys("health", {"helth": {"clearance": 2e-5}}, ["clearance", "faults"])


def test_no_suggestion_when_nothing_is_close():
    with pytest.raises(UnknownKeyError) as info:
        require_known_keys("profile", {"colour": "red"}, ["speed", "load"])
    assert "did you mean" not in str(info.value) and info.value.suggestion is None
    assert nearest_key("Seed", ["seed"]) == "seed"  # case alone is still the same key


def test_unknown_keys_come_before_missing_ones():
    # "sead" instead of "seed": the typo is reported, not a missing seed
    with pytest.raises(RecipeError, match="unknown key 'sead' in \\[recipe\\] \\(did you mean"):
        require_known_keys(
            "recipe", {"sead": 3}, ["name", "seed"], required=["name", "seed"], error=RecipeError
        )
    with pytest.raises(MissingKeyError, match=r"missing key 'seed' in \[recipe\]"):
        require_known_keys("recipe", {"name": "x"}, ["name", "seed"], required=["name", "seed"])
    require_known_keys("recipe", {"name": "x", "seed": 1}, ["name", "seed"], required=["seed"])


@pytest.mark.parametrize(
    "error",
    [
        ParameterError("profile.speed", -1.0, "must be > 0"),
        UnknownKeyError("scenario", "sead", 3, SCENARIO_KEYS),
        MissingKeyError("recipe", "seed", ["name", "seed"]),
    ],
)
def test_errors_survive_a_process_pool(error):
    # dataset workers raise these in another process: pickling must keep the message
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error) and str(copy) == str(error)
    assert isinstance(copy, PRSMHealthError)


def test_messages_built_from_names_take_their_article(tmp_path):
    # "is a angle", "not a instrumentation profile": the article follows the noun
    from prsm_health.core.errors import a_or_an
    from prsm_health.core.tomlfile import read_toml

    names = ("angle", "length", "Accelerometer", "instrumentation profile")
    assert [a_or_an(n) for n in names] == [
        "an angle",
        "a length",
        "an Accelerometer",
        "an instrumentation profile",
    ]
    with pytest.raises(PRSMHealthError, match="is a directory, not an instrumentation profile"):
        read_toml(tmp_path, "instrumentation profile")
