"""A short simulated health check: the phase of every sample, its energy book, and the phase
column, topic and boundaries read back from Parquet (pyarrow) and MCAP (the mcap package)."""

import json

import numpy as np
import pytest

from prsm_health.actuator.health_check import BUILT_IN, CheckPhase, HealthCheck
from prsm_health.actuator.states import OperatingProfile
from prsm_health.core.channels import CHECK_METADATA, CHECK_PHASE, TOPIC_CHECK_PHASE
from prsm_health.io.mcap import read_mcap, write_mcap
from prsm_health.io.parquet import read_run_parquet, write_run_parquet
from prsm_health.physics.load_rating import load_ratings
from prsm_health.simulation.scenario import Scenario


def short_check() -> HealthCheck:
    """The built-in check with its phases shrunk: 0.2 s simulated in all (same kinds of phase,
    same loads as shares of C_a; speeds and reversal period shortened with them)."""
    phases = []
    for p in BUILT_IN["health-check"].phases:
        phases.append(
            CheckPhase(
                p.name,
                p.motion,
                speed=p.speed,
                load=p.load,
                duration=0.03,
                ramp_time=0.008,
                reversal_shape=p.reversal_shape,
                reversal_period=0.03,
            )
        )
    return HealthCheck("short-check", phases)


@pytest.fixture(scope="module")
def run():
    scenario = Scenario(design="paper01")
    ratings = load_ratings(scenario.design)
    check = short_check().resolved({"C_a": ratings.dynamic, "C_0a": ratings.static})
    assert check.duration <= 0.3
    return Scenario(design="paper01", profile=OperatingProfile(check=check)).simulate()


def test_every_sample_has_its_phase(run):
    check = run.scenario["profile"]["check"]
    assert run.check.name == check["name"] == "short-check"
    phase = run.check_phase
    assert phase.shape == run.time.shape and phase.dtype == np.int16
    for b in run.check.phases:
        inside = (run.time >= b.start) & (run.time < b.end)
        assert np.all(phase[inside] == b.index)
        # 0.03 s at the sample rate, ±1 sample at the edges
        assert abs(inside.sum() - 0.03 * run.sample_rate) <= 1
    assert np.all(phase[run.time < run.check.phases[0].start] == -1)
    parts = run.phases()
    assert list(parts) == [p["name"] for p in check["phases"]]
    # the phase's settled speed is what the drive measured there (prescribed drive: the motor
    # speed is the command; the resolver-derived estimate within 2 % of it)
    stroke = parts["high-speed stroke"]
    assert np.median(stroke["screw_speed"]) == pytest.approx(100.0, rel=0.02)


def test_energy_balance_through_the_check(run):
    # From rest to rest (the check ramps back down): drive = output + dissipated within 1 %,
    # the bound of the constant-speed energy tests (tests/simulation/dynamics/test_dynamics.py);
    # what is left is the vibration energy stored at the end and the RK4 error. The high-load
    # stroke back-drives the motor (its load aids the retraction), so the net drive energy can
    # be small or negative: the balance is read against the energy that went through the
    # actuator, (|drive| + |load|)/2.
    e = run.energy
    through = 0.5 * (abs(e["drive"]) + abs(e["load"]))
    assert through > 0 and e["dissipated"] > 0
    assert (e["drive"] + e["load"] - e["dissipated"]) / through == pytest.approx(0, abs=1e-2)


def test_parquet_column_and_metadata_read_by_pyarrow(run, tmp_path):
    import pyarrow.parquet as pq

    path = write_run_parquet(run, tmp_path / "check.parquet")
    table = pq.read_table(path)
    assert str(table.schema.field(CHECK_PHASE).type) == "int16"
    assert np.array_equal(table.column(CHECK_PHASE).to_numpy(), run.check_phase)
    meta = json.loads(table.schema.metadata[f"prsm_health.{CHECK_METADATA}".encode()])
    assert meta == json.loads(json.dumps(run.check.as_record()))
    # the reader can cut by phase from the file alone
    time = table.column("time").to_numpy()
    for b in meta["phases"]:
        at = time[table.column(CHECK_PHASE).to_numpy() == b["index"]]
        assert b["start"] <= at[0] < b["start"] + 1.5 / run.sample_rate and at[-1] < b["end"]
    back = read_run_parquet(path)
    assert np.array_equal(back.check_phase, run.check_phase) and back.check == run.check


def test_mcap_topic_and_metadata_read_by_mcap(run, tmp_path):
    from mcap.reader import make_reader

    path = write_mcap(run, tmp_path / "check.mcap")
    with open(path, "rb") as f:
        reader = make_reader(f)
        messages = [
            (m.log_time, json.loads(m.data))
            for _, _, m in reader.iter_messages(topics=[TOPIC_CHECK_PHASE])
        ]
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    # one message per change: −1, then each phase and the ramp after it
    assert [m["index"] for _, m in messages] == [-1, 0, -1, 1, -1, 2, -1, 3, -1, 4, -1, 5, -1]
    names = run.check.names()
    for log_time, m in messages:
        assert m["name"] == names.get(m["index"], "")
        k = int(round(log_time * 1e-9 * run.sample_rate))  # the sample it starts at
        assert run.check_phase[k] == m["index"] and (k == 0 or run.check_phase[k - 1] != m["index"])
    record = metadata[CHECK_METADATA]
    assert record["name"] == "short-check"
    assert json.loads(record["phases"]) == run.check.as_record()["phases"]
    back = read_mcap(path)
    assert np.array_equal(back.check_phase, run.check_phase)
