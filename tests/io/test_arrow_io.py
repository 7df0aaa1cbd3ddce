"""Recordings in memory: the Arrow IPC stream reader and writer, what a stream declares
(read from its headers, never decompressed), and Parquet and MCAP bytes."""

import warnings

import numpy as np
import pyarrow as pa
import pytest

from prsm_health.core.errors import PRSMHealthError, TruncatedRecordingWarning
from prsm_health.core.run import Run
from prsm_health.io import read_recording_bytes
from prsm_health.io.arrow import arrow_stream_sizes, read_run_arrow, write_run_arrow
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet


@pytest.fixture(scope="module")
def run() -> Run:
    n, rate = 3000, 20000.0
    rng = np.random.default_rng(4)
    channels = {"nut_axial_accel": rng.normal(size=n), "screw_speed": np.full(n, 100.0)}
    truth = {"carrier_speed": rng.normal(size=n)}
    labels = {"design": "paper01", "clearance": 2e-5}
    return Run(np.arange(n) / rate, channels, rate, labels, {"seed": 3}, truth=truth)


def _same(a: Run, b: Run) -> None:
    assert a.sample_rate == b.sample_rate and a.labels == b.labels and a.scenario == b.scenario
    assert np.array_equal(a.time, b.time)
    assert a.channels.keys() == b.channels.keys() and a.truth.keys() == b.truth.keys()
    for name in a.channels:
        assert np.array_equal(a.channels[name], b.channels[name])
    for name in a.truth:
        assert np.array_equal(a.truth[name], b.truth[name])


@pytest.mark.parametrize("compression", [None, "zstd", "lz4"])
def test_arrow_round_trip_and_declared_sizes(run, compression, tmp_path):
    data = write_run_arrow(run, compression=compression)
    _same(read_run_arrow(data), run)
    sizes = arrow_stream_sizes(data)
    assert (sizes.rows, sizes.columns) == (len(run), 4)  # time, 2 channels, 1 truth column
    assert sizes.decoded_bytes == 4 * 8 * len(run)  # float64 columns, no validity bitmaps
    path = write_run_arrow(run, tmp_path / "run.arrows", compression=compression)
    _same(read_run_arrow(path.read_bytes()), run)
    _same(read_recording_bytes(data, "arrow"), run)


def test_compressed_bomb_sizes_come_from_the_headers():
    rows = 4_000_000  # 32 MB of zeros per column
    zeros = pa.array(np.zeros(rows))
    table = pa.table({"time": zeros, "nut_axial_accel": zeros})
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(
        sink, table.schema, options=pa.ipc.IpcWriteOptions(compression="zstd")
    ) as writer:
        writer.write_table(table)
    data = sink.getvalue().to_pybytes()
    assert len(data) < 100_000
    sizes = arrow_stream_sizes(data)
    assert (sizes.rows, sizes.decoded_bytes, sizes.columns) == (rows, 2 * 8 * rows, 2)


@pytest.mark.parametrize(
    "cut, message",
    [
        (lambda d: b"", "recording: not an Arrow IPC stream (no schema message)"),
        (lambda d: b"\x00" * 7, "recording: not an Arrow IPC stream (no schema message)"),
        (lambda d: d[: len(d) // 2], "recording: not a readable Arrow IPC stream (Expected"),
        (lambda d: d[:-9], "recording: not a readable Arrow IPC stream (Expected"),
        (lambda d: b"PAR1" + d[4:], "recording: not a readable Arrow IPC stream (Expected"),
    ],
)
def test_damaged_arrow_streams_raise_one_message(run, cut, message):
    data = cut(write_run_arrow(run, compression="zstd"))
    with pytest.raises(PRSMHealthError) as sizes_error:
        arrow_stream_sizes(data)
    assert str(sizes_error.value).startswith(message)
    with pytest.raises(PRSMHealthError, match="^recording: not a"):
        read_run_arrow(data)


def test_dictionary_columns_are_refused():
    table = pa.table(
        {"time": [0.0, 1.0], "nut_axial_accel": pa.array(["a", "b"]).dictionary_encode()}
    )
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    with pytest.raises(PRSMHealthError, match="dictionary-encoded Arrow columns"):
        arrow_stream_sizes(sink.getvalue().to_pybytes(), "body")


def test_arrow_stream_needs_time_and_a_channel(run):
    table = pa.table({"nut_axial_accel": run.channels["nut_axial_accel"]})
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    with pytest.raises(PRSMHealthError, match="^body: no 'time' column$"):
        read_run_arrow(sink.getvalue().to_pybytes(), "body")


def test_parquet_and_mcap_bytes(run, tmp_path):
    measured = run.without_truth()
    write_run_parquet(run, tmp_path / "run.parquet")
    _same(read_recording_bytes((tmp_path / "run.parquet").read_bytes(), "parquet"), run)
    write_mcap(measured, tmp_path / "run.mcap", chunk_size=20_000)  # bytes: several chunks
    data = (tmp_path / "run.mcap").read_bytes()
    from_mcap = read_recording_bytes(data, "mcap", "upload")
    assert np.array_equal(from_mcap.channels["nut_axial_accel"], run.channels["nut_axial_accel"])
    # messages and warnings name the recording, never the temporary file
    with pytest.raises(PRSMHealthError, match="^upload: not an MCAP file"):
        read_recording_bytes(b"not mcap at all", "mcap", "upload")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cut = read_recording_bytes(data[: int(len(data) * 0.7)], "mcap", "upload")
    assert 0 < len(cut) < len(run)
    notes = [str(w.message) for w in caught if w.category is TruncatedRecordingWarning]
    assert len(notes) == 1 and notes[0].startswith("upload: the file ends at byte")
    with pytest.raises(PRSMHealthError, match="unsupported format 'xlsx'"):
        read_recording_bytes(data, "xlsx")
    with pytest.raises(PRSMHealthError, match="^upload: not a readable CSV file"):
        read_recording_bytes(data, "csv", "upload")  # MCAP bytes are no CSV
