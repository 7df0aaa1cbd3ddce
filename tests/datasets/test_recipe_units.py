"""Recipes of a few units recorded many times ([units]): each run records unit run_id mod count
as built (its manufacturing seed and [units.build] values, the same in every recipe with the
same units seed), its sensors their own noise; whole units are held out; the errors."""

from pathlib import Path

import pytest

from prsm_health.datasets import Recipe, RecipeError, load_recipe

ROOT = Path(__file__).resolve().parents[2]
BASE = dict(name="units", design="paper01", duration=0.01, sample_rate=20000, seed=1)
UNITS = {
    "count": 4,
    "seed": 9,
    "build": {
        "preload": [0.0, 5e-6],
        "drive_train.payload_mass": [5.0, 20.0],
        # the accelerometer installed on the unit: its noise level, not its noise
        "instrumentation.nut_axial_accel.noise_density_ug": [20.0, 60.0],
    },
}


def recipe(seed=1, samples=12, **changes):
    sweep = {"mode": "lhs", "samples": samples, "clearance": [0.0, 40e-6]}
    return Recipe.from_dict(
        dict(
            BASE,
            seed=seed,
            units=UNITS,
            test_fraction=0.25,
            sweep=sweep,
            instrumentation="flight-ema",
            **changes,
        )
    )


def test_a_units_recipe_records_each_unit_as_built_with_its_own_sensor_noise():
    runs = recipe().runs()
    scenarios = [spec.scenario() for spec in runs]
    for spec, scenario in zip(runs, scenarios):
        twin = scenarios[spec.run_id % 4]  # the unit's first run
        assert spec.labels()["unit_id"] == spec.run_id % 4
        assert scenario.seed == twin.seed  # the same build
        assert scenario.health.preload == twin.health.preload
        assert scenario.drive_train.payload_mass == twin.drive_train.payload_mass
        accel = scenario.instrumentation.nut_axial_accel
        assert accel.noise_density == twin.instrumentation.nut_axial_accel.noise_density
        assert scenario.sensor_seed == spec.seed  # its own sensors' noise
    assert len({s.seed for s in scenarios}) == 4
    assert len({s.instrumentation.nut_axial_accel.noise_density for s in scenarios}) == 4
    assert len({s.health.clearance_screw for s in scenarios}) == 12  # swept per run


def test_recipes_with_one_units_seed_record_the_same_units_and_hold_out_the_same():
    a, b = recipe(seed=1).runs(), recipe(seed=2, samples=8).runs()
    for unit in range(4):
        sa, sb = a[unit].scenario(), b[unit].scenario()
        assert (sa.seed, sa.health.preload) == (sb.seed, sb.health.preload)
    held = {spec.run_id % 4 for spec in a if spec.split == "test"}
    assert held == {spec.run_id % 4 for spec in b if spec.split == "test"}
    assert len(held) == 1  # a quarter of 4 units, whole
    assert all((spec.split == "test") == (spec.run_id % 4 in held) for spec in a)


@pytest.mark.parametrize(
    "units, needle",
    [
        ({"count": 0, "seed": 1}, "units.count"),
        ({"count": 2, "seed": -1}, "units.seed"),
        ({"count": 2, "seed": 1, "colour": 3}, "unknown key"),
        ({"count": 2, "seed": 1, "build": {"speed": [1.0, 2.0]}}, "units.build.speed"),
        ({"count": 2, "seed": 1, "build": {"preload": [2e-6, 1e-6]}}, "units.build.preload"),
    ],
)
def test_bad_units_are_recipe_errors_naming_the_key(units, needle):
    with pytest.raises(RecipeError, match=needle):
        Recipe.from_dict(dict(BASE, units=units, sweep={"clearance": [1e-6]}))


@pytest.mark.parametrize(
    "name, other",
    [
        ("flight-ema-check", "flight-ema-check-baseline"),
        ("own-design-check", "own-design-check-baseline"),  # the docs' own-design example
    ],
)
def test_the_shipped_check_recipes_share_their_units(name, other):
    check = load_recipe(ROOT / "datasets" / f"{name}.toml")
    twin = load_recipe(ROOT / "datasets" / f"{other}.toml")
    assert check.design == twin.design
    assert check.units["seed"] == twin.units["seed"] and check.units["count"] == twin.units["count"]
    for unit in (0, 17):
        built, twin_built = check.unit_build(unit), twin.unit_build(unit)
        # the baseline also fixes the clearance as built; every key both draw is the same
        assert built and all(twin_built[k] == v for k, v in built.items())
    assert twin.profile["check"] == "health-check"
