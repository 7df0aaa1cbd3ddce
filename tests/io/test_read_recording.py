"""The one recording reader: formats, column maps, derived channels, warnings, cell errors."""

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design_files import design_fingerprint
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.io import (
    ColumnMap,
    load_column_map,
    read_recording,
    read_recording_bytes,
    read_with_warnings,
)
from prsm_health.io.column_map import column_map_from_text
from prsm_health.io.derived import derive_channels
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet

RATE = 1000.0
N = 600
MAP = """
design = "paper01"
torque_constant = 0.05  # N·m/A
[columns]
time = "t_ms"
screw_angle = "motor_deg"
nut_axial_accel = "acc_g"
motor_current = "i_mA"
[units]
t_ms = "ms"
motor_deg = "deg"
acc_g = "g"
i_mA = "mA"
"""


def _rig_frame() -> pd.DataFrame:
    """A made-up rig log: ms time from a wall clock, angle in degrees, acceleration in g."""
    t = np.arange(N) / RATE
    angle = 2 * np.pi * 5.0 * t + 0.3 * np.sin(2 * np.pi * 7.0 * t)
    rng = np.random.default_rng(0)
    return pd.DataFrame(
        {
            "t_ms": 1e3 * (t + 1234.5),
            "motor_deg": np.degrees(angle),
            "acc_g": rng.standard_normal(N),
            "i_mA": 1e3 * (1.0 + 0.1 * np.sin(2 * np.pi * 3.0 * t)),
            "comment": ["x"] * N,
        }
    )


@pytest.fixture
def rig(tmp_path):
    frame = _rig_frame()
    frame.to_csv(tmp_path / "rig.csv", index=False)
    frame.to_parquet(tmp_path / "rig.parquet")
    (tmp_path / "map.toml").write_text(MAP)
    return tmp_path, frame


def test_map_converts_to_si_derives_speed_and_reads_every_table_alike(rig):
    root, frame = rig
    run = read_recording(root / "rig.csv", column_map=root / "map.toml")
    # ms → s from 0, deg → rad, g → m/s², mA × k_t → N·m (exact up to the CSV's text)
    assert run.time[0] == 0.0
    assert np.allclose(run.time, (frame["t_ms"] - frame["t_ms"][0]) * 1e-3, rtol=0, atol=1e-9)
    assert run.sample_rate == pytest.approx(RATE, rel=1e-6)
    assert np.allclose(run.channels["screw_angle"], np.radians(frame["motor_deg"]), rtol=1e-12)
    assert np.allclose(run.channels["nut_axial_accel"], 9.80665 * frame["acc_g"], rtol=1e-12)
    assert np.allclose(run.channels["drive_torque"], 0.05e-3 * frame["i_mA"], rtol=1e-12)
    assert "motor_current" not in run.channels
    # screw speed derived from the angle (the drive's estimate): 5 rev/s + the wobble
    assert np.allclose(
        run.channels["screw_speed"], np.gradient(run.channels["screw_angle"], run.time)
    )
    assert np.median(run.channels["screw_speed"]) == pytest.approx(2 * np.pi * 5.0, rel=0.05)
    assert run.operating == OperatingPoint(
        design="paper01", design_fingerprint=design_fingerprint("paper01")
    )
    assert run.labels == {}  # a recording: no ground truth
    assert run.scenario == {"design": "paper01"}
    # the same table as Parquet, and as bytes, read the same through the same map
    spec = load_column_map(root / "map.toml")
    as_parquet = read_recording(root / "rig.parquet", column_map=spec)
    from_bytes = read_recording_bytes(
        (root / "rig.csv").read_bytes(), "csv", "upload.csv", column_map=spec
    )
    for other in (as_parquet, from_bytes):
        assert set(other.channels) == set(run.channels)
        for name, values in run.channels.items():
            assert np.allclose(other.channels[name], values, rtol=1e-12), name


def test_contract_csv_without_map_derives_screw_speed(tmp_path):
    # What `prsm-health diagnose FILE.csv` reads: contract names, no screw_speed column
    t = np.arange(N) / RATE
    angle = 2 * np.pi * 3.0 * t
    pd.DataFrame({"time": t, "screw_angle": angle, "nut_axial_accel": np.sin(t)}).to_csv(
        tmp_path / "run.csv", index=False
    )
    recording = read_with_warnings(tmp_path / "run.csv")
    assert recording.derived == ("screw_speed",)
    assert np.allclose(recording.run.channels["screw_speed"], 2 * np.pi * 3.0, rtol=1e-6)
    assert recording.run.time[0] == 0.0 and recording.warnings == ()
    # a recording that has the speed keeps its own
    run = Run(t, {"screw_angle": angle, "screw_speed": np.zeros(N)}, RATE)
    same, derived = derive_channels(run)
    assert same is run and derived == ()
    # MCAP and Parquet recordings get it from the same function
    write_mcap(Run(t, {"screw_angle": angle}, RATE), tmp_path / "a.mcap")
    write_run_parquet(Run(t, {"screw_angle": angle}, RATE), tmp_path / "a.parquet")
    for name in ("a.mcap", "a.parquet"):
        back = read_recording(tmp_path / name)
        assert np.allclose(back.channels["screw_speed"], 2 * np.pi * 3.0, rtol=1e-6), name


