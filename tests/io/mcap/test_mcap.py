"""Run → MCAP → Run checked by mcap's own readers; damaged files; replay; diagnosis output."""

import json
import time
import warnings
import zlib

import numpy as np
import pytest
import zstandard
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Chunk, Footer, MessageIndex, SummaryOffset
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, IndexType, Writer

from prsm_health.core.channels import CHANNEL_NAMES, MEASURED_TOPICS, TRUTH_NAMES, UNITS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.io.mcap import (
    TOPIC_DIAGNOSIS,
    TOPIC_DRIVE,
    TOPIC_FIELDS,
    TOPIC_NUT_ACCEL,
    TOPIC_TRUTH,
    DiagnosisWriter,
    TruncatedRecordingWarning,
    Window,
    _container,
    iter_windows,
    read_mcap,
    window_statistics,
    write_diagnosis_mcap,
    write_mcap,
)
from prsm_health.io.mcap import writer as mcap_writer

FS = 20_000.0

LABELS = {
    "run_id": "r-0001",
    "design": "paper01",
    "fault_class": "healthy",
    "clearance_screw": 1.25e-5,
    "seed": 7,
    "split": "train",
    "spall": True,
    "missing": None,
    "list": [1, 2.5],
    "looks_like_number": "1.5",
    "looks_like_json_string": '"quoted"',
}


