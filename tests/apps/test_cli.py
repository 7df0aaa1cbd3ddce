"""The prsm-health command line: output contracts and one-line errors with exit status 2."""

import json
import subprocess
import sys

import pytest

from prsm_health.apps.cli import main

GEAR = [
    "stiffness",
    "gear",
    "--z1",
    "13",
    "--z2",
    "65",
    "--module",
    "0.0005",
    "--pressure-angle",
    "20",
    "--face-width",
    "0.003",
    "--bore-diameter",
    "0",
]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_kinematics_json(capsys):
    code, out, _ = run(capsys, "kinematics", "--design", "paper01", "--speed", "100", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["ratios"]["carrier"] == pytest.approx(0.375)
    assert data["frequencies"]["gear_mesh"] == pytest.approx(387.94, abs=0.01)


def test_kinematics_speed_defaults_as_simulate(capsys):
    from prsm_health.apps.cli import build_parser

    simulate = build_parser().parse_args(["simulate"]).speed
    code, out, _ = run(capsys, "kinematics", "--json")
    assert code == 0
    assert json.loads(out)["screw_speed"] == simulate


def test_stiffness_gear_json_contract(capsys):
    code, out, _ = run(capsys, *GEAR, "--internal", "--threaded-tooth", "--json")
    assert code == 0
    data = json.loads(out)
    assert set(data) >= {"contact_ratio", "k_min", "k_max", "k_mean"}
    assert 1.0 < data["contact_ratio"] < 3.0
    assert 0 < data["k_min"] <= data["k_mean"] <= data["k_max"]


def test_stiffness_axial_and_cylinder(capsys):
    code, out, _ = run(
        capsys, "stiffness", "axial", "--design", "paper04", "--load", "10000", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert data["secant_stiffness"] > 0 and data["deformation"] > 0
    code, out, _ = run(
        capsys, "stiffness", "cylinder", "--load", "1000", "--extension", "0.3", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert data["total"] == pytest.approx(sum(data["components"].values()), rel=1e-9)
    assert data["stiffness"] == pytest.approx(1000 / data["total"], rel=1e-9)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["stiffness", "gear", "--z1", "-3", *GEAR[4:]], "z1"),
        (["stiffness", "gear", *GEAR[2:8], "--face-width", "-1"], "face_width"),
        (["stiffness", "axial", "--design", "nope", "--load", "1"], "--design"),
        (["stiffness", "axial", "--design", "paper01", "--load", "-5"], "load"),
        (["stiffness", "cylinder", "--load", "100", "--extension", "-1"], "extension"),
        (["kinematics", "--speed", "fast"], "--speed"),
        (["frobnicate"], "frobnicate"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, argv, needle):
    code, out, err = run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert needle in lines[0]
    assert "Traceback" not in err


def test_console_script_runs_as_a_process():
    # The real entry point, as a user types it: exit 2 and a one-line error, no traceback.
    proc = subprocess.run(
        [sys.executable, "-m", "prsm_health.apps.cli", *GEAR[:2], "--z1", "-3", *GEAR[4:]],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: ") and "Traceback" not in proc.stderr


def test_simulate_writes_parquet_and_plot(tmp_path, capsys):
    out = tmp_path / "run.parquet"
    png = tmp_path / "run.png"
    code, stdout, _ = run(
        capsys,
        "simulate",
        "--duration",
        "0.02",
        "--seed",
        "2",
        "--out",
        str(out),
        "--plot",
        str(png),
        "--json",
    )
    assert code == 0
    summary = json.loads(stdout)
    assert summary["gear_mesh_frequency"] == pytest.approx(387.94, abs=0.01)
    assert summary["instrumentation"] == "flight-ema"  # the default profile
    import pandas as pd

    frame = pd.read_parquet(out)
    assert len(frame) == summary["samples"] and "nut_axial_accel" in frame
    assert "nut_tangential_accel" not in frame and "axial_load" not in frame  # not fitted
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--out", "x.csv"], "unsupported extension"),
        (["--out", "x.parquet", "--clearance=-1e-6"], "health.clearance_screw"),
        (["--out", "x.parquet", "--profile", "zigzag"], "--profile"),
        (["--out", "x.parquet", "--max-step", "1e-4"], "stable limit"),
        (["--out", "x.parquet", "--max-step", "fast"], "neither a step in seconds nor 'auto'"),
        (["--out", "no/such/dir/x.parquet", "--duration", "0.001"], "does not exist"),
    ],
)
def test_simulate_bad_input(tmp_path, capsys, monkeypatch, extra, needle):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "simulate", *extra)
    assert code == 2
    assert err.startswith("error: ") and needle in err and len(err.strip().splitlines()) == 1


