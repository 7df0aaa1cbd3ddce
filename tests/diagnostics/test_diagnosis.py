"""Training on a small dataset, diagnosis of recordings, the regime gate, bad input, the CLI."""

import json
import textwrap

import numpy as np
import pandas as pd
import pytest

from prsm_health.apps.cli import main
from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.errors import ModelVersionError
from prsm_health.datasets import generate
from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
from prsm_health.io import read_recording
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet
from prsm_health.training.train import train

# Trains a model on a generated dataset (≈ 20 s) and diagnoses simulated recordings.
pytestmark = pytest.mark.slow

RECIPE = textwrap.dedent(
    """
    name = "diag-test"
    design = "paper01"
    duration = 0.2
    sample_rate = 20000
    instrumentation = "ideal"
    seed = 5
    test_fraction = 0.2
    batch_size = 4  # 10 batches: both workers busy to the end (5 batches of 8 leave one idle)
    [profile]
    load_profile = "reversing"
    load_amplitude = 300.0
    load_frequency = 10.0
    accel_time = 0.002
    [options]
    contact_law = "hertz"
    [sweep]
    clearance = [2e-6, 10e-6, 18e-6, 26e-6, 34e-6]
    speed = [60.0, 100.0]
    load = [0.0, 100.0]
    friction_scale = [1.0, 2.2]
    repeats = 1
    """
)


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    root = tmp_path_factory.mktemp("diag")
    recipe = root / "r.toml"
    recipe.write_text(RECIPE)
    generate(recipe, root / "ds", workers=2, progress=False)
    metrics = train(root / "ds", root / "model.skops", cv=2, progress=False)
    return root / "model.skops", metrics


def test_training_writes_model_and_metrics(model):
    path, metrics = model
    assert path.exists() and path.with_name("model.metrics.json").exists()
    stored = json.loads(path.with_name("model.metrics.json").read_text())
    assert stored["clearance_test"]["mae"] == pytest.approx(metrics["clearance_test"]["mae"])
    assert {"clearance_cv", "fault_cv", "clearance_importance", "fault_importance"} <= set(stored)
    groups = {r["name"] for r in stored["clearance_importance"] if r["kind"] == "group"}
    assert {"mesh", "axial_frequency", "lost_motion"} <= groups
    bundle = load_bundle(path)
    assert bundle.channels == CHANNEL_NAMES  # what a recording must have for this model
    assert not {"friction_torque_mean", "friction_torque_ripple"} & set(bundle.feature_names)


def test_diagnosis_contract(model, reversing_run):
    bundle = load_bundle(model[0])
    result = diagnose(reversing_run(26e-6), bundle).to_json()
    assert set(result) >= {
        "clearance",
        "fault_class",
        "class_probabilities",
        "indicators",
        "model",
        "windows",
    }
    assert set(result["clearance"]) == {"estimate", "lower", "upper"}
    c = result["clearance"]
    assert c["lower"] <= c["estimate"] <= c["upper"]
    assert sum(result["class_probabilities"].values()) == pytest.approx(1.0)
    assert set(result["class_set"]) <= set(result["class_probabilities"])
    # a named class is in its set and reached P = 0.5; a set of several classes is warned about
    if result["fault_class"] != "cannot_tell":
        assert result["fault_class"] in result["class_set"]
        assert result["class_probabilities"][result["fault_class"]] >= 0.5
    if len(result["class_set"]) > 1:
        assert any("not ruled out at 90 %" in w for w in result["warnings"])
    assert result["model"]["name"] == "diag-test-model"
    json.dumps(result, allow_nan=False)  # plain JSON (NaN indicators become null)


def test_small_model_orders_clearances(model, reversing_run):
    # Accuracy belongs to the shipped model (tests/test_default_model.py, 400 training runs):
    # a 32-run model is biased by several µm, and an impact-dominated recording differs sample
    # by sample on another CPU, so one estimate is no test. What must hold on any machine: two
    # recordings 24 µm apart (lost motion grows by ≈ 4·24 µm) are told apart by more than half
    # that gap, on average over two seeds each.
    bundle = load_bundle(model[0])

    def mean_estimate(clearance):
        estimates = [
            diagnose(reversing_run(clearance, seed=seed), bundle).clearance["estimate"]
            for seed in (9, 10)
        ]
        return float(np.mean(estimates))

    assert mean_estimate(30e-6) - mean_estimate(6e-6) > 12e-6


def test_regime_gate_reports_the_trained_range_without_reversal(model, reversing_run):
    bundle = load_bundle(model[0])
    steady = diagnose(reversing_run(26e-6, load=100.0, load_profile="constant"), bundle).to_json()
    assert steady["indicators"]["lost_motion"] is None
    span = bundle.metadata["clearance_range"]
    assert [steady["clearance"]["lower"], steady["clearance"]["upper"]] == pytest.approx(span)
    # no class either (the wear classes differ by clearance), and a sentence saying why
    assert steady["fault_class"] == "cannot_tell"
    assert steady["observability"] == {"clearance": 0.0, "fault": 0.0}
    assert any("no load or motion reversal" in w for w in steady["warnings"])
    reversing = diagnose(reversing_run(26e-6), bundle).to_json()
    assert reversing["observability"]["clearance"] == 1.0
    assert reversing["indicator_groups"]["lost_motion"] == "computed"


