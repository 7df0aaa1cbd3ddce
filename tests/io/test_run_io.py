"""Run → Parquet → Run, read back by independent readers; damaged files give clear errors."""

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.channels import CHANNEL_NAMES, UNITS
from prsm_health.errors import PRSMHealthError
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
    assert back.labels == json.loads(json.dumps(run.labels))


def test_independent_readers(tmp_path, run):
    path = write_run_parquet(run, tmp_path / "run.parquet")
    frame = pd.read_parquet(path)
    assert list(frame.columns) == ["time", *CHANNEL_NAMES]
    meta = pq.read_schema(path).metadata
    assert json.loads(meta[b"prsm_health.units"])["nut_axial_accel"] == UNITS["nut_axial_accel"]
    assert float(meta[b"prsm_health.sample_rate"]) == run.sample_rate


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
