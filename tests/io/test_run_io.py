"""Run → Parquet (and CSV) → Run, read back by independent readers; truth kept apart from the
channels; damaged files give clear errors."""

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.core.channels import CHANNEL_NAMES, STANDARD_TRUTH_NAMES, UNITS, truth_column
from prsm_health.core.errors import PRSMHealthError
from prsm_health.io.csv import read_csv
from prsm_health.io.parquet import read_run_parquet, write_run_parquet


@pytest.fixture(scope="module")
def run():
    return simulate("paper01", HealthState(), OperatingProfile(duration=0.02), "ideal", 4)


def test_round_trip_exact(tmp_path, run):
    path = write_run_parquet(run, tmp_path / "run.parquet")
    back = read_run_parquet(path)
    assert back.sample_rate == run.sample_rate
    assert np.array_equal(back.time, run.time)
    for name in CHANNEL_NAMES:
        assert np.array_equal(back[name], run[name]), name
    assert list(back.truth) == list(STANDARD_TRUTH_NAMES)
    for name in STANDARD_TRUTH_NAMES:
        assert np.array_equal(back.truth[name], run.truth[name]), name
    assert back.labels == json.loads(json.dumps(run.labels))


def test_independent_readers(tmp_path, run):
    path = write_run_parquet(run, tmp_path / "run.parquet")
    frame = pd.read_parquet(path)
    truth_columns = [truth_column(n) for n in STANDARD_TRUTH_NAMES]
    assert list(frame.columns) == ["time", *CHANNEL_NAMES, *truth_columns]
    table = pq.read_table(path)
    assert np.array_equal(table.column("truth_friction_torque"), run.truth["friction_torque"])
    assert np.array_equal(table.column("truth_motor_angle"), run.truth["motor_angle"])
    meta = pq.read_schema(path).metadata
    units = json.loads(meta[b"prsm_health.units"])
    assert units["nut_axial_accel"] == UNITS["nut_axial_accel"]
    assert units["truth_friction_torque"] == "N*m" and units["truth_payload_position"] == "m"
    assert set(units) == set(frame.columns)
    assert float(meta[b"prsm_health.sample_rate"]) == run.sample_rate


def test_units_where_every_reader_sees_them(tmp_path, run):
    path = write_run_parquet(run, tmp_path / "run.parquet")
    contract = {name: UNITS[name] for name in pd.read_parquet(path).columns}
    # pandas: DataFrame.attrs, restored by read_parquet
    attrs = pd.read_parquet(path).attrs
    assert attrs["units"] == contract and attrs["sample_rate"] == run.sample_rate
    # Arrow: the unit of each field, beside the contract's schema-level JSON
    schema = pq.read_schema(path)
    assert schema.field("nut_axial_accel").metadata[b"unit"] == b"m/s^2"
    assert {f.name: f.metadata[b"unit"].decode() for f in schema} == contract
    assert json.loads(schema.metadata[b"prsm_health.units"]) == contract
    # polars and duckdb read the columns and the file's key-value metadata
    polars = pytest.importorskip("polars")
    assert polars.read_parquet(path).columns == list(contract)
    kv = polars.read_parquet_metadata(path)
    assert json.loads(kv["prsm_health.units"]) == contract
    duckdb = pytest.importorskip("duckdb")
    rows = duckdb.sql(
        f"select value from parquet_kv_metadata('{path}') where key = 'prsm_health.units'"
    ).fetchall()
    assert json.loads(rows[0][0]) == contract
    count = duckdb.sql(f"select count(*) from read_parquet('{path}')").fetchall()[0][0]
    assert count == len(run)


