"""``prsm-health train FLEET --target rul``: a prognostics model fitted on a fleet dataset, saved,
its report printed; ``prognose`` then takes histories of the fleet's design and refuses others.
Every bad input is one line ``error: …`` with exit status 2.

The fleet is a tiny life recipe of paper01 (4 units × 3 snapshots of 0.1 s), diagnosed by the
shipped model: fitting for one's own design needs a diagnosis model of that design, too costly
to train here — the refusal without one is checked instead (tests/test_own_design.py fits one
from given histories through the library).
"""

import contextlib
import copy
import inspect
import io
import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.design_files import design_fingerprint
from prsm_health.apps.cli import main
from prsm_health.apps.cli.models_options import DEFAULT_CV, TRAIN_TARGETS
from prsm_health.datasets import Recipe, generate
from prsm_health.prognostics import load_prognostics_model
from prsm_health.training import train as training

FLEET = {
    "name": "tiny-fleet",
    "design": "paper01",
    "instrumentation": "flight-ema",
    "duration": 0.1,
    "sample_rate": 20000,
    "seed": 3,
    "test_fraction": 0.25,
    "sweep": {"mode": "random", "speed": [80.0, 120.0], "load_amplitude": [1000.0, 2000.0]},
    "profile": {"load_profile": "reversing"},
    "options": {"contact_law": "hertz"},
    "life": {"units": 4, "snapshots": 3},
    "batch_size": 6,  # one batch per worker
}
BASE = preset("paper01")
#: paper01 renamed, with a nut twice as heavy: another mechanism.
MINE = BASE.with_(name="rig-7", masses=replace(BASE.masses, nut_mass=2 * BASE.masses.nut_mass))


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    out = tmp_path_factory.mktemp("fleet") / "tiny-fleet"
    generate(Recipe.from_dict(copy.deepcopy(FLEET)), out, workers=2, progress=False)
    return out


@pytest.fixture(scope="module")
def fitted(fleet, tmp_path_factory):
    """``train --target rul --json``: (the model file, the printed report)."""
    path = tmp_path_factory.mktemp("model") / "prognostics.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = main(["train", str(fleet), "--target", "rul", "--out", str(path), "--json"])
    assert code == 0
    return path, json.loads(printed.getvalue())


def test_the_parser_mirrors_the_library():
    assert TRAIN_TARGETS == (*training.TARGETS, "rul")
    assert DEFAULT_CV == inspect.signature(training.train).parameters["cv"].default


def test_json_report_and_the_saved_model(fitted):
    path, report = fitted
    assert report["model"] == str(path)
    assert report["design"] == "paper01"
    assert report["design_fingerprint"] == design_fingerprint("paper01")
    assert report["threshold_learnt"] and report["threshold"] > 0
    assert len(report["train_units"]) == 3 and len(report["test_units"]) == 1
    # a fleet dataset carries its [life] recipe: the physics method is fitted and scored too
    methods = {"degradation", "similarity", "physics"}
    assert report["snapshots"] == 12 and set(report["summary"]) == methods
    model = load_prognostics_model(path)
    assert model.ageing_ is not None
    assert model.design_id == ("paper01", design_fingerprint("paper01"))
    assert model.threshold == pytest.approx(report["threshold"], rel=1e-12)


def test_table_with_a_given_threshold(fleet, tmp_path, capsys):
    path = tmp_path / "p.json"
    code, out, err = run(
        capsys, "train", fleet, "--target", "rul", "--out", path, "--threshold", "25e-6"
    )
    assert code == 0, err
    lines = {line.split("  ")[0]: line for line in out.splitlines()}
    assert str(path) in lines["model"]
    assert design_fingerprint("paper01") in lines["design"]
    assert "3 training, 1 held out" in lines["units"]
    assert "25.0 µm" in lines["failure threshold"] and "given" in lines["failure threshold"]
    assert "degradation held-out RMSE" in lines and "similarity prognostic horizon" in lines
    assert load_prognostics_model(path).threshold == 25e-6