def make_run(n=2000, channels=CHANNEL_NAMES, seed=0, truth=False):
    """Known signals on every requested channel, plus values that stress float printing; with
    ``truth``, every truth signal too, each unlike the channel of the same name."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    w = 2 * np.pi * 5.0
    signals = {
        "screw_angle": w * t,
        "screw_speed": w + 0.1 * np.sin(2 * np.pi * 50 * t),
        "nut_position": 1e-3 * t,
        "nut_axial_accel": 3.0 * np.sin(2 * np.pi * 1234.5 * t) + rng.standard_normal(n),
        "nut_tangential_accel": rng.standard_normal(n) * 1e-7,
        "nut_radial_x_accel": rng.standard_normal(n) * 1e12,
        "nut_radial_y_accel": np.cos(2 * np.pi * 700 * t),
        "drive_torque": 0.5 + 0.05 * rng.standard_normal(n),
        "axial_load": np.full(n, 2000.0),
        "housing_temperature": 313.15 + 0.5 * np.sin(2 * np.pi * 0.5 * t),
    }
    x = signals["nut_radial_x_accel"]
    x[:6] = [-0.0, 5e-324, 1e300, 0.1, 1 / 3, 2.0**-1074 * 3]
    true = {name: k + rng.standard_normal(n) for k, name in enumerate(TRUTH_NAMES)}
    true["carrier_speed"] = 0.4 * w + 0.01 * rng.standard_normal(n)
    true["friction_torque"] = np.full(n, 0.1)
    return Run(
        time=t,
        channels={name: signals[name] for name in channels},
        sample_rate=FS,
        labels=dict(LABELS),
        scenario={"design": "paper01", "health": {"clearance_screw": 1.25e-5}, "seed": 7},
        energy={"drive": 1.5, "load": 0.25, "dissipated": 1.0, "friction": 0.25},
        truth=true if truth else {},
    )


def assert_same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert a.shape == b.shape
    assert np.array_equal(a.view(np.int64), b.view(np.int64))


@pytest.fixture(scope="module")
def run():
    return make_run()


@pytest.fixture(scope="module")
def mcap_file(tmp_path_factory, run):
    # Small chunks so the damaged-file tests cut through many of them.
    return write_mcap(run, tmp_path_factory.mktemp("mcap") / "run.mcap", chunk_size=16_384)


# ----------------------------------------------------------------------------- round trip
def test_round_trip_exact(mcap_file, run):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_mcap(mcap_file)
    assert back.sample_rate == run.sample_rate
    assert_same_bits(back.time, run.time)
    assert list(back.channels) == list(CHANNEL_NAMES)
    for name in CHANNEL_NAMES:
        assert_same_bits(back[name], run[name])
    assert back.labels == LABELS
    assert back.scenario == run.scenario
    assert back.energy == run.energy


def test_round_trip_missing_channels(tmp_path):
    present = ("screw_speed", "nut_axial_accel", "nut_radial_y_accel", "drive_torque")
    run = make_run(channels=present)
    path = write_mcap(run, tmp_path / "partial.mcap")
    back = read_mcap(path)
    assert list(back.channels) == [c for c in CHANNEL_NAMES if c in present]
    for name in present:
        assert_same_bits(back[name], run[name])
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    fields = {
        summary.channels[cid].topic: list(json.loads(schema.data)["properties"])
        for cid in summary.channels
        for schema in [summary.schemas[summary.channels[cid].schema_id]]
    }
    assert fields == {
        TOPIC_NUT_ACCEL: ["axial", "radial_y"],
        TOPIC_DRIVE: ["screw_speed", "drive_torque"],
    }


def test_only_one_topic(tmp_path):
    run = make_run(channels=("nut_axial_accel",))
    back = read_mcap(write_mcap(run, tmp_path / "one.mcap"))
    assert list(back.channels) == ["nut_axial_accel"]
    assert_same_bits(back["nut_axial_accel"], run["nut_axial_accel"])


def test_truth_topic_round_trip_read_by_the_mcap_library(tmp_path):
    run = make_run(n=500, truth=True)
    path = write_mcap(run, tmp_path / "truth.mcap", chunk_size=16_384)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_mcap(path)
    assert list(back.channels) == list(CHANNEL_NAMES) and list(back.truth) == list(TRUTH_NAMES)
    for name in CHANNEL_NAMES:  # truth of the same name (screw_angle …) stays out
        assert_same_bits(back.channels[name], run.channels[name])
    for name in TRUTH_NAMES:
        assert_same_bits(back.truth[name], run.truth[name])
    # mcap's own reader: one /prsm/truth message per sample, one field per truth signal.
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        (channel,) = [c for c in summary.channels.values() if c.topic == TOPIC_TRUTH]
        schema = summary.schemas[channel.schema_id]
        body = json.loads(schema.data)
        assert schema.name == "prsm_health.Truth" and schema.encoding == "jsonschema"
        assert list(body["properties"]) == list(TRUTH_NAMES) == body["required"]
        friction = body["properties"]["friction_torque"]["description"]
        assert "[N*m] (truth friction_torque)" in friction
        assert "not a measurement" in body["description"]
        assert summary.statistics.channel_message_counts[channel.id] == len(run)
        messages = [json.loads(m.data) for _, _, m in reader.iter_messages(topics=[TOPIC_TRUTH])]
    assert [m["motor_torque"] for m in messages] == run.truth["motor_torque"].tolist()
    assert [m["screw_angle"] for m in messages] == run.truth["screw_angle"].tolist()
    # Cut: channels and truth end together.
    data = path.read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[: len(data) // 2])
    with pytest.warns(TruncatedRecordingWarning):
        cut = read_mcap(tmp_path / "cut.mcap")
    assert 0 < len(cut) < len(run)
    assert all(len(v) == len(cut) for v in [*cut.channels.values(), *cut.truth.values()])
    assert_same_bits(cut.truth["load_force"], run.truth["load_force"][: len(cut)])


def test_truth_only_when_present_and_with_foreign_writers(tmp_path):
    plain = make_run(n=100, channels=("nut_axial_accel", "drive_torque"))
    with open(write_mcap(plain, tmp_path / "plain.mcap"), "rb") as f:
        topics = {c.topic for c in make_reader(f).get_summary().channels.values()}
    assert topics == {TOPIC_NUT_ACCEL, TOPIC_DRIVE}
    assert read_mcap(tmp_path / "plain.mcap").truth == {}
    # A run with truth but no measured channel is not a recording.
    no_channels = make_run(n=100, channels=(), truth=True)
    with pytest.raises(PRSMHealthError, match="none of the contract channels"):
        write_mcap(no_channels, tmp_path / "x.mcap")
    # mcap's Writer, schemas without property lists, no summary: truth read from the messages.
    run = make_run(n=300, channels=("nut_axial_accel",), truth=True)
    back = read_mcap(write_with_mcap_writer(tmp_path / "other.mcap", run, summary=False))
    assert list(back.channels) == ["nut_axial_accel"] and list(back.truth) == list(TRUTH_NAMES)
    for name in TRUTH_NAMES:
        assert_same_bits(back.truth[name], run.truth[name])


def test_replay_reads_truth_apart_and_only_when_asked(tmp_path):
    run = make_run(n=4000, truth=True)
    path = write_mcap(run, tmp_path / "truth.mcap", chunk_size=16_384)
    windows = list(iter_windows(path, 0.05))
    assert len(windows) == 4
    for k, w in enumerate(windows):
        assert list(w.channels) == list(CHANNEL_NAMES) and list(w.truth) == list(TRUTH_NAMES)
        assert_same_bits(w.truth["carrier_speed"], run.truth["carrier_speed"][1000 * k :][:1000])
        assert_same_bits(w["screw_angle"], run.channels["screw_angle"][1000 * k :][:1000])
    measured = list(iter_windows(path, 0.05, topics=MEASURED_TOPICS))
    assert [w.truth for w in measured] == [{}] * 4
    for a, b in zip(windows, measured):
        assert all(np.array_equal(a[c], b[c]) for c in CHANNEL_NAMES)


def test_non_finite_samples_are_null(tmp_path):
    run = make_run(n=50)
    run.channels["drive_torque"][[3, 4, 5]] = [np.nan, np.inf, -np.inf]
    path = write_mcap(run, tmp_path / "nan.mcap")
    with open(path, "rb") as f:
        drive = [
            json.loads(m.data) for _, _, m in make_reader(f).iter_messages(topics=[TOPIC_DRIVE])
        ]
    assert [d["drive_torque"] for d in drive[3:6]] == [None, None, None]  # strict JSON
    back = read_mcap(path)
    assert np.isnan(back["drive_torque"][3:6]).all()  # JSON has no inf: documented
    keep = np.ones(50, bool)
    keep[3:6] = False
    assert_same_bits(back["drive_torque"][keep], run["drive_torque"][keep])


def test_start_time_and_irregular_time(tmp_path):
    run = make_run(n=100)
    start = 1_700_000_000_123_456_789
    path = write_mcap(run, tmp_path / "clock.mcap", start_time_ns=start)
    with open(path, "rb") as f:
        logs = [m.log_time for _, _, m in make_reader(f).iter_messages(topics=[TOPIC_DRIVE])]
    assert logs[0] == start and logs[1] - logs[0] == 50_000
    assert_same_bits(read_mcap(path).time, run.time)

    jitter = run.time + np.random.default_rng(1).uniform(0, 1e-6, 100)
    irregular = Run(np.sort(jitter), run.channels, FS, run.labels)
    back = read_mcap(write_mcap(irregular, tmp_path / "jitter.mcap"))
    # Log times are integer ns: the times come back to half a nanosecond.
    assert np.max(np.abs(back.time - irregular.time)) <= 0.5e-9 + 1e-15


def test_write_errors(tmp_path, run):
    with pytest.raises(PRSMHealthError, match="none of the contract channels"):
        write_mcap(Run(run.time, {"vibration": run.time}, FS), tmp_path / "x.mcap")
    bad = Run(run.time, {"nut_axial_accel": run.time[:-1]}, FS)
    with pytest.raises(PRSMHealthError, match="nut_axial_accel"):
        write_mcap(bad, tmp_path / "x.mcap")
    with pytest.raises(PRSMHealthError, match="no such directory"):
        write_mcap(run, tmp_path / "missing" / "x.mcap")
    with pytest.raises(PRSMHealthError, match="non-decreasing"):
        write_mcap(Run(run.time[::-1], run.channels, FS), tmp_path / "x.mcap")
    with pytest.raises(PRSMHealthError, match="start_time_ns"):
        write_mcap(run, tmp_path / "x.mcap", start_time_ns=-1)
    with pytest.raises(PRSMHealthError, match="sample_rate"):
        write_mcap(Run(run.time, run.channels, 0.0), tmp_path / "x.mcap")
    with pytest.raises(PRSMHealthError, match="not JSON-serialisable"):
        write_mcap(Run(run.time, run.channels, FS, {"x": object()}), tmp_path / "x.mcap")
    assert list(tmp_path.iterdir()) == []


def test_blockwise_write_gives_the_same_file(tmp_path, run, monkeypatch):
    whole = write_mcap(run, tmp_path / "whole.mcap", chunk_size=10_000).read_bytes()
    monkeypatch.setattr(mcap_writer, "_WRITE_BLOCK", 333)  # long runs are formatted in blocks
    blocks = write_mcap(run, tmp_path / "blocks.mcap", chunk_size=10_000).read_bytes()
    assert blocks == whole


def test_write_is_deterministic(tmp_path, run):
    a = write_mcap(run, tmp_path / "a.mcap").read_bytes()
    b = write_mcap(run, tmp_path / "b.mcap").read_bytes()
    assert a == b  # no wall-clock times inside: datasets can be hashed


def test_write_is_atomic(tmp_path, run, monkeypatch):
    path = tmp_path / "run.mcap"
    path.write_bytes(b"previous content")

    def interrupted(self):
        raise KeyboardInterrupt

    monkeypatch.setattr(_container._FileWriter, "finish", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_mcap(run, path)
    assert path.read_bytes() == b"previous content"
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]  # no temporary left behind


# ----------------------------------------------------------------------------- contract
def test_contract_with_mcap_reader(mcap_file, run):
    n = len(run)
    with open(mcap_file, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        topics = {c.topic: c for c in summary.channels.values()}
        assert set(topics) == {TOPIC_NUT_ACCEL, TOPIC_DRIVE}
        for topic, channel in topics.items():
            assert channel.message_encoding == "json"
            schema = summary.schemas[channel.schema_id]
            assert schema.encoding == "jsonschema"
            body = json.loads(schema.data)
            assert body["$schema"] == "http://json-schema.org/draft-07/schema#"
            assert body["type"] == "object"
            assert list(body["properties"]) == [name for name, _ in TOPIC_FIELDS[topic]]
            for name, channel_name in TOPIC_FIELDS[topic]:
                prop = body["properties"][name]
                assert prop["type"] == "number"
                assert f"[{UNITS[channel_name]}]" in prop["description"]
            assert summary.statistics.channel_message_counts[channel.id] == n
        assert summary.statistics.message_count == 2 * n
        assert summary.chunk_indexes and all(
            ci.compression == "zstd" and set(ci.message_index_offsets) == {1, 2}
            for ci in summary.chunk_indexes
        )
        assert summary.metadata_indexes and summary.attachment_indexes

        expected_ns = np.round(run.time * 1e9).astype(np.int64)
        seen = {TOPIC_NUT_ACCEL: 0, TOPIC_DRIVE: 0}
        last = -1
        for _, channel, message in reader.iter_messages(log_time_order=True):
            i = seen[channel.topic]
            seen[channel.topic] += 1
            assert message.log_time == message.publish_time == expected_ns[i]
            assert message.log_time >= last
            last = message.log_time
            decoded = json.loads(message.data)
            expected = {
                name: float(run.channels[ch][i]) for name, ch in TOPIC_FIELDS[channel.topic]
            }
            assert decoded == expected
            # Byte for byte what json.dumps writes (compact), i.e. repr of every float.
            assert message.data == json.dumps(expected, separators=(",", ":")).encode()
        assert seen == {TOPIC_NUT_ACCEL: n, TOPIC_DRIVE: n}

        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        assert metadata["labels"]["design"] == "paper01"  # plain strings stay readable
        assert metadata["labels"]["seed"] == "7"
        assert metadata["labels"]["looks_like_number"] == '"1.5"'
        assert float(metadata["prsm_health"]["sample_rate"]) == FS
        (attachment,) = list(reader.iter_attachments())
        assert attachment.name == "scenario.json"
        assert attachment.media_type == "application/json"
        assert json.loads(attachment.data) == run.scenario

    # A linear read validating every CRC (data section, chunks), and the message indexes.
    with open(mcap_file, "rb") as f:
        records = list(StreamReader(f, validate_crcs=True, emit_chunks=True).records)
    chunk = None
    for record in records:
        if isinstance(record, Chunk):
            assert record.compression == "zstd"
            chunk = zstandard.decompress(record.data)
            assert zlib.crc32(chunk) == record.uncompressed_crc
        elif isinstance(record, MessageIndex):
            for log_time, offset in record.records:
                assert chunk[offset] == 0x05  # a Message record starts there
                channel_id = int.from_bytes(chunk[offset + 9 : offset + 11], "little")
                assert channel_id == record.channel_id
                assert int.from_bytes(chunk[offset + 15 : offset + 23], "little") == log_time
    # Summary offsets point at their groups; the summary CRC covers summary + footer fields.
    data = mcap_file.read_bytes()
    footer = next(r for r in records if isinstance(r, Footer))
    offsets = [r for r in records if isinstance(r, SummaryOffset)]
    assert {o.group_opcode for o in offsets} >= {0x03, 0x04, 0x08, 0x0A, 0x0B, 0x0D}
    for group in offsets:
        assert data[group.group_start] == group.group_opcode
        assert footer.summary_start <= group.group_start < footer.summary_offset_start
    footer_at = len(data) - 8 - (1 + 8 + 20)
    assert data[footer_at] == 0x02 and footer.summary_start > 0
    covered = data[footer.summary_start : footer_at + 1 + 8 + 16]
    assert zlib.crc32(covered) == footer.summary_crc
    # A non-seeking reader (e.g. a pipe) reads it too.
    with open(mcap_file, "rb") as f:
        count = sum(1 for _ in NonSeekingReader(f).iter_messages(log_time_order=False))
    assert count == 2 * n


# ----------------------------------------------------------------------------- damaged files
def assert_prefix(back, run):
    n = len(back)
    assert 0 < n <= len(run)
    assert_same_bits(back.time, run.time[:n])
    for name in back.channels:
        assert_same_bits(back[name], run[name][:n])


@pytest.mark.parametrize("fraction", [0.5, 0.9])
def test_truncated_file_reads_what_precedes(tmp_path, mcap_file, run, fraction):
    data = mcap_file.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * fraction)])
    with pytest.warns(TruncatedRecordingWarning, match="the file ends at byte"):
        back = read_mcap(cut)
    assert_prefix(back, run)
    assert len(back) < len(run)
    assert back.labels == LABELS and back.sample_rate == FS


def test_damaged_tail_after_data_is_complete(tmp_path, mcap_file, run):
    data = mcap_file.read_bytes()
    cut = tmp_path / "no_footer.mcap"
    cut.write_bytes(data[:-30])  # footer and magic lost, every chunk intact
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_mcap(cut)  # the data section ends with DataEnd: nothing is missing
    assert len(back) == len(run)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"", "empty file"),
        (b"\x89MCAP0\r", "not an MCAP file"),
        (b"PK\x03\x04 this is a zip file, not a recording", "not an MCAP file"),
        (b"\x89MCAP0\r\n", "no channels could be read"),
    ],
)
def test_not_a_recording(tmp_path, content, message):
    path = tmp_path / "bad.mcap"
    path.write_bytes(content)
    with pytest.raises(PRSMHealthError, match=message):
        read_mcap(path)


def test_header_only_and_missing_file(tmp_path, mcap_file):
    data = mcap_file.read_bytes()
    header_end = 8 + 9 + int.from_bytes(data[9:17], "little")
    path = tmp_path / "header.mcap"
    path.write_bytes(data[:header_end])
    with pytest.raises(PRSMHealthError, match="no channels could be read.*ends at byte"):
        read_mcap(path)
    with open(mcap_file, "rb") as f:
        first_chunk = make_reader(f).get_summary().chunk_indexes[0].chunk_start_offset
    path.write_bytes(data[:first_chunk])
    with pytest.raises(PRSMHealthError, match="no samples could be read"):
        read_mcap(path)
    with pytest.raises(PRSMHealthError, match="no such file"):
        read_mcap(tmp_path / "missing.mcap")
    with pytest.raises(PRSMHealthError, match="cannot open"):
        read_mcap(tmp_path)


def test_every_cut_and_corruption_is_handled(tmp_path, mcap_file, run):
    """Cuts anywhere and flipped bytes: a prefix of the run with a warning, or a clear error."""
    data = mcap_file.read_bytes()
    rng = np.random.default_rng(3)
    cases = [data[:k] for k in np.linspace(0, len(data), 41).astype(int)]
    for _ in range(25):
        damaged = bytearray(data)
        at = int(rng.integers(8, len(data)))
        damaged[at : at + 4] = rng.integers(0, 256, 4, dtype=np.uint8).tobytes()
        cases.append(bytes(damaged))
    cases.append(data[:8] + rng.integers(0, 256, 5000, dtype=np.uint8).tobytes())
    path = tmp_path / "damaged.mcap"
    outcomes = set()
    for content in cases:
        path.write_bytes(content)
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                back = read_mcap(path)
        except PRSMHealthError as exc:
            assert str(exc).startswith(str(path))
            outcomes.add("error")
            continue
        truncated = [w for w in caught if issubclass(w.category, TruncatedRecordingWarning)]
        if len(back) == len(run) and not truncated:
            outcomes.add("intact")  # damage outside the data (summary, index, footer)
            continue
        assert truncated, "a shortened run must come with a TruncatedRecordingWarning"
        outcomes.add("prefix")
        n = len(back)
        assert_same_bits(back.time, run.time[:n])
        for name in back.channels:
            # A flipped byte inside a JSON number can change that one value without breaking
            # the chunk CRC only if the CRC is off; ours is on, so values are the originals.
            assert_same_bits(back[name], run[name][:n])
    assert {"error", "prefix"} <= outcomes


# ----------------------------------------------------------------------------- other writers
def write_with_mcap_writer(path, run, *, summary=True, chunking=True, finish=True, **kw):
    """The same topics written by mcap's own Writer (json.dumps per message)."""
    f = open(path, "wb")  # noqa: SIM115
    writer = Writer(
        f,
        use_chunking=chunking,
        chunk_size=16_384,
        **(
            {}
            if summary
            else dict(
                index_types=IndexType.NONE,
                repeat_channels=False,
                repeat_schemas=False,
                use_statistics=False,
                use_summary_offsets=False,
            )
        ),
        **kw,
    )
    writer.start()
    ids = {}
    for topic, pairs in TOPIC_FIELDS.items():
        source = run.truth if topic == TOPIC_TRUTH else run.channels
        pairs = [(name, source[ch]) for name, ch in pairs if ch in source]
        if pairs:  # a schema without a property list: fields come from the messages
            sid = writer.register_schema(topic, "jsonschema", b'{"type": "object"}')
            ids[topic] = (writer.register_channel(topic, "json", sid), pairs)
    writer.add_metadata("labels", {"design": "paper01", "seed": "7"})
    for i, t in enumerate(run.time):
        for cid, pairs in ids.values():
            body = {name: float(values[i]) for name, values in pairs}
            writer.add_message(cid, round(t * 1e9), json.dumps(body).encode(), round(t * 1e9))
    if finish:
        writer.finish()
    else:
        writer.flush()  # a recorder killed after its last flush
    f.close()
    return path


