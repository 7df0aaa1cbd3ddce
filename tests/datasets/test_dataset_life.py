"""Life recipes (dataset [life]): units × snapshots runs, whole units per split, the unit's seed
and health in every snapshot, refused sweeps; Scenario.sensor_seed."""

import copy

import numpy as np
import pytest

from prsm_health import OperatingProfile
from prsm_health.core.errors import ParameterError
from prsm_health.datasets import Recipe, RecipeError
from prsm_health.simulation.scenario import Scenario

LIFE_RECIPE = {
    "name": "life",
    "design": "paper01",
    "instrumentation": "flight-ema",
    "duration": 0.05,
    "sample_rate": 20000,
    "seed": 3,
    "test_fraction": 0.25,
    "sweep": {"mode": "random", "speed": [60.0, 120.0], "load_amplitude": [300.0, 2000.0]},
    "profile": {"load_profile": "reversing"},
    "life": {"units": 4, "snapshots": 3},
}
UNITS, SNAPSHOTS = 4, 3


def recipe_with(**changes) -> dict:
    data = copy.deepcopy(LIFE_RECIPE)
    data.update(changes)
    return data


@pytest.fixture(scope="module")
def recipe():
    return Recipe.from_dict(copy.deepcopy(LIFE_RECIPE))


def test_runs_are_units_times_snapshots_unit_major(recipe):
    runs = recipe.runs()
    assert len(runs) == UNITS * SNAPSHOTS
    assert [r.run_id for r in runs] == list(range(UNITS * SNAPSHOTS))
    assert [r.point["unit_id"] for r in runs] == [u for u in range(UNITS) for _ in range(SNAPSHOTS)]
    fleet = recipe.fleet()
    for r in runs:
        unit = fleet[r.point["unit_id"]]
        k = r.run_id % SNAPSHOTS
        assert r.point["age_hours"] == pytest.approx(unit.failure_age * k / SNAPSHOTS, rel=1e-12)
        assert 60.0 <= r.point["speed"] <= 120.0 and 300.0 <= r.point["load_amplitude"] <= 2000.0
    assert recipe.runs() == Recipe.from_dict(copy.deepcopy(LIFE_RECIPE)).runs()  # deterministic