def test_simulated_truth_is_the_physics_without_sensor_errors(run):
    # The ideal profile adds no sensor error, so each reading equals the true value it reads:
    # the motor side for angle and torque. With the default drive train the linkage force
    # (axial_load) differs from the applied force by the payload's vibration, and the screw
    # sits pushed back on its thrust bearing.
    assert list(run.truth) == list(STANDARD_TRUTH_NAMES)
    assert "carrier_speed" not in run.channels and "friction_torque" not in run.channels
    # the resolver is on the motor: the drive reports the screw angle as its reading / N
    ratio = run.scenario["drive_train"]["gear_ratio"]
    assert np.allclose(run.truth["motor_angle"] / ratio, run.channels["screw_angle"], rtol=1e-12)
    # equal to round-off: the truth record is decimated all columns at once, a reading alone
    # (the same filter, its sum in another order)
    for truth, channel in (("motor_torque", "drive_torque"), ("axial_load", "axial_load")):
        scale = np.max(np.abs(run.truth[truth]))
        assert np.max(np.abs(run.truth[truth] - run.channels[channel])) < 1e-12 * scale
    assert not np.array_equal(run.truth["motor_angle"], run.truth["screw_angle"])  # coupling
    assert np.all(run.truth["screw_axial_position"] < 0)
    assert all(len(v) == len(run) for v in run.truth.values())


def test_files_without_truth_and_truth_columns_in_csv(tmp_path, run):
    plain = run.without_truth()
    path = write_run_parquet(plain, tmp_path / "plain.parquet")
    assert pq.read_schema(path).names == ["time", *CHANNEL_NAMES]
    back = read_run_parquet(path)
    assert back.truth == {} and list(back.channels) == list(CHANNEL_NAMES)
    # A CSV export of a simulated run: truth_* columns go to the truth, never to the channels;
    # a truth column alone is no recording.
    run.to_frame().to_csv(tmp_path / "run.csv", index=False)
    csv = read_csv(tmp_path / "run.csv")
    assert list(csv.channels) == list(CHANNEL_NAMES) and list(csv.truth) == list(
        STANDARD_TRUTH_NAMES
    )
    assert np.allclose(csv.truth["carrier_speed"], run.truth["carrier_speed"], rtol=1e-15)
    only_truth = run.to_frame()[["time", "truth_nut_axial_accel", "truth_friction_torque"]]
    only_truth.to_csv(tmp_path / "truth.csv", index=False)
    with pytest.raises(PRSMHealthError, match="truth_\\* columns are simulator truth"):
        read_csv(tmp_path / "truth.csv")


def test_damaged_files(tmp_path):
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1 not really")
    with pytest.raises(PRSMHealthError, match="not a readable Parquet"):
        read_run_parquet(bad)
    with pytest.raises(PRSMHealthError, match="no such file"):
        read_run_parquet(tmp_path / "missing.parquet")
    pd.DataFrame({"x": [1.0, 2.0]}).to_parquet(tmp_path / "other.parquet")
    with pytest.raises(PRSMHealthError, match="no 'time' column"):
        read_run_parquet(tmp_path / "other.parquet")


def test_unknown_channel(run):
    with pytest.raises(PRSMHealthError, match="unknown channel"):
        run["vibration"]


def test_the_operating_point_travels_in_every_format(tmp_path, run):
    from prsm_health.io.arrow import read_run_arrow, write_run_arrow
    from prsm_health.io.mcap import read_mcap, write_mcap

    assert run.operating.design == "paper01" and run.operating.screw_speed == 100.0
    parquet = read_run_parquet(write_run_parquet(run, tmp_path / "run.parquet"))
    arrow = read_run_arrow(write_run_arrow(run))
    mcap = read_mcap(write_mcap(run, tmp_path / "run.mcap"))
    for back in (parquet, arrow, mcap):
        assert back.operating == run.operating
    meta = pq.read_schema(tmp_path / "run.parquet").metadata
    assert json.loads(meta[b"prsm_health.operating"]) == run.operating.as_dict()


def test_a_file_without_the_operating_record_reads_it_from_its_labels(tmp_path, run):
    # files written before the record carried the same keys in their labels
    path = write_run_parquet(run, tmp_path / "run.parquet")
    table = pq.read_table(path)
    meta = {k: v for k, v in table.schema.metadata.items() if k != b"prsm_health.operating"}
    pq.write_table(table.replace_schema_metadata(meta), tmp_path / "old.parquet")
    assert read_run_parquet(tmp_path / "old.parquet").operating == run.operating
