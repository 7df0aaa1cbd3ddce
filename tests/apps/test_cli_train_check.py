"""``train`` on a dataset of health checks: the check part of a bundle for the checks' own design
(a design file, not the shipped model's), which then reads a check phase by phase; bad input
refused in one line, exit status 2.

The training set is tiny (4 units × 4 checks of a 0.93 s check, 8 baseline checks): it shows the
path works, not how well a check part reads — that is measured by
tools/release/train_check_model.py on the shipped recipes."""

import json
from pathlib import Path

import pytest

from prsm_health.apps.cli import main
from prsm_health.datasets import Dataset, Recipe, generate
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL, diagnose, load_bundle
from prsm_health.io.parquet import write_run_parquet

DESIGN = str(Path(__file__).resolve().parents[2] / "datasets" / "designs" / "paper02.toml")

#: The conftest's short check (every role) as a recipe's inline table: 0.93 s.
SHORT = {
    "name": "short-check",
    "phases": [
        {"name": "quiet", "speed": 50.0, "load": 0.0, "duration": 0.1, "ramp_time": 0.02},
        {"name": "slow", "speed": -10.0, "load": "10 % C_a", "duration": 0.1, "ramp_time": 0.02},
        {"name": "fast", "speed": 100.0, "load": "10 % C_a", "duration": 0.06, "ramp_time": 0.02},
        {
            "name": "swing",
            "motion": "reversing",
            "speed": 10.0,
            "load": "25 % C_a",
            "duration": 0.25,
            "ramp_time": 0.02,
            "reversal_period": 0.125,
        },
        {"name": "heavy", "speed": -100.0, "load": "-25 % C_a", "duration": 0.3, "ramp_time": 0.02},
    ],
}
CHECKS = {
    "name": "tiny-checks",
    "design": DESIGN,
    "instrumentation": "flight-ema",
    "duration": 0.93,
    "sample_rate": 20000,
    "seed": 11,
    "test_fraction": 0.25,  # one unit of four held out
    "units": {"count": 4, "seed": 7},
    "profile": {"check": SHORT},
    "fault_cases": {"spall_nut": [{"kind": "spall", "location": "nut"}]},
    "sweep": {"mode": "grid", "fault_case": ["none", "spall_nut"], "repeats": 8},
}
BASELINE = {
    **CHECKS,
    "name": "tiny-baseline",
    "seed": 12,
    "fault_cases": {},
    "sweep": {"mode": "grid", "clearance": [4e-6], "repeats": 8},
}
#: Two checks of 0.07 s (two phases): enough for what is refused before training.
MINIMAL = {
    **CHECKS,
    "name": "minimal",
    "duration": 0.07,
    "units": {"count": 2, "seed": 7},
    "test_fraction": 0.5,
    "profile": {
        "check": {
            "name": "tiny",
            "phases": [
                {"name": "free", "speed": 50.0, "load": 0.0, "duration": 0.02, "ramp_time": 0.01},
                {"name": "on", "speed": -50.0, "load": 100.0, "duration": 0.02, "ramp_time": 0.01},
            ],
        }
    },
    "fault_cases": {},
    "sweep": {"mode": "grid", "clearance": [4e-6], "repeats": 2},
}


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def minimal(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("minimal") / "ds"
    generate(Recipe.from_dict(MINIMAL), path, workers=1, progress=False)
    return path


@pytest.fixture(scope="module")
def checks(tmp_path_factory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("checks")
    for recipe in (CHECKS, BASELINE):
        generate(Recipe.from_dict(recipe), folder / recipe["name"], workers=1, progress=False)
    return folder / CHECKS["name"], folder / BASELINE["name"]


@pytest.mark.slow
def test_train_on_checks_builds_a_check_part_that_reads_a_check_phase_by_phase(
    capsys, tmp_path, checks
):
    dataset, baseline = checks
    out = tmp_path / "own.skops"
    code, printed, _ = run(capsys, "train", dataset, "--baseline", baseline, "--out", out)
    assert code == 0, printed
    assert "check part only" in printed and "paper02" in printed
    bundle = load_bundle(out)
    assert bundle.check is not None and bundle.check_only
    assert bundle.design_name == "paper02"
    metrics = json.loads(out.with_name("own.check.metrics.json").read_text())
    assert metrics["check"]["runs"] == {"train": 12, "test": 4}
    # the clearance gauge calibrated on the training units' checks, commissioned by their
    # baselines, and scored on the held-out units'
    gauge = metrics["check"]["gauge"]
    assert gauge["commissioned"]["calibration_checks"] == 12
    assert gauge["nominal"]["held_out_checks"] == 4
    assert bundle.check["gauge"]["commissioned_scale"] > 0
    assert bundle.clearance_gauge.commissioned_scale == bundle.check["gauge"]["commissioned_scale"]

    ds = Dataset(dataset)
    held_out = int(ds.runs.loc[ds.runs["split"] == "test", "run_id"].iloc[0])
    d = diagnose(ds.run(held_out, truth=False), bundle)
    assert d.check_phases and not d.windows  # phase by phase, not window by window
    assert d.measured_clearance is not None and d.measured_clearance.learnt is not None
    assert not [w for w in d.warnings if "no health-check part" in w]

    # the front door: the recording as a file, read against the unit's baseline
    recording = write_run_parquet(ds.run(held_out, truth=False), tmp_path / "check.parquet")
    code, printed, _ = run(
        capsys, "diagnose", recording, "--model", out, "--asset", "u-3", "--store", tmp_path / "s"
    )
    assert code == 0 and "check phases" in printed and "asset" in printed


def test_a_check_dataset_without_baseline_is_refused_in_one_line(capsys, tmp_path, minimal):
    code, out, err = run(capsys, "train", minimal, "--out", tmp_path / "m.skops")
    assert code == 2 and not out
    assert err.count("\n") == 1 and err.startswith("error: ") and "--baseline" in err
    assert not (tmp_path / "m.skops").exists()


def test_a_window_model_of_another_design_is_refused(capsys, tmp_path, minimal):
    # the shipped model is of paper01, the checks of paper02
    code, _, err = run(
        capsys,
        "train",
        minimal,
        "--baseline",
        minimal,
        "--window-model",
        DEFAULT_MODEL,
        "--out",
        tmp_path / "m.skops",
    )
    assert code == 2 and err.count("\n") == 1 and "--window-model" in err and "paper01" in err


def test_too_few_units_are_refused_before_training(capsys, tmp_path, minimal):
    code, _, err = run(
        capsys, "train", minimal, "--baseline", minimal, "--out", tmp_path / "m.skops"
    )
    assert code == 2 and err.count("\n") == 1 and "training units" in err and "--cv" in err


def test_baseline_and_window_model_are_options_of_check_datasets(capsys, tmp_path):
    code, _, err = run(
        capsys, "train", "x", "--target", "rul", "--baseline", "y", "--out", tmp_path / "m.json"
    )
    assert code == 2 and "--baseline" in err and err.count("\n") == 1