def test_evaluate_cli(model, tmp_path, capsys):
    dataset = model[0].parent / "ds"
    argv = ["evaluate", str(model[0]), str(dataset), "--json", "--plot", str(tmp_path / "f")]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    test_runs = int((pd.read_parquet(dataset / "runs.parquet")["split"] == "test").sum())
    assert report["runs"] == test_runs
    c = report["clearance"]
    assert 0 <= c["coverage"] <= 1 and c["mae"] > 0 and c["observable"]["n"] <= test_runs
    matrix = np.array(report["fault"]["confusion"]["matrix"])
    assert matrix.sum() == test_runs
    for name in ("clearance.png", "calibration.png", "confusion.png"):
        assert (tmp_path / "f" / name).read_bytes()[:4] == b"\x89PNG"
    # the same numbers as the training's held-out metrics where no gate intervened
    metrics = json.loads(model[0].with_name("model.metrics.json").read_text())
    if c["observable_fraction"] == 1.0 and report["ood"]["flagged_fraction"] == 0.0:
        assert c["mae"] == pytest.approx(metrics["clearance_test"]["mae"], rel=1e-9)
    assert main(["evaluate", str(model[0]), str(tmp_path / "nowhere")]) == 2
    assert capsys.readouterr().err.startswith("error: ")


def test_sources_mcap_parquet_csv_agree(model, tmp_path, reversing_run):
    run = reversing_run(10e-6)
    write_mcap(run, tmp_path / "r.mcap")
    write_run_parquet(run, tmp_path / "r.parquet")
    run.to_frame().to_csv(tmp_path / "r.csv", index=False)
    bundle = load_bundle(model[0])
    estimates = [
        diagnose(read_recording(tmp_path / f"r.{ext}"), bundle).clearance["estimate"]
        for ext in ("mcap", "parquet", "csv")
    ]
    assert estimates[0] == pytest.approx(estimates[1], rel=1e-9)
    assert estimates[2] == pytest.approx(estimates[1], rel=1e-6)  # CSV: 17-digit text


def test_bad_inputs(model, tmp_path, capsys, reversing_run):
    path = str(model[0])
    run = reversing_run(10e-6, duration=0.01)
    write_run_parquet(run, tmp_path / "short.parquet")
    pd.DataFrame({"time": np.arange(5000) / 2e4, "temperature": np.ones(5000)}).to_csv(
        tmp_path / "nochan.csv", index=False
    )
    frame = reversing_run(10e-6).to_frame()
    frame.loc[100, "nut_axial_accel"] = np.nan
    frame.to_csv(tmp_path / "nan.csv", index=False)
    cases = [
        (["diagnose", str(tmp_path / "short.parquet"), "--model", path], "too short"),
        (["diagnose", str(tmp_path / "nochan.csv"), "--model", path], "no usable channels"),
        (["diagnose", str(tmp_path / "nan.csv"), "--model", path], "NaN"),
        (["diagnose", str(tmp_path / "missing.mcap"), "--model", path], "no such file"),
        (
            ["diagnose", str(tmp_path / "nochan.csv"), "--model", str(tmp_path / "nochan.csv")],
            "model",
        ),
    ]
    for argv, needle in cases:
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: ") and needle in err and len(err.strip().splitlines()) == 1, (
            err
        )


def test_model_from_another_version(model, tmp_path, capsys, monkeypatch, reversing_run):
    import prsm_health.diagnostics.model_files as est

    monkeypatch.setattr(est, "__version__", "9.9.0")
    with pytest.raises(ModelVersionError):
        load_bundle(model[0])
    write_run_parquet(reversing_run(10e-6), tmp_path / "r.parquet")
    assert main(["diagnose", str(tmp_path / "r.parquet"), "--model", str(model[0])]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "9.9.0" in err and len(err.strip().splitlines()) == 1


def test_cli_diagnose_plot_and_replay_with_diagnosis(model, tmp_path, capsys, reversing_run):
    run = reversing_run(18e-6, duration=0.6)
    write_mcap(run, tmp_path / "r.mcap")
    assert (
        main(
            [
                "diagnose",
                str(tmp_path / "r.mcap"),
                "--model",
                str(model[0]),
                "--json",
                "--plot",
                str(tmp_path / "d.png"),
            ]
        )
        == 0
    )
    result = json.loads(capsys.readouterr().out)
    assert len(result["windows"]) == 3
    assert (tmp_path / "d.png").read_bytes()[:4] == b"\x89PNG"
    out = tmp_path / "diag.mcap"
    assert (
        main(
            [
                "replay",
                str(tmp_path / "r.mcap"),
                "--model",
                str(model[0]),
                "--out",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    replay = json.loads(capsys.readouterr().out)
    assert len(replay["windows"]) == 3
    from mcap.reader import make_reader

    with open(out, "rb") as f:
        messages = [
            json.loads(m.data)
            for _, c, m in make_reader(f).iter_messages(topics=["/prsm/diagnosis"])
        ]
    assert len(messages) == 3 and "clearance" in messages[0]