@pytest.fixture(scope="module")
def short_run():
    return make_run(n=400)


@pytest.mark.parametrize(
    "options",
    [
        dict(summary=False),
        dict(summary=False, chunking=False),
        dict(compression=CompressionType.LZ4),
        dict(compression=CompressionType.NONE),
    ],
    ids=["no-summary", "no-chunks", "lz4", "uncompressed"],
)
def test_files_from_mcap_writer(tmp_path, short_run, options):
    path = write_with_mcap_writer(tmp_path / "other.mcap", short_run, **options)
    if not options.get("summary", True):
        with open(path, "rb") as f:
            assert make_reader(f).get_summary() is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_mcap(path)  # scanned when there is no summary
    assert back.sample_rate == pytest.approx(FS, rel=1e-12)  # from the log-time spacing
    assert back.labels == {"design": "paper01", "seed": 7}
    assert_prefix(back, short_run)
    assert len(back) == len(short_run)
    windows = list(iter_windows(path, 0.005))
    assert sum(len(w) for w in windows) == len(short_run)


def test_foreign_file_with_some_fields(tmp_path):
    run = make_run(n=100, channels=("nut_radial_y_accel", "axial_load"))
    path = write_with_mcap_writer(tmp_path / "some.mcap", run, summary=False)
    back = read_mcap(path)
    assert list(back.channels) == ["nut_radial_y_accel", "axial_load"]
    for name in back.channels:
        assert_same_bits(back[name], run[name])