@pytest.mark.parametrize("mapped", [False, True])
@pytest.mark.parametrize(
    "cell, text",
    [("", "is empty or NaN"), ("abc", "'abc' is not a finite number"), ("inf", "'inf'")],
)
def test_bad_cell_names_file_column_and_row(rig, mapped, cell, text):
    root, frame = rig
    if mapped:
        column, spec = "acc_g", load_column_map(root / "map.toml")
    else:
        frame = frame.rename(columns={"acc_g": "nut_axial_accel"}).assign(time=np.arange(N) / RATE)
        column, spec = "nut_axial_accel", None
    frame = frame.astype({column: object})
    frame.loc[11, column] = cell  # data row 12 (line 13 of the file)
    frame.to_csv(root / "bad.csv", index=False)
    with pytest.raises(PRSMHealthError) as info:
        read_recording(root / "bad.csv", column_map=spec)
    message = str(info.value)
    assert message.startswith(f"{root / 'bad.csv'}: column {column!r}, data row 12: "), message
    assert text in message and "\n" not in message
    # an upload is named as its client named it, never by a server path
    with pytest.raises(PRSMHealthError, match=r"^upload\.csv: column .*data row 12"):
        read_recording_bytes((root / "bad.csv").read_bytes(), "csv", "upload.csv", column_map=spec)


def test_map_errors_name_the_file_and_the_column(rig):
    root, frame = rig
    spec = load_column_map(root / "map.toml")
    frame.drop(columns=["acc_g"]).to_csv(root / "short.csv", index=False)
    with pytest.raises(PRSMHealthError, match=r"short\.csv: no column\(s\) 'acc_g'"):
        read_recording(root / "short.csv", column_map=spec)
    with pytest.raises(PRSMHealthError, match=r"^map\.toml: unit 'furlong' of column 'acc_g'"):
        column_map_from_text(MAP.replace('acc_g = "g"', 'acc_g = "furlong"'), "map.toml")
    with pytest.raises(PRSMHealthError, match="^m: not valid TOML"):
        column_map_from_text(b"[columns", "m")
    with pytest.raises(PRSMHealthError, match="torque_constant"):
        column_map_from_text(MAP.replace("torque_constant = 0.05", ""))
    # an MCAP recording carries contract channels in SI: a map does not apply to it
    t = np.arange(N) / RATE
    write_mcap(Run(t, {"nut_position": t * 1e-3}, RATE), root / "m.mcap")
    back = read_recording(root / "m.mcap", column_map=spec)
    assert np.allclose(back.channels["nut_position"], t * 1e-3)


def test_reader_warnings_are_collected_once_and_name_the_recording(tmp_path):
    t = np.arange(400) * 0.05  # 20 Hz: time written in ms by mistake?
    pd.DataFrame({"time": t, "nut_axial_accel": np.sin(t)}).to_csv(tmp_path / "r.csv", index=False)
    recording = read_with_warnings(tmp_path / "r.csv", name="client.csv")
    assert len(recording.warnings) == 1
    assert recording.warnings[0].startswith("client.csv: the time axis gives 20 Hz")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_recording(tmp_path / "r.csv")
    assert [str(w.message) for w in caught] == [
        recording.warnings[0].replace("client.csv", str(tmp_path / "r.csv"))
    ]
    with pytest.raises(PRSMHealthError, match="^client.csv: no such file"):
        read_with_warnings(tmp_path / "missing.csv", name="client.csv")
    with pytest.raises(PRSMHealthError, match="unsupported file type '.txt'"):
        (tmp_path / "a.txt").write_text("x")
        read_recording(tmp_path / "a.txt")


def test_column_map_object_and_its_labels():
    spec = column_map_from_text(
        'sample_rate = 50\nlead = 0.004\n[columns]\nnut_position = "p"\n[units]\np = "mm"\n'
    )
    assert isinstance(spec, ColumnMap) and spec.sample_rate == 50.0
    assert spec.operating() == OperatingPoint(lead=0.004)
    frame = pd.DataFrame({"p": np.arange(300.0)})
    from prsm_health.io.column_map import apply_column_map

    run = apply_column_map(frame, spec, "f.csv")
    assert run.sample_rate == 50.0 and run.time[-1] == pytest.approx(299 / 50)
    assert np.allclose(run.channels["nut_position"], np.arange(300.0) * 1e-3)
    assert math.isclose(run.operating.lead, 0.004)
