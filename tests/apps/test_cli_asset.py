"""`prsm-health diagnose REC --asset ID` and `prsm-health asset show|list`: a unit's history kept
in a store directory, each recording counted once, the asset part in the table and the JSON, and
user errors as one line with exit status 2 (fast: a tiny model and tiny CSV recordings)."""

import json

import numpy as np
import pandas as pd
import pytest
from sklearn.dummy import DummyClassifier

from prsm_health.apps.cli import main
from prsm_health.diagnostics.model_files import save_model
from prsm_health.monitoring import FileAssetStore


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A tiny model (prior class probabilities, no clearance model, no design) and five 0.2 s
    CSV recordings with their own noise, the screw reversing in each (a window without a
    reversal cannot show the class: its answer would add no evidence)."""
    root = tmp_path_factory.mktemp("asset")
    x = pd.DataFrame({"ax_rms": np.linspace(0.0, 1.0, 12)})
    y = np.array(["healthy", "healthy", "wear", "lubrication"] * 3)
    save_model(
        root / "tiny.skops",
        {"clearance": None, "fault": DummyClassifier().fit(x, y), "feature_names": ["ax_rms"]},
        metadata={"name": "tiny", "model_version": "1", "design": None, "window": 0.2},
    )
    fs, n = 5000.0, 1000
    t = np.arange(n) / fs
    for k in range(5):
        rng = np.random.default_rng(k)
        speed = 100.0 * np.cos(2 * np.pi * 5.0 * t)  # [rad/s]: one reversal in 0.2 s
        angle = 100.0 / (2 * np.pi * 5.0) * np.sin(2 * np.pi * 5.0 * t)
        accel = (1 + 0.1 * k) * rng.standard_normal(n)
        table = np.column_stack([t, accel, angle, speed])
        np.savetxt(
            root / f"rec{k}.csv",
            table,
            delimiter=",",
            header="time,nut_axial_accel,screw_angle,screw_speed",
            comments="",
        )
    return root


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def diagnose(files, store, k, *extra):
    return [
        "diagnose",
        files / f"rec{k}.csv",
        "--model",
        files / "tiny.skops",
        "--asset",
        "pump-1",
        "--store",
        store,
        *extra,
    ]


def test_the_same_recording_twice_counts_once(files, tmp_path, capsys):
    code, out, _ = run(capsys, *diagnose(files, tmp_path, 0, "--json"))
    assert code == 0
    first = json.loads(out)["asset"]
    assert first["asset_id"] == "pump-1" and first["baseline"]["recordings"] == 1
    code, out, _ = run(capsys, *diagnose(files, tmp_path, 0))
    assert code == 0
    assert "already in the history of asset pump-1" in out
    assert "1 of 3 recordings" in out
    history = FileAssetStore(tmp_path).load("pump-1").history
    assert len(history.entries) == 1 and history.entries[0].filename == "rec0.csv"


def test_baseline_then_evidence_and_asset_show(files, tmp_path, capsys):
    for k in range(4):
        code, out, err = run(capsys, *diagnose(files, tmp_path, k, "--operating-hours", 10 * k))
        assert code == 0, err
    # the 4th: scored against the 3-recording baseline, evidence from it on
    table = {line.split("  ")[0]: line.split()[-2:] for line in out.splitlines()}
    assert table["baseline"] == ["3", "recordings"] and table["evidence"] == ["1", "recordings"]
    assert "baseline distance" in table and "change statistic" in table
    code, out, _ = run(capsys, "asset", "show", "pump-1", "--store", tmp_path)
    assert code == 0
    lines = out.splitlines()
    assert lines[0].split() == ["asset", "pump-1"]
    head = next(i for i, line in enumerate(lines) if line.startswith("recording "))
    rows = [line.split() for line in lines[head + 1 :]]
    assert [r[0] for r in rows] == ["rec0.csv", "rec1.csv", "rec2.csv", "rec3.csv"]
    assert [r[3] for r in rows] == ["yes", "yes", "yes", "no"]  # in the baseline?
    assert rows[3][2] == "30"  # operating hours
    code, out, _ = run(capsys, "asset", "show", "pump-1", "--store", tmp_path, "--json")
    report = json.loads(out)
    assert report["baseline"]["complete"] and report["evidence"]["recordings"] == 1
    assert "ax_rms" in report["baseline"]["indicators"]
    # with the model: the baseline of the indicators it reads (this one: ax_rms alone, no
    # prior scale, so the same centre)
    model = ("--model", files / "tiny.skops", "--json")
    code, out, _ = run(capsys, "asset", "show", "pump-1", "--store", tmp_path, *model)
    shown = json.loads(out)["baseline"]["indicators"]
    assert code == 0 and list(shown) == ["ax_rms"]
    assert shown["ax_rms"]["center"] == report["baseline"]["indicators"]["ax_rms"]["center"]
    code, out, _ = run(capsys, "asset", "list", "--store", tmp_path)
    assert out.split() == ["pump-1"]


def test_healthy_label_and_plain_diagnose_unchanged(files, tmp_path, capsys):
    code, out, _ = run(capsys, *diagnose(files, tmp_path, 1, "--unhealthy", "--json"))
    assert json.loads(out)["asset"]["baseline"]["recordings"] == 0
    code, out, _ = run(capsys, *diagnose(files, tmp_path, 2, "--healthy", "--time", "2024-01-01"))
    history = FileAssetStore(tmp_path).load("pump-1").history
    assert [e.baseline for e in history.entries] == [False, True]
    assert history.entries[1].time == "2024-01-01"
    # without --asset: no asset part, no store written
    code, out, _ = run(
        capsys, "diagnose", files / "rec0.csv", "--model", files / "tiny.skops", "--json"
    )
    assert code == 0 and "asset" not in json.loads(out)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--asset", "../etc"], "--asset"),
        (["--asset", "a b"], "--asset"),
        (["--healthy"], "give --asset"),
        (["--operating-hours", "5"], "give --asset"),
        (["--asset", "p", "--healthy", "--unhealthy"], "not allowed with"),
        (["--asset", "p", "--operating-hours", "-1"], "--operating-hours"),
        (["--asset", "p", "--time", "yesterday"], "ISO 8601"),
    ],
)
def test_bad_asset_options_are_one_line(files, tmp_path, capsys, argv, needle):
    code, out, err = run(
        capsys,
        "diagnose",
        files / "rec0.csv",
        "--model",
        files / "tiny.skops",
        "--store",
        tmp_path,
        *argv,
    )
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ") and needle in err
    assert not list(tmp_path.iterdir())  # nothing stored


def test_asset_show_errors_are_one_line(files, tmp_path, capsys):
    code, _, err = run(capsys, "asset", "show", "nobody", "--store", tmp_path)
    assert code == 2 and err.startswith("error: no asset 'nobody'") and err.count("\n") == 1
    code, _, err = run(capsys, "asset", "show", "a/b", "--store", tmp_path)
    assert code == 2 and "--asset" not in err and err.count("\n") == 1
    # a damaged history: one line naming the file, for show and for diagnose
    (tmp_path / "pump-1.json").write_text('{"format": 1, "asset_id": "pu')
    code, _, err = run(capsys, "asset", "show", "pump-1", "--store", tmp_path)
    assert code == 2 and "pump-1.json" in err and err.count("\n") == 1
    code, _, err = run(capsys, *diagnose(files, tmp_path, 0))
    assert code == 2 and "pump-1.json" in err and err.count("\n") == 1