def test_crashed_recording_without_footer(tmp_path, short_run):
    path = write_with_mcap_writer(tmp_path / "crash.mcap", short_run, summary=True, finish=False)
    with pytest.warns(TruncatedRecordingWarning, match="before the end of its data section"):
        back = read_mcap(path)
    assert_prefix(back, short_run)
    assert len(back) == len(short_run)  # the writer had flushed every chunk


def _one_message_file(path, topic, encoding, payload):
    """An MCAP file with a single message, written by mcap's own Writer."""
    with open(path, "wb") as f:
        writer = Writer(f)
        writer.start()
        cid = writer.register_channel(topic, encoding, 0)
        writer.add_message(cid, 0, payload, 0)
        writer.finish()
    return path


def test_other_topics_and_encodings(tmp_path):
    path = tmp_path / "other.mcap"
    for topic, encoding, payload, message in (
        ("/camera", "json", b"{}", "topics present: /camera"),
        (TOPIC_DRIVE, "cbor", b"\xa0", "only 'json' is supported"),
        (TOPIC_DRIVE, "json", b"{not json", "is not valid JSON"),
    ):
        with pytest.raises(PRSMHealthError, match=message):
            read_mcap(_one_message_file(path, topic, encoding, payload))


# ----------------------------------------------------------------------------- replay
@pytest.fixture(scope="module")
def long_run():
    return make_run(n=20_000, seed=1)  # 1 s