def _history(fleet, design: str, fingerprint: str) -> pd.DataFrame:
    """A unit's history as a diagnosis would give it: its true clearance ± 0.3 µm."""
    runs = pd.read_parquet(fleet / "runs.parquet")
    unit = runs[runs["unit_id"] == runs["unit_id"].max()].sort_values("age_hours")
    noise = 0.3e-6 * np.random.default_rng(0).standard_normal(len(unit))
    value = unit["clearance_mean_true"].to_numpy() + noise
    return pd.DataFrame(
        {
            "age_hours": unit["age_hours"].to_numpy(),
            "clearance": value,
            "clearance_lower": value - 0.5e-6,
            "clearance_upper": value + 0.5e-6,
            "design": design,
            "design_fingerprint": fingerprint,
        }
    )


def test_prognose_takes_histories_of_the_design_and_refuses_others(fleet, fitted, tmp_path, capsys):
    ours = tmp_path / "ours.csv"
    _history(fleet, "paper01", design_fingerprint("paper01")).to_csv(ours, index=False)
    model = fitted[0]
    code, out, err = run(capsys, "prognose", ours, "--model", model, "--json")
    assert code == 0, err
    assert json.loads(out)["rul_hours"]["estimate"] >= 0
    other = tmp_path / "other.csv"
    _history(fleet, "rig-7", design_fingerprint(MINE)).to_csv(other, index=False)
    code, out, err = run(capsys, "prognose", other, "--model", model)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert "another design" in err and "rig-7" in err


def test_a_fleet_of_another_design_needs_its_own_diagnosis_model(tmp_path, capsys):
    (tmp_path / "mine.toml").write_text(_design_toml())
    recipe = copy.deepcopy(FLEET) | {"name": "own", "design": "mine.toml", "duration": 0.05}
    recipe["instrumentation"] = "ideal"
    # the heavier nut's contacts are stiffer than paper01's default step allows
    recipe["options"] = {"contact_law": "hertz", "max_step": "auto"}
    generate(Recipe.from_dict(recipe, base=tmp_path), tmp_path / "own", workers=2, progress=False)
    code, out, err = run(
        capsys, "train", tmp_path / "own", "--target", "rul", "--out", tmp_path / "p.json"
    )
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert "diagnosis model is for design 'paper01'" in err and "'rig-7'" in err
    assert not (tmp_path / "p.json").exists()


def _design_toml() -> str:
    from prsm_health.actuator.design_files import design_to_toml

    return design_to_toml(MINE)


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--target", "rul", "--cv", "3"], "--cv applies to --target clearance, fault or both"),
        (["--target", "clearance", "--threshold", "3e-5"], "--threshold applies to --target rul"),
        (["--model", "m.skops"], "--model applies to --target rul, not to --target both"),
        (["--target", "rul", "--threshold=-1e-6"], "--threshold -1e-06 must be a clearance"),
        (["--target", "rul", "--threshold", "nan"], "--threshold"),
        (["--target", "rul", "--model", "missing.skops"], "missing.skops"),
        (["--target", "astrology"], "--target"),
    ],
)
def test_bad_options_are_one_line_exit_2(fleet, tmp_path, capsys, extra, words):
    code, out, err = run(capsys, "train", fleet, "--out", tmp_path / "p.json", *extra)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert words in err and "Traceback" not in err
    assert not (tmp_path / "p.json").exists()


@pytest.mark.parametrize(
    "make, out, words",
    [
        (lambda d: d.mkdir(), "p.json", "no manifest.json"),
        (lambda d: None, "p.skops", "a prognostics model is a .json file"),
    ],
)
def test_bad_fleet_or_out_is_one_line_exit_2(fleet, tmp_path, capsys, make, out, words):
    target = tmp_path / "not-a-dataset"
    make(target)
    source = target if target.exists() else fleet
    code, printed, err = run(capsys, "train", source, "--target", "rul", "--out", tmp_path / out)
    assert code == 2 and printed == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert words in err