def test_recordings_at_each_age_are_runs_of_their_own(recipe):
    # [life] recordings = 2: each age recorded twice, each recording its own conditions and
    # sensor noise; recordings = 1 keeps the run ids (and so the draws) of the plain recipe
    twice = Recipe.from_dict(
        recipe_with(life={"units": UNITS, "snapshots": SNAPSHOTS, "recordings": 2})
    )
    runs = twice.runs()
    assert len(runs) == UNITS * SNAPSHOTS * 2
    assert [r.run_id for r in runs] == list(range(UNITS * SNAPSHOTS * 2))
    plain = recipe.runs()
    for r in runs:
        at = plain[r.run_id // 2]  # the plain recipe's run at the same unit and age
        assert (r.point["unit_id"], r.point["age_hours"]) == (
            at.point["unit_id"],
            at.point["age_hours"],
        )
    pairs = [(runs[i], runs[i + 1]) for i in range(0, len(runs), 2)]
    assert all(a.point["speed"] != b.point["speed"] for a, b in pairs)
    assert all(a.scenario().sensors_seed != b.scenario().sensors_seed for a, b in pairs)
    one = Recipe.from_dict(
        recipe_with(life={"units": UNITS, "snapshots": SNAPSHOTS, "recordings": 1})
    )

    def draws(runs):
        return [(r.run_id, r.point, r.seed, r.split) for r in runs]

    assert draws(one.runs()) == draws(plain)
    with pytest.raises(RecipeError, match=r"life\.recordings = 0"):
        Recipe.from_dict(
            recipe_with(life={"units": UNITS, "snapshots": SNAPSHOTS, "recordings": 0})
        )


def test_snapshots_of_a_unit_share_its_split_and_build(recipe):
    runs = recipe.runs()
    scenarios = [r.scenario() for r in runs]
    splits = {}
    for u in range(UNITS):
        mine = [i for i, r in enumerate(runs) if r.point["unit_id"] == u]
        assert len({runs[i].split for i in mine}) == 1
        splits[u] = runs[mine[0]].split
        # the unit as built: one scenario seed; each snapshot its own sensor noise
        assert len({scenarios[i].seed for i in mine}) == 1
        assert scenarios[mine[0]].seed == recipe.fleet()[u].seed
        assert len({scenarios[i].sensors_seed for i in mine}) == SNAPSHOTS
        assert all(scenarios[i].sensor_seed is not None for i in mine)
    assert len({scenarios[u * SNAPSHOTS].seed for u in range(UNITS)}) == UNITS
    assert sum(s == "test" for s in splits.values()) == round(UNITS * 0.25)


def test_labels_and_health_are_the_units_at_its_age(recipe):
    fleet = recipe.fleet()
    for r in recipe.runs():
        unit, age = fleet[r.point["unit_id"]], r.point["age_hours"]
        labels = r.labels()
        assert labels["unit_id"] == unit.unit_id and labels["age_hours"] == age
        assert labels["rul_hours"] == pytest.approx(unit.failure_age - age, rel=1e-12)
        assert labels["failure_mode"] == unit.failure_mode
        assert labels["clearance_mean_true"] == float(unit.clearance(age))
        scenario = r.scenario()
        assert scenario.health == unit.health_at(age)
        assert scenario.profile.temperature == unit.temperature  # the sweep draws none
        assert scenario.profile.load_profile == "reversing"
        assert labels["screw_speed"] == r.point["speed"]


def test_the_clearance_label_is_what_the_installed_unit_shows(recipe):
    # the life's truth is the rollers' realised mean half-clearance the dynamics build (threads
    # plus the assembly's take-up of pitch errors; uneven wear keeps the mean): exact up to
    # float rounding, since both come from the unit's one variation stream
    from prsm_health.simulation.dynamics.model import build_model, realised_clearances

    fleet = recipe.fleet()
    plays = []
    for r in recipe.runs()[::SNAPSHOTS]:
        unit, age = fleet[r.point["unit_id"]], r.point["age_hours"]
        s = r.scenario()
        model = build_model(s.design, s.health, s.profile, s.options, s.seed, s.drive_train)
        real = realised_clearances(model)
        mean = 0.5 * (real["clearance_screw_realised_mean"] + real["clearance_nut_realised_mean"])
        assert mean == pytest.approx(float(unit.clearance(age)), abs=1e-15)
        assert r.labels()["clearance_thread_true"] == float(unit.thread_clearance(age))
        plays.append(unit.assembly_play)
    # 2 µm pitch error σ per side: E|Δp|/2 over 7 rollers ≈ 1 µm, and it differs by unit
    assert 0.3e-6 < np.mean(plays) < 2e-6 and np.ptp(plays) > 0


def test_the_fleet_is_computed_once_per_process(recipe):
    assert recipe.fleet() is recipe.fleet()
    assert Recipe.from_dict(copy.deepcopy(LIFE_RECIPE)).fleet() is recipe.fleet()
    other = Recipe.from_dict(recipe_with(seed=4))
    assert other.fleet() is not recipe.fleet()
    assert other.fleet()[0].failure_age != recipe.fleet()[0].failure_age


@pytest.mark.parametrize(
    "key, value",
    [
        ("clearance", [5e-6, 20e-6]),
        ("clearance_nut", [5e-6, 20e-6]),
        ("lubricant_degradation", [0.0, 1.0]),
        ("wear_spread", [0.0, 0.2]),
        ("fault_case", ["none"]),
        ("severity", [0.5, 1.0]),
    ],
)
def test_life_recipes_refuse_sweeping_what_the_life_sets(key, value):
    sweep = dict(LIFE_RECIPE["sweep"], **{key: value})
    with pytest.raises(RecipeError, match=key) as err:
        Recipe.from_dict(recipe_with(sweep=sweep))
    assert "life" in str(err.value)


@pytest.mark.parametrize(
    "sweep, key",
    [
        ({"mode": "lhs", "speed": [60.0, 120.0]}, "sweep.mode"),
        ({"mode": "grid", "speed": [60.0, 120.0]}, "sweep.mode"),
        ({"mode": "random", "samples": 5, "speed": [60.0, 120.0]}, "sweep.samples"),
    ],
)
def test_life_recipes_draw_their_recording_conditions(sweep, key):
    with pytest.raises(RecipeError, match=key):
        Recipe.from_dict(recipe_with(sweep=sweep))


@pytest.mark.parametrize(
    "life, field",
    [
        ({"units": 0}, "life.units"),
        ({"units": 2, "colour": "red"}, "unknown key 'colour' in [life]"),
        ({"units": 2, "duty": {"shares": [0.5, 0.5, 0.5]}}, "life.duty.shares"),
        ({"units": 2, "max_age": 10.0}, "life.max_age"),
    ],
)
def test_a_bad_life_table_is_a_recipe_error(life, field):
    with pytest.raises(RecipeError) as err:
        Recipe.from_dict(recipe_with(life=life))
    assert str(err.value).startswith("recipe [life]: ")
    assert field in str(err.value)


# ------------------------------------------------------------------ Scenario.sensor_seed
def test_sensor_seed_round_trips_and_old_files_are_unchanged(tmp_path):
    scenario = Scenario(seed=5, sensor_seed=17)
    assert scenario.sensors_seed == 17 and scenario.labels()["sensor_seed"] == 17
    data = scenario.to_dict()
    assert data["sensor_seed"] == 17
    assert Scenario.from_dict(data) == scenario
    path = tmp_path / "s.toml"
    path.write_text(scenario.to_toml())
    assert Scenario.from_toml(path) == scenario
    plain = Scenario(seed=5)
    assert "sensor_seed" not in plain.to_dict() and "sensor_seed" not in plain.to_toml()
    assert plain.sensors_seed == 5 and plain.labels()["sensor_seed"] == 5
    path.write_text(plain.to_toml())
    assert Scenario.from_toml(path).sensor_seed is None


@pytest.mark.parametrize("bad", [-1, 1.5, True, "2"])
def test_a_bad_sensor_seed_names_the_field(bad):
    with pytest.raises(ParameterError) as err:
        Scenario(sensor_seed=bad)
    assert err.value.field == "sensor_seed"
    with pytest.raises(ParameterError):
        Scenario.from_dict({"seed": 1, "sensor_seed": bad})


def test_sensor_seed_changes_the_sensors_not_the_unit():
    # Same process, same inputs: the dynamics are deterministic, so the truth is bit-identical;
    # only the sensors' noise and errors are drawn from the other seed.
    profile = OperatingProfile(duration=0.01)
    base = Scenario(profile=profile, seed=1).simulate()
    resensed = Scenario(profile=profile, seed=1, sensor_seed=2).simulate()
    assert base.truth.keys() == resensed.truth.keys() and base.truth
    for name in base.truth:
        assert np.array_equal(base.truth[name], resensed.truth[name]), name
    for name in base.channels:
        assert not np.array_equal(base.channels[name], resensed.channels[name]), name
    # whereas the seed is the unit as built: another seed, other dynamics
    rebuilt = Scenario(profile=profile, seed=2, sensor_seed=1).simulate()
    assert not all(np.array_equal(base.truth[k], rebuilt.truth[k]) for k in base.truth)