@pytest.fixture(scope="module")
def long_file(tmp_path_factory, long_run):
    return write_mcap(long_run, tmp_path_factory.mktemp("long") / "long.mcap", chunk_size=32_768)


def test_windows_stream_in_order(long_file, long_run):
    stream = iter_windows(long_file, 0.05)
    windows = list(stream)
    assert len(windows) == 20
    assert [w.index for w in windows] == list(range(20))
    for k, w in enumerate(windows):
        assert len(w) == 1000 and w.sample_rate == FS
        assert w.start == pytest.approx(0.05 * k) and w.end == pytest.approx(0.05 * (k + 1))
        assert w.end_ns - w.start_ns == 50_000_000
        assert np.all(np.diff(w.time) > 0) and w.start <= w.time[0] and w.time[-1] < w.end
        assert w.labels == LABELS
        assert list(w.channels) == list(CHANNEL_NAMES)
    for name in CHANNEL_NAMES:
        assert_same_bits(np.concatenate([w[name] for w in windows]), long_run[name])
    # Streaming: at most the unfinished window plus one decoded chunk (~160 samples) is held.
    assert stream.peak_buffered <= 2 * 1000


def test_windows_overlap_partial_and_topics(long_file, long_run):
    windows = list(iter_windows(long_file, 0.05, step=0.025))
    assert len(windows) == 39
    for k, w in enumerate(windows):
        assert_same_bits(w["nut_axial_accel"], long_run["nut_axial_accel"][500 * k :][:1000])
    full = list(iter_windows(long_file, 0.3))
    assert [len(w) for w in full] == [6000] * 3
    partial = list(iter_windows(long_file, 0.3, partial=True))
    assert [len(w) for w in partial] == [6000] * 3 + [2000]
    drive_only = list(iter_windows(long_file, 0.5, topics=[TOPIC_DRIVE]))
    assert list(drive_only[0].channels) == [name for name, _ in TOPIC_FIELDS[TOPIC_DRIVE]]