def test_instrumentation_list_and_show(capsys, tmp_path):
    code, out, _ = run(capsys, "instrumentation", "list")
    assert code == 0
    assert [line.split()[0] for line in out.strip().splitlines()] == [
        "flight-ema",
        "ideal",
        "lab-rig",
        "minimal",
    ]
    code, out, _ = run(capsys, "instrumentation", "list", "--json")
    profiles = {p["name"]: p for p in json.loads(out)}
    assert profiles["minimal"]["channels"] == ["screw_angle", "screw_speed", "drive_torque"]
    code, out, _ = run(capsys, "instrumentation", "show", "flight-ema", "--json")
    info = json.loads(out)
    assert set(info["sensors"]) == {
        "screw_angle",
        "screw_speed",
        "nut_position",
        "nut_axial_accel",
        "drive_torque",
        "housing_temperature",
    }
    code, out, _ = run(capsys, "instrumentation", "show", "lab-rig")
    assert code == 0 and "noise_density" in out and "m/s^2/sqrt(Hz)" in out
    path = tmp_path / "p.toml"
    path.write_text('profile = "minimal"\n[drive_torque]\nnoise = 0.01\n')
    code, out, _ = run(capsys, "instrumentation", "show", str(path), "--json")
    assert json.loads(out)["name"] == "minimal"


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["instrumentation", "show", "flight-emma"], "lab-rig"),
        (["simulate", "--out", "x.parquet", "--accel-noise", "0.05"], "removed"),
        (["simulate", "--out", "x.parquet", "--sample-rate", "7"], "sample_rate"),
    ],
)
def test_instrumentation_errors_are_one_line(capsys, argv, needle):
    code, _, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ")
    assert needle in lines[0]


def test_unknown_profile_through_the_console_script(tmp_path):
    # The real entry point: exit 2, one line naming every built-in profile, no traceback.
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "prsm_health.apps.cli",
            "simulate",
            "--instrumentation",
            "flight-emma",
            "--out",
            str(tmp_path / "x.parquet"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: instrumentation")
    assert all(name in lines[0] for name in ("flight-ema", "ideal", "lab-rig", "minimal"))


def test_kinematics_recirculating_and_friction_json(capsys):
    code, out, _ = run(
        capsys,
        "kinematics",
        "--design",
        "paper03",
        "--speed",
        str(40 * 3.141592653589793),
        "--json",
    )
    assert code == 0
    data = json.loads(out)
    assert data["variant"] == "recirculating"
    assert data["frequencies"]["gear_mesh"] is None
    assert data["nut_speed"] == pytest.approx(20.00e-3, rel=1e-9)  # paper 03: v_n = 20 mm/s
    code, out, _ = run(
        capsys, "friction", "--load", "1000", "--accel-time", "0.02", "--speed", "1", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert data["steady_friction_torque"] == pytest.approx(0.115, abs=1e-3)
    assert data["min_efficiency"] <= data["overall_efficiency"] <= data["steady_efficiency"] <= 1


def test_simulate_mcap_and_replay(tmp_path, capsys):
    out = tmp_path / "run.mcap"
    code, _, _ = run(capsys, "simulate", "--duration", "0.2", "--out", str(out), "--json")
    assert code == 0
    from mcap.reader import make_reader

    with open(out, "rb") as f:  # the independent reader sees both contract topics
        topics = {c.topic for c in make_reader(f).get_summary().channels.values()}
    assert {"/prsm/nut_accel", "/prsm/drive"} <= topics
    code, stdout, _ = run(capsys, "replay", str(out), "--window", "0.05", "--json")
    assert code == 0
    windows = json.loads(stdout)["windows"]
    assert len(windows) == 4 and windows[1]["start"] == pytest.approx(0.05)
    truncated = tmp_path / "cut.mcap"
    truncated.write_bytes(out.read_bytes()[:200])
    code, _, err = run(capsys, "replay", str(truncated))
    assert code == 2 and err.startswith("error: ") and len(err.strip().splitlines()) == 1


def test_generate_warns_when_the_dataset_cannot_train(tmp_path, capsys):
    recipe = tmp_path / "small.toml"
    recipe.write_text(
        'name = "small"\ndesign = "paper01"\nduration = 0.02\nsample_rate = 20000\nseed = 1\n'
        'instrumentation = "ideal"\n'
        "[sweep]\nclearance = [5e-6, 40e-6]\nspeed = [80.0]\nload = [100.0]\n"
    )
    assert main(["generate", str(recipe), "--out", str(tmp_path / "d"), "--workers", "1"]) == 0
    err = capsys.readouterr().err
    assert "warning: this dataset cannot train a model as is" in err and "add runs" in err
    assert main(["train", str(tmp_path / "d"), "--out", str(tmp_path / "m.skops")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and len(err.splitlines()) == 1
