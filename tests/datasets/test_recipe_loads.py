"""Recipes with loads in every written form: swept lists, ranges and per-run draws of shares of
the design's rating, [profile] loads as shares, the errors; the shipped recipes at service loads
with their light-load cases, and the fleet's recordings at its life duty's loads."""

from pathlib import Path

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.datasets import Recipe, RecipeError, load_recipe
from prsm_health.physics.load_rating import load_ratings

ROOT = Path(__file__).resolve().parents[2]
BASE = dict(name="loads", design="paper01", duration=0.01, sample_rate=20000, seed=1)
C_A = load_ratings(preset("paper01")).dynamic


def test_a_grid_of_shares_and_units_resolves_per_run():
    recipe = Recipe.from_dict(
        dict(BASE, sweep={"load": ["5 % C_a", "2.2 kN", 300], "speed": [80.0]})
    )
    loads = [spec.scenario().profile.load for spec in recipe.runs()]
    assert loads == pytest.approx([0.05 * C_A, 2200.0, 300.0], rel=1e-12)
    shares = [spec.labels()["load_share"] for spec in recipe.runs()]
    assert shares == pytest.approx([0.05, 2200.0 / C_A, 300.0 / C_A], rel=1e-12)


@pytest.mark.parametrize("mode", ["random", "lhs"])
def test_a_range_of_shares_is_a_range_of_newtons(mode):
    recipe = Recipe.from_dict(
        dict(
            BASE,
            sweep={
                "mode": mode,
                "samples": 40,
                "load": ["5 % C_a", "40 % C_a"],
                "load_amplitude": ["1 kN", "10 % C_0a"],
            },
            profile={"load_profile": "reversing"},
        )
    )
    loads = np.array([s.point["load"] for s in recipe.runs()])
    assert np.all((loads >= 0.05 * C_A) & (loads <= 0.40 * C_A))
    assert np.ptp(loads) > 0.25 * C_A  # 40 draws spread over the range, not one end
    # the same draws as the range written in newtons
    ratings = recipe.ratings
    newtons = Recipe.from_dict(
        dict(
            recipe.source,
            sweep={
                "mode": mode,
                "samples": 40,
                "load": [0.05 * C_A, 0.40 * C_A],
                "load_amplitude": [1000.0, 0.1 * ratings["C_0a"]],
            },
        )
    )
    assert loads == pytest.approx([s.point["load"] for s in newtons.runs()], rel=1e-12)


def test_a_grid_key_drawn_per_run_takes_shares():
    sweep = {"load": [0.0], "load_amplitude": {"uniform": ["3 % C_a", "30 % C_a"]}, "repeats": 8}
    recipe = Recipe.from_dict(dict(BASE, sweep=sweep, profile={"load_profile": "reversing"}))
    swings = np.array([s.scenario().profile.load_amplitude for s in recipe.runs()])
    assert len(swings) == 8 and np.all((swings >= 0.03 * C_A) & (swings <= 0.30 * C_A))


def test_profile_loads_as_shares_and_the_sweep_wins():
    recipe = Recipe.from_dict(
        dict(
            BASE,
            sweep={"speed": [80.0], "load": ["1 % C_a"]},
            profile={"load": "30 % C_a", "load_amplitude": "10 % C_a", "load_profile": "reversing"},
        )
    )
    profile = recipe.runs()[0].scenario().profile
    assert profile.load == pytest.approx(0.01 * C_A)  # the swept value, not [profile]'s
    assert profile.load_amplitude == pytest.approx(0.10 * C_A)


def test_no_load_anywhere_is_the_default_share():
    from prsm_health.actuator.states import DEFAULT_LOAD_SHARE

    recipe = Recipe.from_dict(dict(BASE, sweep={"speed": [80.0]}))
    assert recipe.runs()[0].scenario().profile.load == pytest.approx(DEFAULT_LOAD_SHARE * C_A)


@pytest.mark.parametrize(
    ("changes", "needle"),
    [
        ({"sweep": {"load": ["20 % C_x"]}}, "sweep.load"),
        ({"sweep": {"load": ["4 lbf"]}}, "unknown unit"),
        ({"sweep": {"speed": ["20 % C_a"]}}, "sweep.speed"),  # not a force
        ({"sweep": {"mode": "lhs", "samples": 2, "load": ["40 % C_a", "1 kN"]}}, "min ≤ max"),
        ({"sweep": {"load": ["250 % C_a"]}}, "sweep.load = .250 % C_a. is invalid: is 2.6"),
        # each value below C_0a, their peak above it: the run's scenario names the peak
        (
            {
                "sweep": {"load": ["90 % C_0a"], "load_amplitude": ["20 % C_0a"]},
                "profile": {"load_profile": "reversing"},
            },
            "run 0.*peak axial load.*C_0a",
        ),
        ({"profile": {"load": "5 % C_1a"}, "sweep": {"speed": [80.0]}}, "profile.load"),
    ],
)
def test_bad_loads_are_recipe_errors_naming_the_key(changes, needle):
    with pytest.raises(RecipeError, match=needle.replace("(", r"\(")):
        Recipe.from_dict(dict(BASE, **changes))


# ---------------------------------------------------------------------- the shipped recipes
SHIPPED = ("demo", "clearance-study", "flight-ema-reference", "fleet")


@pytest.fixture(scope="module")
def shipped():
    return {name: load_recipe(ROOT / "datasets" / f"{name}.toml") for name in SHIPPED}


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_recipes_run_at_service_loads_with_named_light_cases(shipped, name):
    # Service: the median run's peak load is 10–40 % of C_a (issue 26); every run below C_0a
    # (the scenario refuses it) and at most 40 % of C_a. The light-load cases (peak < 5 % of
    # C_a) are kept, and are a minority: in the demo its "light" half, elsewhere the low end of
    # a drawn swing.
    shares = np.array([spec.labels()["load_share"] for spec in shipped[name].runs()])
    assert 0.10 <= np.median(shares) <= 0.40
    assert shares.max() <= 0.40
    light = np.mean(shares < 0.05)
    assert 0.0 < light <= (0.5 if name == "demo" else 0.1)


def test_the_fleet_records_the_reference_recipes_loads(shipped):
    # The default model is trained on the reference recipe: the fleet's snapshots are recorded
    # in the same load ranges, so its diagnoses stay in distribution.
    fleet, reference = shipped["fleet"], shipped["flight-ema-reference"]
    for key in ("load", "load_amplitude"):
        assert fleet.sweep[key] == reference.sweep[key]
