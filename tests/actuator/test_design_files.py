"""Design files: dict and TOML round trips, the shipped preset files, `prsm-health design`,
`--design FILE`, scenarios and recipes with a design file."""

import dataclasses
import json
import math
import re
from dataclasses import fields
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design import PRESETS, PRSMDesign, preset
from prsm_health.actuator.design_files import (
    FIELDS,
    design_fingerprint,
    design_to_toml,
    load_design,
)
from prsm_health.apps.cli import main
from prsm_health.core.errors import ParameterError, PRSMHealthError
from prsm_health.datasets import load_recipe
from prsm_health.simulation.scenario import Scenario

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_every_preset_round_trips(name, tmp_path):
    design = preset(name)
    assert PRSMDesign.from_dict(design.to_dict()) == design
    path = tmp_path / f"{name}.toml"
    path.write_text(design_to_toml(design))
    loaded = load_design(path)
    assert loaded == design and loaded.reference == design.reference
    # the shipped file (tools/release/make_design_files.py) equals its preset
    assert load_design(ROOT / "datasets" / "designs" / f"{name}.toml") == design


def test_every_field_has_a_unit_and_meaning():
    top = {f.name for f in fields(PRSMDesign)}
    nested = {
        "masses",
        "gear",
        "screw_material",
        "roller_material",
        "nut_material",
        "recirculation",
    }
    assert top - nested <= set(FIELDS)


def test_from_dict_errors_name_the_field():
    data = preset().to_dict()
    with pytest.raises(
        ParameterError,
        match=r"unknown key 'modul' in \[design\.gear\] \(did you mean 'module'\?\).*allowed: ring_teeth",
    ):
        PRSMDesign.from_dict({**data, "gear": {**data["gear"], "modul": 1e-3}})
    with pytest.raises(ParameterError, match=r"design\.pitch .*expected a number"):
        PRSMDesign.from_dict({**data, "pitch": "2 mm"})
    with pytest.raises(ParameterError, match=r"design\.n_rollers .*expected an integer"):
        PRSMDesign.from_dict({**data, "n_rollers": 7.0})
    with pytest.raises(ParameterError, match=r"design\.masses "):
        PRSMDesign.from_dict({k: v for k, v in data.items() if k != "masses"})