def test_windows_without_summary_and_truncated(tmp_path, long_file, long_run):
    data = long_file.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.warns(TruncatedRecordingWarning):
        windows = list(iter_windows(cut, 0.05))
    assert 5 <= len(windows) < 20
    assert_same_bits(
        np.concatenate([w["drive_torque"] for w in windows]),
        long_run["drive_torque"][: 1000 * len(windows)],
    )


def test_windows_damaged_chunk_with_summary(tmp_path, long_file, long_run):
    data = bytearray(long_file.read_bytes())
    with open(long_file, "rb") as f:
        chunks = make_reader(f).get_summary().chunk_indexes
    middle = chunks[len(chunks) // 2]
    at = middle.chunk_start_offset + middle.chunk_length // 2
    data[at : at + 8] = b"\x00" * 8  # inside the compressed data; the summary is intact
    path = tmp_path / "flipped.mcap"
    path.write_bytes(bytes(data))
    with pytest.warns(TruncatedRecordingWarning, match="damaged chunk"):
        windows = list(iter_windows(path, 0.05))
    assert 5 <= len(windows) < 20
    got = np.concatenate([w["nut_axial_accel"] for w in windows])
    assert_same_bits(got, long_run["nut_axial_accel"][: len(got)])


def test_windows_pacing(tmp_path, run):
    path = write_mcap(run, tmp_path / "run.mcap")  # 0.1 s of log time
    started = time.monotonic()
    windows = list(iter_windows(path, 0.02, rate=2.0))
    elapsed = time.monotonic() - started
    assert len(windows) == 5
    assert elapsed >= 0.5 * 0.1 / 2.0  # very loose lower bound: it does wait


def test_window_parameters(mcap_file, tmp_path):
    for kwargs in (dict(window=0), dict(window=float("nan")), dict(window=0.1, rate=-1)):
        with pytest.raises(PRSMHealthError):
            iter_windows(mcap_file, **kwargs)
    with pytest.raises(PRSMHealthError, match="cannot replay topics"):
        iter_windows(mcap_file, 0.1, topics=["/camera"])
    with pytest.raises(PRSMHealthError, match="no such file"):
        iter_windows(tmp_path / "missing.mcap", 0.1)


def test_window_statistics(run):
    t = run.time
    window = Window(
        index=0,
        start=0.0,
        end=0.1,
        start_ns=0,
        end_ns=100_000_000,
        time=t,
        channels={
            "nut_axial_accel": 2.0 * np.sin(2 * np.pi * 100 * t),  # whole periods
            "axial_load": np.full(len(t), -5.0),
            "drive_torque": np.full(len(t), np.nan),
        },
    )
    stats = window_statistics(window)
    sine = stats["nut_axial_accel"]
    assert sine["mean"] == pytest.approx(0.0, abs=1e-12)
    assert sine["rms"] == pytest.approx(2.0 / np.sqrt(2.0), rel=1e-12)
    assert sine["peak"] == pytest.approx(2.0, rel=1e-6)
    assert sine["crest_factor"] == pytest.approx(np.sqrt(2.0), rel=1e-6)
    assert stats["axial_load"] == {"mean": -5.0, "rms": 5.0, "peak": 5.0, "crest_factor": 1.0}
    assert all(np.isnan(v) for v in stats["drive_torque"].values())


# ----------------------------------------------------------------------------- diagnosis
def diagnosis(k):
    return {
        "clearance": {"estimate": 1e-5 * k, "lower": 0.5e-5 * k, "upper": np.float64(2e-5)},
        "fault_class": "healthy" if k % 2 else "wear",
        "class_probabilities": {"healthy": 0.75, "wear": 0.25},
        "indicators": {"rms": float("nan"), "kurtosis": 3.0 + k},
        "model": {"name": "default", "version": "0.1.0"},
    }


def test_write_diagnosis_mcap(tmp_path, mcap_file, run):
    windows = list(iter_windows(mcap_file, 0.025))
    dst = write_diagnosis_mcap(
        mcap_file, tmp_path / "diagnosed.mcap", [(w.end_ns, diagnosis(w.index)) for w in windows]
    )
    with open(dst, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        topics = {c.topic: c for c in summary.channels.values()}
        assert set(topics) == {TOPIC_NUT_ACCEL, TOPIC_DRIVE, TOPIC_DIAGNOSIS}
        channel = topics[TOPIC_DIAGNOSIS]
        assert channel.message_encoding == "json"
        schema = summary.schemas[channel.schema_id]
        assert schema.encoding == "jsonschema"
        props = json.loads(schema.data)["properties"]
        assert props["clearance"]["properties"]["estimate"]["type"] == "number"
        assert "[m]" in props["clearance"]["properties"]["estimate"]["description"]
        got = [
            (m.log_time, json.loads(m.data))
            for _, _, m in reader.iter_messages(topics=[TOPIC_DIAGNOSIS])
        ]
        assert [t for t, _ in got] == [w.end_ns for w in windows]
        assert got[1][1]["indicators"] == {"rms": None, "kurtosis": 4.0}  # NaN → null
        assert got[1][1]["clearance"]["upper"] == 2e-5
        assert {m.name for m in reader.iter_metadata()} == {"labels", "operating", "prsm_health"}
        assert [a.name for a in reader.iter_attachments()] == ["scenario.json"]
        count = sum(1 for _ in reader.iter_messages(topics=[TOPIC_NUT_ACCEL, TOPIC_DRIVE]))
        assert count == 2 * len(run)
    # The signals are untouched and still replay in order next to the diagnosis.
    back = read_mcap(dst)
    for name in CHANNEL_NAMES:
        assert_same_bits(back[name], run[name])
    again = list(iter_windows(dst, 0.025))
    assert [len(w) for w in again] == [len(w) for w in windows]
    # Diagnosing the diagnosed file in place adds to the same channel.
    write_diagnosis_mcap(dst, dst, [(10**9, diagnosis(99))])
    with open(dst, "rb") as f:
        summary = make_reader(f).get_summary()
    (channel,) = [c for c in summary.channels.values() if c.topic == TOPIC_DIAGNOSIS]
    assert summary.statistics.channel_message_counts[channel.id] == len(windows) + 1


def test_diagnosis_writer_incremental(tmp_path, short_run):
    src = write_with_mcap_writer(tmp_path / "src.mcap", short_run, summary=False)
    dst = tmp_path / "dst.mcap"
    with DiagnosisWriter(src, dst, chunk_size=200) as writer:
        for k in range(10):
            writer.add(1_000_000 * k, {"fault_class": "healthy", "score": k})
        with pytest.raises(PRSMHealthError, match="must be a dict"):
            writer.add(0, [1, 2])
    with open(dst, "rb") as f:
        reader = make_reader(f)
        scores = [
            json.loads(m.data)["score"] for _, _, m in reader.iter_messages([TOPIC_DIAGNOSIS])
        ]
        assert scores == list(range(10))
        assert len(reader.get_summary().chunk_indexes) > 2
    assert_prefix(read_mcap(dst), short_run)

    with pytest.raises(RuntimeError), DiagnosisWriter(src, tmp_path / "aborted.mcap") as writer:
        writer.add(0, {"x": 1.0})
        raise RuntimeError("the pipeline failed")
    assert not (tmp_path / "aborted.mcap").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dst.mcap", "src.mcap"]


def test_diagnosis_of_damaged_source(tmp_path, mcap_file):
    data = mcap_file.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.warns(TruncatedRecordingWarning):
        dst = write_diagnosis_mcap(cut, tmp_path / "dst.mcap", [(0, {"score": 1.0})])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = read_mcap(dst)  # a complete file again, holding what was readable
    assert 0 < len(back) < 2000
    with open(dst, "rb") as f:
        assert make_reader(f).get_summary() is not None
