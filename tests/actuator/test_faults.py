"""Health states with several faults (issue 12, item 7): the [[faults]] interface, labels,
the primary class, recipes that sweep fault kinds and severities, and one-line CLI errors."""

import json

import pytest

from prsm_health import HealthState, Scenario
from prsm_health.actuator.faults import (
    FaultThresholds,
    PreloadLoss,
    Spall,
    ToothCrack,
    fault_from_dict,
    scaled,
)
from prsm_health.apps.cli import main
from prsm_health.core.errors import ParameterError, RecipeError
from prsm_health.datasets import Recipe

HEALTH_FILE = """
clearance = 12e-6
preload = 8e-6

[[faults]]
kind = "spall"
location = "nut"
depth = 30e-6

[[faults]]
kind = "preload_loss"
fraction = 0.25
"""


def test_health_file_reads_faults_of_several_kinds(tmp_path):
    path = tmp_path / "health.toml"
    path.write_text(HEALTH_FILE)
    health = HealthState.from_toml(path)
    assert health.clearance_gear == 12e-6
    assert health.faults == (Spall(location="nut", depth=30e-6), PreloadLoss(fraction=0.25))
    assert health.effective_preload == pytest.approx(6e-6)


def test_scenario_toml_round_trip_and_labels():
    health = HealthState(faults=({"kind": "spall", "location": "roller", "roller": 2},))
    scenario = Scenario(health=health)
    assert (
        Scenario.from_dict(
            {"health": {"faults": [{"kind": "spall", "location": "roller", "roller": 2}]}}
        ).health
        == health
    )
    labels = scenario.labels()
    assert labels["fault_kinds"] == "spall"
    assert json.loads(labels["faults"]) == [
        {"kind": "spall", "location": "roller", "depth": 20e-6, "length": 1.5e-3, "angle": 0.0,
         "roller": 2, "position": 0.0, "flank": "loaded"}
    ]  # fmt: skip
    path_text = scenario.to_toml()
    assert "[[health.faults]]" in path_text


def test_primary_class_precedence():
    t = FaultThresholds()
    assert t.classify(HealthState.uniform(5e-6)) == "healthy"
    assert t.classify(HealthState.uniform(5e-6, friction_scale=2.0)) == "lubrication"
    assert t.classify(HealthState.uniform(20e-6, friction_scale=2.0)) == "wear"
    assert t.classify(HealthState.uniform(40e-6, faults=(Spall(),))) == "spall"
    lost = HealthState.uniform(5e-6, preload=10e-6, faults=(PreloadLoss(fraction=0.8),))
    assert t.classify(lost) == "preload_loss"
    partly = HealthState.uniform(5e-6, preload=10e-6, faults=(PreloadLoss(fraction=0.2),))
    assert t.classify(partly) == "healthy"
    assert t.classify(HealthState.uniform(40e-6, faults=(ToothCrack(),))) == "tooth_damage"
    assert t.classify(HealthState.uniform(5e-6, lubricant_starvation=0.6)) == "lubrication"


def test_severity_scaling_names_the_field_out_of_range():
    assert scaled(Spall(length=2e-3), 2.0).length == pytest.approx(4e-3)
    assert scaled(ToothCrack(depth=0.2e-3), 2.0).depth == pytest.approx(0.4e-3)
    with pytest.raises(ParameterError, match="faults.length"):
        scaled(Spall(length=8e-3), 2.0)


@pytest.mark.parametrize(
    "table, field",
    [
        ({"kind": "crack"}, "faults.kind"),
        ({"kind": "spall", "location": "ring_gear"}, "faults.location"),
        ({"kind": "spall", "depth": -1e-6}, "faults.depth"),
        ({"kind": "spall", "size": 1.0}, r"unknown key 'size' in \[faults\]"),
        ({"kind": "preload_loss", "fraction": 2.0}, "faults.fraction"),
        ({"kind": "tooth_crack", "location": "nut"}, "faults.location"),
        ({"kind": "tooth_pit", "depth": -1e-6}, "faults.depth"),
        ({"kind": "tooth_crack", "tooth": -1}, "faults.tooth"),
    ],
)
def test_bad_fault_tables_name_the_field(table, field):
    with pytest.raises(ParameterError, match=field):
        fault_from_dict(table)


RECIPE = {
    "name": "faults",
    "design": "paper01",
    "duration": 0.05,
    "sample_rate": 5000,
    "seed": 1,
    "fault_cases": {
        "screw_spall": [{"kind": "spall", "location": "screw", "depth": 20e-6}],
        "two": [{"kind": "spall", "location": "nut"}, {"kind": "spall", "location": "roller"}],
    },
    "sweep": {"fault_case": ["none", "screw_spall", "two"], "severity": [0.5, 1.0]},
}


def test_recipe_sweeps_fault_kinds_and_severities():
    recipe = Recipe.from_dict(RECIPE)
    specs = recipe.runs()
    assert len(specs) == 6
    labels = [s.labels() for s in specs]
    assert {(x["fault_case"], x["severity"]) for x in labels} == {
        (c, s) for c in ("none", "screw_spall", "two") for s in (0.5, 1.0)
    }
    lengths = {
        (x["fault_case"], x["severity"]): [f["length"] for f in json.loads(x["faults"])]
        for x in labels
    }
    assert lengths[("screw_spall", 0.5)] == [pytest.approx(0.75e-3)]
    assert lengths[("two", 1.0)] == [pytest.approx(1.5e-3)] * 2
    assert lengths[("none", 1.0)] == []
    assert {x["fault_class"] for x in labels} == {"healthy", "spall"}
    random = Recipe.from_dict(
        dict(RECIPE, sweep={"mode": "random", "samples": 12, "fault_case": ["none", "two"],
                            "severity": [0.5, 2.0]})
    )  # fmt: skip
    assert {s.point["fault_case"] for s in random.runs()} == {"none", "two"}


@pytest.mark.parametrize(
    "change, message",
    [
        ({"sweep": {"fault_case": ["bogus"]}}, "sweep.fault_case"),
        ({"fault_cases": {"x": [{"kind": "spall", "depth": -1.0}]}}, "fault_cases.x"),
        ({"sweep": {"fault_case": ["screw_spall"], "severity": [20.0]}}, "faults.length"),
    ],
)
def test_recipe_fault_errors(change, message):
    with pytest.raises(RecipeError, match=message):
        Recipe.from_dict({**RECIPE, **change})


@pytest.mark.parametrize(
    "text, field",
    [
        ('[[faults]]\nkind = "crack"\n', "faults.kind"),
        ('[[faults]]\nkind = "spall"\nlocation = "ring"\n', "faults.location"),
        ('[[faults]]\nkind = "spall"\ndepth = -1e-6\n', "faults.depth"),
        ('[[faults]]\nkind = "preload_loss"\n', "faults.kind"),
        ('[[faults]]\nkind = "spall"\nposition = 0.3\n', "faults.position"),  # off the threads
        (
            '[[faults]]\nkind = "tooth_crack"\nlocation = "roller_gear"\ndepth = 0.9e-3\n',
            "faults.depth",
        ),
        ("clearance = [", "not valid TOML"),
    ],
)
def test_simulate_health_file_errors_are_one_line(tmp_path, capsys, text, field):
    path = tmp_path / "health.toml"
    path.write_text(text)
    code = main(["simulate", "--health", str(path), "--out", str(tmp_path / "r.parquet")])
    out, err = capsys.readouterr()
    assert code == 2
    assert err.startswith("error: ") and err.count("\n") == 1 and field in err, err