def test_load_design_file_errors(tmp_path):
    with pytest.raises(PRSMHealthError, match="missing.toml: no such design file"):
        load_design(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("pitch = = 1\n")
    with pytest.raises(PRSMHealthError, match="bad.toml: not valid TOML"):
        load_design(bad)
    with pytest.raises(ParameterError, match="paper99"):
        load_design("paper99")


def _check(path, capsys) -> tuple[int, str, str]:
    code = main(["design", "check", str(path)])
    out, err = capsys.readouterr()
    return code, out, err


def test_template_then_check(tmp_path, capsys):
    assert main(["design", "template", "--from", "paper02"]) == 0
    path = tmp_path / "mine.toml"
    path.write_text(capsys.readouterr().out)
    assert load_design(path) == preset("paper02")
    assert _check(path, capsys) == (0, "ok: paper02\n", "")


def test_the_recirculating_template_writes_its_cam_ring_geometry_out_and_checks_it(
    tmp_path, capsys
):
    from prsm_health.physics.recirculating import RecirculatingGeometry

    assert main(["design", "template", "--variant", "recirculating"]) == 0
    text = capsys.readouterr().out
    assert "[recirculation]" in text and "groove_length = " in text
    path = tmp_path / "mine.toml"
    path.write_text(text)
    mine, paper03 = load_design(path), preset("paper03")
    # every rule's value written out: the same geometry as the preset's derived one
    assert RecirculatingGeometry.for_design(mine) == RecirculatingGeometry.for_design(paper03)
    assert _check(path, capsys) == (0, "ok: paper03\n", "")
    # a value the design file sets is checked against paper 03 and named as its field there
    # the whole line replaced: the written value's last digits are the platform's arithmetic
    path.write_text(
        re.sub(r"(?m)^carrier_outer_diameter = .*$", "carrier_outer_diameter = 0.1", text)
    )
    code, out, err = _check(path, capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("error: design.recirculation.carrier_outer_diameter = 0.1 is invalid")
    assert "eq. 15" in err
    # a standard design has no cam ring; a standard preset is no recirculating template
    data = preset("paper01").to_dict()
    with pytest.raises(ParameterError, match=r"design\.recirculation .*standard PRSM"):
        PRSMDesign.from_dict({**data, "recirculation": {"groove_length": 0.02}})
    assert main(["design", "template", "--variant", "recirculating", "--from", "paper01"]) == 2
    assert capsys.readouterr().err.startswith("error: --from paper01 is a standard design")


def test_a_design_without_a_recirculation_table_keeps_its_fingerprint():
    from prsm_health.actuator.recirculation_spec import RecirculationSpec

    paper03 = preset("paper03")
    # fingerprints from before the table existed (2026-12-02, the roller mass aside: paper01)
    assert design_fingerprint("paper01") == "8bb0837666273084"
    empty = dataclasses.replace(paper03, recirculation=RecirculationSpec())
    assert design_fingerprint(empty) == design_fingerprint(paper03)
    given = dataclasses.replace(paper03, recirculation=RecirculationSpec(groove_length=0.021))
    assert design_fingerprint(given) != design_fingerprint(paper03)


@pytest.mark.parametrize(
    "old, new, message",
    [
        (
            "module = 0.0005",
            "modul = 0.0005",
            "unknown key 'modul' in [design.gear] (did you mean 'module'?)",
        ),
        ("pitch = 0.002", 'pitch = "0.002"', "design.pitch = "),
        ("nut_diameter = 0.0325", "nut_diameter = 0.04", "design.nut_diameter = "),
        # a length typed in mm is blamed on its own key, not on a length computed from it
        ("pitch = 0.002", "pitch = 2", "design.pitch = 2 is invalid: must be ≤ 0.1 m"),
        ("screw_diameter = 0.0195", "screw_diameter = 19.5", "design.screw_diameter = 19.5 "),
        ("face_width = 0.003", "face_width = 3", "gear.face_width = 3 "),
        # a ring gear of twice the nut's pitch diameter (the teeth ratio still d_n/d_r)
        ("module = 0.0005", "module = 0.001", "gear.module = 0.001 is invalid: must lie in ["),
    ],
)
def test_check_refuses_a_bad_file_in_one_line(old, new, message, tmp_path, capsys):
    text = design_to_toml(preset("paper01"))
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    code, out, err = _check(path, capsys)
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and err.startswith(f"error: {message}")


def test_show_table_and_json(capsys):
    assert main(["design", "show", "paper05", "--json"]) == 0
    assert PRSMDesign.from_dict(json.loads(capsys.readouterr().out)) == preset("paper05")
    assert main(["design", "show", str(ROOT / "datasets/designs/paper01.toml")]) == 0
    out = capsys.readouterr().out
    assert "gear.module" in out and "0.0005 m" in out and "masses.screw_inertia" in out


def test_show_prints_the_lead_and_angles_in_degrees(capsys):
    design = preset("paper01")
    assert main(["design", "show", "paper01"]) == 0
    lines = capsys.readouterr().out.splitlines()
    rows = dict(re.split(r"\s{2,}", line, maxsplit=1) for line in lines)
    assert rows["contact_angle"].startswith(f"{math.degrees(design.contact_angle):.6g} °")
    assert rows["gear.pressure_angle"].startswith(
        f"{math.degrees(design.gear.pressure_angle):.6g} °"
    )
    assert rows["lead (screw and nut, starts × pitch)"] == f"{design.screw_lead:.6g} m"
    lead_angle = math.degrees(math.atan(design.screw_lead / (math.pi * design.screw_diameter)))
    assert rows["lead angle λ_s (screw)"] == f"{lead_angle:.6g} °"


def test_simulate_with_a_design_file_equals_the_preset(tmp_path, capsys):
    common = ["simulate", "--duration", "0.02", "--json"]
    path = ROOT / "datasets" / "designs" / "paper01.toml"
    assert main([*common, "--design", str(path), "--out", str(tmp_path / "f.parquet")]) == 0
    assert main([*common, "--design", "paper01", "--out", str(tmp_path / "p.parquet")]) == 0
    capsys.readouterr()
    a, b = pd.read_parquet(tmp_path / "f.parquet"), pd.read_parquet(tmp_path / "p.parquet")
    pd.testing.assert_frame_equal(a, b)


def test_scenario_design_name_path_or_dict(tmp_path):
    modified = preset().with_(name="mine", n_rollers=6)
    path = tmp_path / "mine.toml"
    path.write_text(design_to_toml(modified))
    for design in ("paper01", str(path), preset().to_dict()):
        Scenario.from_dict({"design": design})  # all accepted
    scenario = Scenario.from_dict({"design": str(path)})
    assert scenario.design == modified
    assert Scenario.from_dict({"design": "paper01"}).to_dict()["design"] == "paper01"
    recorded = scenario.to_dict()["design"]
    assert recorded == modified.to_dict()  # a modified design is recorded in full
    assert Scenario.from_dict(scenario.to_dict()) == scenario
    # to_toml / from_toml carry the full design as [design] tables; file paths in a scenario
    # file are relative to it
    toml_path = tmp_path / "scenario.toml"
    toml_path.write_text(scenario.to_toml())
    assert Scenario.from_toml(toml_path) == scenario
    toml_path.write_text('design = "mine.toml"\n')
    assert Scenario.from_toml(toml_path).design == modified


def test_recipe_with_a_relative_design_path(tmp_path, monkeypatch):
    (tmp_path / "designs").mkdir()
    modified = preset("paper04").with_(name="wide", n_rollers=8)
    (tmp_path / "designs" / "wide.toml").write_text(design_to_toml(modified))
    recipe_path = tmp_path / "recipe.toml"
    recipe_path.write_text(
        'name = "r"\ndesign = "designs/wide.toml"\nduration = 0.01\nsample_rate = 20000\n'
        "seed = 1\n[sweep]\nclearance = [0.0, 1e-5]\n"
    )
    monkeypatch.chdir(ROOT)  # the path is relative to the recipe, not the working directory
    recipe = load_recipe(recipe_path)
    assert recipe.source["design"] == modified.to_dict()  # workers rebuild from the source
    specs = recipe.runs()
    assert [s.scenario().design for s in specs] == [modified, modified]
    assert specs[0].labels()["design"] == "wide"
    assert load_recipe(recipe_path).fingerprint == recipe.fingerprint  # deterministic
    recipe_path.write_text(recipe_path.read_text().replace("wide.toml", "none.toml"))
    with pytest.raises(PRSMHealthError, match="none.toml: no such design file"):
        load_recipe(recipe_path)
    assert np.isfinite(specs[0].point["clearance"])
