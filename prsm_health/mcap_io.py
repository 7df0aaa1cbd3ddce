"""MCAP recordings of runs: writer, tolerant reader, streaming replay and diagnosis output.

The files follow the MCAP contract of ../shared/DESIGN.md, so Foxglove plots every channel
with no custom code:

- JSON schema encoding (``jsonschema``, draft-07) and JSON message encoding, one message per
  sample and topic, each message a flat object of numbers;
- topics :data:`TOPIC_NUT_ACCEL` (fields ``axial``, ``tangential``, ``radial_x``,
  ``radial_y``), :data:`TOPIC_DRIVE` (``screw_angle``, ``screw_speed``, ``carrier_speed``,
  ``nut_position``, ``drive_torque``, ``friction_torque``, ``axial_load``) and
  :data:`TOPIC_DIAGNOSIS` (written by :class:`DiagnosisWriter`); SI units, given in each
  field's schema description;
- ``log_time`` = ``publish_time`` = run start + sample time, in nanoseconds;
- zstd-compressed chunks, message indexes, and a summary section (schemas, channels,
  statistics, chunk/attachment/metadata indexes, summary offsets) with its CRC;
- the run labels in a Metadata record named ``labels``, and the scenario (JSON) as an
  attachment (``application/json``).

MCAP metadata values are strings. A label that is a string is stored as is, unless it would
itself parse as JSON (``"1.5"``, ``"true"``, ``"null"``, ``'"x"'``), in which case it is stored
JSON-encoded; every other value (numbers, booleans, None, lists, dicts, numpy scalars) is stored
JSON-encoded. The reader JSON-decodes each value and keeps the raw string when that fails, so
labels round-trip exactly and a human reading the metadata in Foxglove sees ``paper01``, not
``"paper01"``.

A second Metadata record, ``prsm_health``, holds what the reader needs to rebuild the
:class:`~prsm_health.run.Run` exactly: the sample rate [Hz], the run start [ns], the energy book
[J], the channel units and the name of the scenario attachment. It is kept out of ``labels`` so
that ``labels`` equals :attr:`Run.labels` after a round trip.

Message payloads are written with :func:`repr` of each float (shortest string that parses back
to the same double) — byte for byte what ``json.dumps(..., separators=(",", ":"))`` writes for
finite values. JSON has no NaN or infinity: non-finite samples are written as ``null`` and read
back as NaN. The record layout is assembled with numpy rather than one
:meth:`mcap.writer.Writer.add_message` call per message (see tools/bench_mcap.py); the record
classes of :mod:`mcap.records` serialise every other record, and the tests read the files back
with :mod:`mcap`'s own readers.
"""

from __future__ import annotations

import io
import json
import math
import numbers
import os
import secrets
import struct
import time as _time
import warnings
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from itertools import chain
from operator import itemgetter
from pathlib import Path

import numpy as np

from .channels import CHANNEL_NAMES, UNITS
from .errors import PRSMHealthError, TruncatedRecordingWarning
from .jsonable import json_ready
from .run import Run, lookup_channel

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "TOPIC_DIAGNOSIS",
    "TOPIC_DRIVE",
    "TOPIC_FIELDS",
    "TOPIC_NUT_ACCEL",
    "DiagnosisWriter",
    "TruncatedRecordingWarning",
    "Window",
    "WindowStream",
    "iter_windows",
    "read_mcap",
    "window_statistics",
    "write_diagnosis_mcap",
    "write_mcap",
]

TOPIC_NUT_ACCEL = "/prsm/nut_accel"
TOPIC_DRIVE = "/prsm/drive"
TOPIC_DIAGNOSIS = "/prsm/diagnosis"

#: Message fields of each signal topic, as (field, contract channel) pairs (contract).
TOPIC_FIELDS: dict[str, tuple[tuple[str, str], ...]] = {
    TOPIC_NUT_ACCEL: (
        ("axial", "nut_axial_accel"),
        ("tangential", "nut_tangential_accel"),
        ("radial_x", "nut_radial_x_accel"),
        ("radial_y", "nut_radial_y_accel"),
    ),
    TOPIC_DRIVE: tuple(
        (name, name)
        for name in (
            "screw_angle",
            "screw_speed",
            "carrier_speed",
            "nut_position",
            "drive_torque",
            "friction_torque",
            "axial_load",
        )
    ),
}

#: Default uncompressed chunk size [bytes]: about 10 000 messages, 0.25 s of a 20 kHz run.
DEFAULT_CHUNK_SIZE = 1 << 20

LABELS_METADATA = "labels"
INFO_METADATA = "prsm_health"
FORMAT_VERSION = "1"

_SCHEMA_NAMES = {TOPIC_NUT_ACCEL: "prsm_health.NutAccel", TOPIC_DRIVE: "prsm_health.Drive"}
_MEANINGS = {
    "screw_angle": "screw rotation (motor encoder)",
    "screw_speed": "screw angular speed",
    "carrier_speed": "carrier (roller revolution) angular speed",
    "nut_position": "nut axial position (linear encoder)",
    "nut_axial_accel": "nut acceleration along the screw axis",
    "nut_tangential_accel": "nut circumferential acceleration at the nut pitch radius",
    "nut_radial_x_accel": "nut lateral acceleration, x",
    "nut_radial_y_accel": "nut lateral acceleration, y",
    "drive_torque": "torque the motor applies to the screw",
    "friction_torque": "friction part of the drive torque",
    "axial_load": "external axial load on the nut",
}


# ============================================================================ low-level writer
_MAGIC = b"\x89MCAP0\r\n"
# Record opcodes of the MCAP specification (mcap.opcode.Opcode).
_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK = 0x02, 0x03, 0x04, 0x05, 0x06
_OP_MESSAGE_INDEX, _OP_ATTACHMENT, _OP_METADATA, _OP_DATA_END = 0x07, 0x09, 0x0C, 0x0F
_SCANNED = frozenset(
    (_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK)
    + (_OP_ATTACHMENT, _OP_METADATA, _OP_DATA_END)
)
# Message record: opcode u8, record length u64, channel u16, sequence u32, log/publish u64.
_MESSAGE_HEADER = np.dtype(
    [
        ("opcode", "u1"),
        ("length", "<u8"),
        ("channel", "<u2"),
        ("sequence", "<u4"),
        ("log_time", "<u8"),
        ("publish_time", "<u8"),
    ]
)
_HEADER_SIZE = _MESSAGE_HEADER.itemsize  # 31: packed, no alignment padding
_HEADER_COLUMNS = np.arange(_HEADER_SIZE)
_MESSAGE_INDEX_HEAD = struct.Struct("<BQHI")
# zstd level 1: on these JSON sample streams it is both faster and ~10 % smaller than the
# library default (3), measured on 2 s of 20 kHz signals (tools/bench_mcap.py).
_ZSTD_LEVEL = 1
# Samples formatted at a time by write_mcap (~10 MB of JSON for both topics).
_WRITE_BLOCK = 1 << 16


@dataclass
class _MessageBlock:
    """Messages in record order: one payload buffer plus per-message arrays."""

    channel: np.ndarray  # uint16
    sequence: np.ndarray  # uint32
    log_time: np.ndarray  # uint64
    publish_time: np.ndarray  # uint64
    payload: np.ndarray  # uint8, payloads back to back
    length: np.ndarray  # int64, payload size of each message

    @classmethod
    def from_payloads(cls, channel, sequence, log_time, publish_time, payloads: list[bytes]):
        n = len(payloads)
        return cls(
            np.asarray(channel, dtype=np.uint16),
            np.asarray(sequence, dtype=np.uint64).astype(np.uint32),  # wraps, as MCAP allows
            np.asarray(log_time, dtype=np.uint64),
            np.asarray(publish_time, dtype=np.uint64),
            np.frombuffer(b"".join(payloads), dtype=np.uint8),
            np.fromiter(map(len, payloads), dtype=np.int64, count=n),
        )

    @classmethod
    def concat(cls, *blocks: _MessageBlock) -> _MessageBlock:
        return cls(
            *(
                np.concatenate([getattr(b, name) for b in blocks])
                for name in ("channel", "sequence", "log_time", "publish_time", "payload", "length")
            )
        )

    def slice(self, a: int, b: int, payload_start: np.ndarray) -> _MessageBlock:
        """Messages ``a:b`` (``payload_start``: offsets of the payloads, plus the end)."""
        return _MessageBlock(
            self.channel[a:b],
            self.sequence[a:b],
            self.log_time[a:b],
            self.publish_time[a:b],
            self.payload[payload_start[a] : payload_start[b]],
            self.length[a:b],
        )


class _FileWriter:
    """Writes an MCAP file from whole chunks of messages.

    The per-message work (record headers, message indexes) is vectorised with numpy; the other
    records are serialised by :mod:`mcap.records`, and the summary section follows what
    :meth:`mcap.writer.Writer.finish` writes, with the data-section CRC filled in as well.
    """

    def __init__(self, stream, *, chunk_size: int = DEFAULT_CHUNK_SIZE):
        import zstandard

        self._stream = stream
        self._chunk_size = int(chunk_size)
        self._compressor = zstandard.ZstdCompressor(level=_ZSTD_LEVEL, write_content_size=True)
        self._pos = 0
        self._crc = 0
        self.schemas: dict[int, object] = {}
        self.channels: dict[int, object] = {}
        self._chunk_indexes: list = []
        self._attachment_indexes: list = []
        self._metadata_indexes: list = []
        self._counts: dict[int, int] = {}
        self._message_count = 0
        self._start_time: int | None = None
        self._end_time = 0
        self._tail: _MessageBlock | None = None

    # ------------------------------------------------------------------ plumbing
    def _write(self, data) -> None:
        self._stream.write(data)
        self._crc = zlib.crc32(data, self._crc)
        self._pos += len(data)

    def _write_record(self, record) -> int:
        from mcap.data_stream import RecordBuilder

        builder = RecordBuilder()
        record.write(builder)
        offset = self._pos
        self._write(builder.end())
        return offset

    # ------------------------------------------------------------------ records
    def start(self, library: str) -> None:
        from mcap.records import Header

        self._write(_MAGIC)
        self._write_record(Header(profile="", library=library))

    def add_schema(self, name: str, encoding: str, data: bytes, schema_id: int | None = None):
        from mcap.records import Schema

        if schema_id is None:
            schema_id = max(self.schemas, default=0) + 1
        if schema_id not in self.schemas:
            schema = Schema(id=schema_id, data=data, encoding=encoding, name=name)
            self.schemas[schema_id] = schema
            self._write_record(schema)
        return schema_id

    def add_channel(
        self,
        topic: str,
        message_encoding: str,
        schema_id: int,
        metadata: dict[str, str] | None = None,
        channel_id: int | None = None,
    ) -> int:
        from mcap.records import Channel

        if channel_id is None:
            channel_id = max(self.channels, default=0) + 1
        if channel_id not in self.channels:
            channel = Channel(
                id=channel_id,
                topic=topic,
                message_encoding=message_encoding,
                schema_id=schema_id,
                metadata=dict(metadata or {}),
            )
            self.channels[channel_id] = channel
            self._write_record(channel)
        return channel_id

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        from mcap.records import Metadata, MetadataIndex

        offset = self._write_record(Metadata(name=name, metadata=data))
        self._metadata_indexes.append(
            MetadataIndex(offset=offset, length=self._pos - offset, name=name)
        )

    def add_attachment(self, name, media_type, data, *, log_time=0, create_time=0) -> None:
        from mcap.records import Attachment, AttachmentIndex

        offset = self._write_record(
            Attachment(
                create_time=create_time,
                log_time=log_time,
                name=name,
                media_type=media_type,
                data=data,
            )
        )
        self._attachment_indexes.append(
            AttachmentIndex(
                offset=offset,
                length=self._pos - offset,
                log_time=log_time,
                create_time=create_time,
                data_size=len(data),
                name=name,
                media_type=media_type,
            )
        )

    def add_messages(self, block: _MessageBlock, *, more: bool = False) -> None:
        """Write messages, in the given order, as chunks of about ``chunk_size`` bytes.

        With ``more``, the last, unfinished chunk is held back and continued by the next call
        (or written by :meth:`finish`), so feeding a long run block by block gives the same
        chunks as one call.
        """
        if self._tail is not None:
            block = _MessageBlock.concat(self._tail, block)
            self._tail = None
        n = len(block.length)
        if n == 0:
            return
        # As mcap's Writer: a chunk is closed by the message that takes it past chunk_size.
        ends = np.cumsum(block.length + _HEADER_SIZE)
        bounds = [0]
        unfinished = False
        while bounds[-1] < n:
            base = int(ends[bounds[-1] - 1]) if bounds[-1] else 0
            past = int(np.searchsorted(ends, base + self._chunk_size, side="right"))
            unfinished = past >= n
            bounds.append(min(past + 1, n))
        payload_start = np.concatenate(([0], np.cumsum(block.length)))
        if more and unfinished:
            self._tail = block.slice(bounds[-2], n, payload_start)
            bounds.pop()
        for a, b in zip(bounds[:-1], bounds[1:]):
            self._write_message_chunk(block, a, b, payload_start)

    def _write_message_chunk(self, block: _MessageBlock, a: int, b: int, payload_start):
        length = block.length[a:b]
        n = b - a
        record_start = np.zeros(n, dtype=np.int64)
        np.cumsum(length[:-1] + _HEADER_SIZE, out=record_start[1:])
        total = int(record_start[-1] + _HEADER_SIZE + length[-1])
        header = np.empty(n, dtype=_MESSAGE_HEADER)
        header["opcode"] = _OP_MESSAGE
        header["length"] = length + (_HEADER_SIZE - 9)
        header["channel"] = block.channel[a:b]
        header["sequence"] = block.sequence[a:b]
        header["log_time"] = block.log_time[a:b]
        header["publish_time"] = block.publish_time[a:b]
        out = np.empty(total, dtype=np.uint8)
        header_at = (record_start[:, None] + _HEADER_COLUMNS).ravel()
        payload_mask = np.ones(total, dtype=bool)
        payload_mask[header_at] = False
        out[header_at] = header.view(np.uint8)
        out[payload_mask] = block.payload[payload_start[a] : payload_start[b]]

        log_time = block.log_time[a:b]
        index = {}
        for channel in np.unique(block.channel[a:b]):
            mine = block.channel[a:b] == channel
            index[int(channel)] = (log_time[mine], record_start[mine])
        self._write_chunk(
            out.tobytes(), index, int(log_time.min()), int(log_time.max()), compressed=None
        )

    def _write_chunk(
        self,
        records: bytes,
        index: dict[int, tuple[np.ndarray, np.ndarray]],
        start_time: int,
        end_time: int,
        *,
        compressed: tuple[str, bytes, int, int] | None,
    ) -> None:
        """Write a Chunk record and its message indexes.

        ``compressed`` = (compression, data, uncompressed size, uncompressed crc) copies an
        existing chunk as is; otherwise ``records`` are compressed with zstd.
        """
        from mcap.records import Chunk, ChunkIndex

        if compressed is None:
            compression = "zstd"
            data = self._compressor.compress(records)
            size, crc = len(records), zlib.crc32(records)
        else:
            compression, data, size, crc = compressed
        chunk = Chunk(
            compression=compression,
            data=data,
            message_start_time=start_time,
            message_end_time=end_time,
            uncompressed_crc=crc,
            uncompressed_size=size,
        )
        chunk_start = self._write_record(chunk)
        chunk_length = self._pos - chunk_start
        index_start = self._pos
        offsets = {}
        for channel, (log_time, record_start) in index.items():
            entries = np.empty((len(log_time), 2), dtype="<u8")
            entries[:, 0] = log_time
            entries[:, 1] = record_start
            body = entries.tobytes()
            offsets[channel] = self._pos
            self._write(
                _MESSAGE_INDEX_HEAD.pack(_OP_MESSAGE_INDEX, 6 + len(body), channel, len(body))
                + body
            )
            self._counts[channel] = self._counts.get(channel, 0) + len(log_time)
            self._message_count += len(log_time)
        self._chunk_indexes.append(
            ChunkIndex(
                message_start_time=start_time,
                message_end_time=end_time,
                chunk_start_offset=chunk_start,
                chunk_length=chunk_length,
                message_index_offsets=offsets,
                message_index_length=self._pos - index_start,
                compression=compression,
                compressed_size=len(data),
                uncompressed_size=size,
            )
        )
        self._start_time = (
            start_time if self._start_time is None else min(self._start_time, start_time)
        )
        self._end_time = max(self._end_time, end_time)

    def finish(self) -> None:
        from mcap.data_stream import RecordBuilder
        from mcap.opcode import Opcode
        from mcap.records import DataEnd, Footer, Statistics, SummaryOffset

        if self._tail is not None:
            tail, self._tail = self._tail, None
            self.add_messages(tail)
        self._write_record(DataEnd(data_section_crc=self._crc))
        summary_start = self._pos
        builder = RecordBuilder()
        groups = []
        statistics = Statistics(
            message_count=self._message_count,
            schema_count=len(self.schemas),
            channel_count=len(self.channels),
            attachment_count=len(self._attachment_indexes),
            metadata_count=len(self._metadata_indexes),
            chunk_count=len(self._chunk_indexes),
            message_start_time=self._start_time or 0,
            message_end_time=self._end_time,
            channel_message_counts=dict(sorted(self._counts.items())),
        )
        for opcode, records in (
            (Opcode.SCHEMA, list(self.schemas.values())),
            (Opcode.CHANNEL, list(self.channels.values())),
            (Opcode.STATISTICS, [statistics]),
            (Opcode.CHUNK_INDEX, self._chunk_indexes),
            (Opcode.ATTACHMENT_INDEX, self._attachment_indexes),
            (Opcode.METADATA_INDEX, self._metadata_indexes),
        ):
            if not records:
                continue
            group_start = builder.count
            for record in records:
                record.write(builder)
            groups.append(
                SummaryOffset(
                    group_opcode=opcode,
                    group_start=summary_start + group_start,
                    group_length=builder.count - group_start,
                )
            )
        summary_offset_start = summary_start + builder.count
        for group in groups:
            group.write(builder)
        summary = builder.end()
        crc = zlib.crc32(summary)
        crc = zlib.crc32(
            struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, summary_offset_start), crc
        )
        self._write(summary)
        self._write_record(
            Footer(
                summary_start=summary_start,
                summary_offset_start=summary_offset_start,
                summary_crc=crc,
            )
        )
        self._write(_MAGIC)


class _AtomicFile:
    """A temporary file next to ``path``, renamed onto it only when the write completed."""

    def __init__(self, path: Path):
        self.path = path
        if path.is_dir():
            raise PRSMHealthError(f"{path}: is a directory")
        if not path.parent.is_dir():
            raise PRSMHealthError(f"{path.parent}: no such directory")
        # A unique name, opened exclusively, with the permissions a plain open() would give.
        self.tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.partial")
        try:
            self.stream = open(self.tmp, "xb", buffering=1 << 20)  # noqa: SIM115 - commit/abort
        except OSError as exc:
            raise PRSMHealthError(f"{path}: cannot write ({exc.strerror or exc})") from None

    def commit(self) -> Path:
        self.stream.flush()
        os.fsync(self.stream.fileno())  # the data is on disk before the name points at it
        self.stream.close()
        os.replace(self.tmp, self.path)
        return self.path

    def abort(self) -> None:
        self.stream.close()
        self.tmp.unlink(missing_ok=True)


def _library() -> str:
    from mcap.writer import LIBRARY_IDENTIFIER

    from . import __version__

    return f"prsm_health/{__version__}; {LIBRARY_IDENTIFIER}"


# ================================================================================== writing
def _json_object_payloads(fields: list[str], columns: list[np.ndarray]) -> list[bytes]:
    """One compact JSON object per row, floats as ``repr`` (exact), non-finite as ``null``."""
    rows = zip(*[column.tolist() for column in columns])
    if all(np.isfinite(column).all() for column in columns):
        template = ("{" + ",".join(f'"{name}":%r' for name in fields) + "}").encode()
        return [template % row for row in rows]
    template = "{" + ",".join(f'"{name}":%s' for name in fields) + "}"
    finite = math.isfinite
    return [
        (template % tuple(repr(v) if finite(v) else "null" for v in row)).encode() for row in rows
    ]


def _topic_schema(topic: str, pairs: list[tuple[str, str]]) -> bytes:
    properties = {
        name: {
            "type": "number",
            "description": f"{_MEANINGS[channel]} [{UNITS[channel]}] (channel {channel}); "
            "null when the sample is not finite",
        }
        for name, channel in pairs
    }
    schema = {
        "$schema": "http://json-schema.org/draft-07/schema#",
        "title": _SCHEMA_NAMES[topic],
        "description": f"One sample of {topic}, SI units (prsm_health MCAP contract)",
        "type": "object",
        "properties": properties,
        "required": [name for name, _ in pairs],
    }
    return json.dumps(schema, indent=2).encode()


def _metadata_value(value) -> str:
    if isinstance(value, str):
        try:
            json.loads(value)
        except ValueError:
            return value
    return json.dumps(json_ready(value))


def _decode_metadata_value(text: str):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _to_ns(seconds: np.ndarray) -> np.ndarray:
    return np.round(seconds * 1e9).astype(np.int64)


def write_mcap(
    run: Run,
    path: str | os.PathLike,
    *,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    scenario_name: str = "scenario.json",
    start_time_ns: int = 0,
) -> Path:
    """Write a run as an MCAP recording that Foxglove plots directly.

    Parameters
    ----------
    run : Run
        Only the contract channels present in ``run.channels`` are written (a recording may
        lack some); other channels are ignored.
    path : str or path-like
        Destination. Written atomically: a temporary file in the same directory, renamed onto
        ``path`` once complete, so an interrupted write never leaves a half file under it.
    chunk_size : int [bytes]
        Uncompressed size above which a chunk is closed.
    scenario_name : str
        Name of the scenario attachment (``application/json``).
    start_time_ns : int [ns]
        Log time of the run start; message ``log_time`` = ``publish_time`` =
        ``start_time_ns + round(time · 1e9)``. Use a Unix time to place the run on a clock.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    PRSMHealthError
        The run has no contract channel, channel lengths differ from ``time``, ``time`` is not
        finite and non-decreasing, or the destination directory does not exist.
    """
    path = Path(path)
    time = np.asarray(run.time, dtype=np.float64)
    n = time.size
    if time.ndim != 1 or n == 0:
        raise PRSMHealthError("run.time must be a non-empty 1-D array [s]")
    if not np.isfinite(time).all() or (n > 1 and np.any(np.diff(time) < 0)):
        raise PRSMHealthError("run.time must be finite and non-decreasing [s]")
    if not isinstance(start_time_ns, (int, np.integer)) or start_time_ns < 0:
        raise PRSMHealthError(f"start_time_ns = {start_time_ns!r} must be an integer >= 0 [ns]")
    if not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise PRSMHealthError(f"chunk_size = {chunk_size!r} must be an integer >= 1 [bytes]")
    rate = run.sample_rate
    _require_positive("run.sample_rate", rate, "[Hz]")
    if not scenario_name or not isinstance(scenario_name, str):
        raise PRSMHealthError("scenario_name must be a non-empty string")
    if float(time[-1]) * 1e9 + start_time_ns >= 2**63 or float(time[0]) * 1e9 + start_time_ns < 0:
        raise PRSMHealthError("start_time_ns + time does not fit the MCAP 64-bit ns clock")
    for name, values in run.channels.items():
        if name in CHANNEL_NAMES and np.shape(values) != (n,):
            raise PRSMHealthError(
                f"channel {name!r} has shape {np.shape(values)}; expected ({n},) like time"
            )
    topics = {}
    for topic, pairs in TOPIC_FIELDS.items():
        present = [(name, channel) for name, channel in pairs if channel in run.channels]
        if present:
            topics[topic] = present
    if not topics:
        raise PRSMHealthError(
            f"run has none of the contract channels ({', '.join(CHANNEL_NAMES)}); nothing to write"
        )

    log_time = start_time_ns + _to_ns(time)
    columns = {
        topic: [np.asarray(run.channels[channel], dtype=np.float64) for _, channel in pairs]
        for topic, pairs in topics.items()
    }

    try:
        info = {
            "format": FORMAT_VERSION,
            "sample_rate": repr(float(rate)),
            "start_time_ns": str(int(start_time_ns)),
            "scenario_attachment": scenario_name,
            "units": json.dumps({k: UNITS[k] for k in ("time", *CHANNEL_NAMES) if k in UNITS}),
            "energy": json.dumps(json_ready(run.energy)),
        }
        scenario = json.dumps(json_ready(run.scenario), indent=1).encode()
        labels = {str(k): _metadata_value(v) for k, v in run.labels.items()}
    except (TypeError, ValueError) as exc:
        raise PRSMHealthError(
            f"run labels, scenario or energy not JSON-serialisable: {exc}"
        ) from None

    target = _AtomicFile(path)
    try:
        writer = _FileWriter(target.stream, chunk_size=chunk_size)
        writer.start(_library())
        channel_ids = []
        for topic, pairs in topics.items():
            schema_id = writer.add_schema(
                _SCHEMA_NAMES[topic], "jsonschema", _topic_schema(topic, pairs)
            )
            channel_ids.append(writer.add_channel(topic, "json", schema_id))
        writer.add_metadata(LABELS_METADATA, labels)
        writer.add_metadata(INFO_METADATA, info)
        writer.add_attachment(
            scenario_name, "application/json", scenario, log_time=int(start_time_ns)
        )
        # One message per topic and sample, interleaved sample by sample as a live recorder
        # would write them, so every chunk covers one time span of all topics. Formatted
        # block by block to bound the memory of long runs.
        k = len(channel_ids)
        for a in range(0, n, _WRITE_BLOCK):
            b = min(a + _WRITE_BLOCK, n)
            payloads = [
                _json_object_payloads([name for name, _ in pairs], [c[a:b] for c in columns[t]])
                for t, pairs in topics.items()
            ]
            block = _MessageBlock.from_payloads(
                np.tile(np.asarray(channel_ids), b - a),
                np.repeat(np.arange(a, b), k),
                np.repeat(log_time[a:b], k),
                np.repeat(log_time[a:b], k),
                list(chain.from_iterable(zip(*payloads))),
            )
            writer.add_messages(block, more=True)
        writer.finish()
    except BaseException:
        target.abort()
        raise
    return target.commit()


# ================================================================================== reading
def _damage_errors() -> tuple[type[BaseException], ...]:
    """Exceptions the mcap, struct, json and codec layers raise on damaged bytes."""
    import zstandard
    from mcap.exceptions import McapError

    return (
        McapError,
        struct.error,
        ValueError,  # CRC mismatch, bad UTF-8 in strings
        EOFError,
        OverflowError,
        zstandard.ZstdError,
    )


class _Damaged(Exception):
    pass


class _CappedStream:
    """A read-only file view whose reads never ask for more than what is left.

    A damaged length field then costs a short read (reported as damage) instead of a
    multi-gigabyte allocation.
    """

    def __init__(self, f, size: int):
        self._f = f
        self._size = size

    def read(self, n: int = -1) -> bytes:
        left = self._size - self._f.tell()
        if n is None or n < 0 or n > left:
            n = max(left, 0)
        return self._f.read(n)

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        return self._f.seek(offset, whence)

    def tell(self) -> int:
        return self._f.tell()

    def seekable(self) -> bool:
        return True


_RECORD_HEAD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")


@dataclass
class _Batch:
    """Samples of one topic: log times [ns] and one row per field."""

    topic: str
    log_time: np.ndarray  # int64
    fields: list[str]
    values: np.ndarray  # (len(fields), n) float64

    def sorted(self) -> _Batch:
        if len(self.log_time) > 1 and np.any(np.diff(self.log_time) < 0):
            order = np.argsort(self.log_time, kind="stable")
            return _Batch(self.topic, self.log_time[order], self.fields, self.values[:, order])
        return self


class _Source:
    """An MCAP file opened for tolerant reading.

    Parsing stops at the first damaged or missing byte; :attr:`damage` then says where, and
    everything before it stays usable.
    """

    def __init__(self, path: str | os.PathLike, topics: Iterable[str] | None = None):
        self.path = Path(path)
        try:
            self._file = open(self.path, "rb")  # noqa: SIM115 - closed by close()
        except FileNotFoundError:
            raise PRSMHealthError(f"{self.path}: no such file") from None
        except OSError as exc:
            raise PRSMHealthError(f"{self.path}: cannot open ({exc.strerror or exc})") from None
        self.size = os.fstat(self._file.fileno()).st_size
        if self.size == 0:
            self.close()
            raise PRSMHealthError(f"{self.path}: empty file, not an MCAP recording")
        if self._file.read(len(_MAGIC)) != _MAGIC:
            self.close()
            raise PRSMHealthError(f"{self.path}: not an MCAP file (no MCAP magic at the start)")
        self.stream = _CappedStream(self._file, self.size)
        self.topics = tuple(TOPIC_FIELDS if topics is None else topics)
        self.errors = _damage_errors()
        self.schemas: dict[int, object] = {}
        self.channels: dict[int, object] = {}
        self.metadata: dict[str, dict[str, str]] = {}
        self.attachments: list = []
        self.damage: str | None = None
        self.complete = False  # the end of the data section was reached
        self._wanted: dict[int, str] = {}
        self._fields: dict[int, frozenset[str]] = {}

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ------------------------------------------------------------------ registration
    def register(self, record) -> None:
        from mcap.records import Channel, Schema

        if isinstance(record, Schema):
            self.schemas[record.id] = record
        elif isinstance(record, Channel):
            self.channels[record.id] = record
            if record.topic in self.topics and record.topic in TOPIC_FIELDS:
                if record.message_encoding != "json":
                    raise PRSMHealthError(
                        f"{self.path}: topic {record.topic} has message encoding "
                        f"{record.message_encoding!r}; only 'json' is supported"
                    )
                self._wanted[record.id] = record.topic
                self._fields.pop(record.id, None)

    def _declared_fields(self, channel_id: int) -> frozenset[str]:
        """Field names the channel's JSON schema declares (empty when it lists none)."""
        if channel_id not in self._fields:
            schema = self.schemas.get(self.channels[channel_id].schema_id)
            declared = None
            if schema is not None and schema.encoding == "jsonschema":
                try:
                    declared = json.loads(schema.data).get("properties")
                except (ValueError, AttributeError):
                    declared = None
            self._fields[channel_id] = frozenset(declared if isinstance(declared, dict) else ())
        return self._fields[channel_id]

    # ------------------------------------------------------------------ chunks
    def chunk_records(self, chunk) -> bytes:
        """Decompressed and CRC-checked records of a chunk."""
        if chunk.compression == "zstd":
            import zstandard

            # Check the size the frame announces before zstd allocates it.
            announced = zstandard.frame_content_size(chunk.data)
            if announced not in (-1, chunk.uncompressed_size):
                raise _Damaged("zstd frame size does not match the chunk header")
            data = zstandard.decompress(chunk.data, max_output_size=chunk.uncompressed_size)
        elif chunk.compression == "lz4":
            import lz4.frame

            try:
                data = lz4.frame.decompress(chunk.data)
            except RuntimeError as exc:
                raise _Damaged(f"lz4: {exc}") from None
        elif chunk.compression == "":
            data = chunk.data
        else:
            raise PRSMHealthError(
                f"{self.path}: unsupported chunk compression {chunk.compression!r}"
            )
        if len(data) != chunk.uncompressed_size:
            raise _Damaged("chunk size does not match its header")
        if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
            raise _Damaged("chunk CRC mismatch")
        return data

    def walk(self, data: bytes, *, index_only: bool = False) -> dict[int, tuple[list, list]]:
        """Messages of the chunk records ``data``, per channel id: (log times, payloads).

        With ``index_only``, every channel is kept and the second list holds each message's
        offset in ``data`` instead of its payload.
        """
        from mcap.data_stream import ReadDataStream
        from mcap.records import Channel, Schema

        out: dict[int, tuple[list, list]] = {}
        wanted = self._wanted
        unpack_record = _RECORD_HEAD.unpack_from
        unpack_message = _MESSAGE_HEAD.unpack_from
        pos, size = 0, len(data)
        while pos < size:
            if pos + 9 > size:
                raise _Damaged("record cut short inside a chunk")
            opcode, length = unpack_record(data, pos)
            body = pos + 9
            end = body + length
            if end > size:
                raise _Damaged("record runs past the end of its chunk")
            if opcode == _OP_MESSAGE:
                if length < 22:
                    raise _Damaged("message record too short")
                channel_id, _, log_time, _ = unpack_message(data, body)
                if index_only:
                    entry = out.get(channel_id)
                    if entry is None:
                        entry = out[channel_id] = ([], [])
                    entry[0].append(log_time)
                    entry[1].append(pos)
                elif channel_id in wanted:
                    entry = out.get(channel_id)
                    if entry is None:
                        entry = out[channel_id] = ([], [])
                    entry[0].append(log_time)
                    entry[1].append(data[body + 22 : end])
            elif opcode in (_OP_SCHEMA, _OP_CHANNEL):
                stream = ReadDataStream(io.BytesIO(data[body:end]))
                self.register((Schema if opcode == _OP_SCHEMA else Channel).read(stream))
            pos = end
        return out

    def decode(self, channel_id: int, log_time: list, payloads: list) -> _Batch:
        """JSON payloads of one channel → a batch of samples."""
        topic = self._wanted[channel_id]
        try:
            objects = json.loads(b"[" + b",".join(payloads) + b"]")
        except ValueError:
            for i, payload in enumerate(payloads):
                try:
                    json.loads(payload)
                except ValueError:
                    raise PRSMHealthError(
                        f"{self.path}: message on {topic} at log time {log_time[i]} ns "
                        "is not valid JSON"
                    ) from None
            raise  # pragma: no cover - the join of valid objects is valid
        # Contract fields the schema declares or the first message has, in contract order.
        declared = self._declared_fields(channel_id)
        first = objects[0] if objects and isinstance(objects[0], dict) else {}
        fields = [n for n, _ in TOPIC_FIELDS[topic] if n in declared or n in first]
        if not fields:
            values = np.empty((0, len(objects)))
        else:
            try:
                getter = itemgetter(*fields)
                rows = list(map(getter, objects))
                values = np.array(rows, dtype=np.float64).reshape(len(objects), len(fields)).T
            except (KeyError, TypeError, ValueError):
                values = (
                    np.array(
                        [
                            [_number(o.get(f)) if isinstance(o, dict) else np.nan for f in fields]
                            for o in objects
                        ],
                        dtype=np.float64,
                    )
                    .reshape(len(objects), len(fields))
                    .T
                )
        return _Batch(topic, np.asarray(log_time, dtype=np.int64), fields, values)

    # ------------------------------------------------------------------ linear scan
    def _next_record(self) -> tuple[int, int, bytes | None]:
        """(offset, opcode, body) of the record at the file position; body None if skipped.

        Raises :class:`_Damaged` when the file ends inside the record.
        """
        offset = self._file.tell()
        head = self._file.read(9)
        if len(head) < 9:
            raise _Damaged(
                f"the file ends at byte {self.size} before the end of its data section"
                if not head
                else f"the file ends at byte {self.size} inside a record header"
            )
        opcode, length = _RECORD_HEAD.unpack(head)
        if length > self.size - offset - 9:
            raise _Damaged(
                f"the file ends at byte {self.size} inside a record of {length} bytes "
                f"that starts at byte {offset}"
            )
        if opcode in _SCANNED:
            return offset, opcode, self._file.read(length)
        self._file.seek(length, io.SEEK_CUR)  # message indexes, summary records: not needed
        return offset, opcode, None

    def scan(self, *, index_only: bool = False, start: int = len(_MAGIC)) -> Iterator[tuple]:
        """Records in file order, stopping at the end of the data section or at damage.

        Yields ``("chunk", chunk, messages)`` (``messages`` as from :meth:`walk`),
        ``("message", message)`` for messages outside chunks on wanted channels (all
        channels with ``index_only``), ``("metadata", record)`` and ``("attachment", record)``.
        Schemas and channels are registered on the way. The records are framed here, not by
        :class:`mcap.stream_reader.StreamReader`, which would parse every message-index entry
        field by field in Python; each record body is parsed by :mod:`mcap.records`.
        """
        from mcap.data_stream import ReadDataStream
        from mcap.records import Attachment, Channel, Chunk, Message, Metadata, Schema

        self._file.seek(start)
        while True:
            offset = self._file.tell()
            try:
                offset, opcode, body = self._next_record()
                if body is None:
                    continue
                if opcode in (_OP_DATA_END, _OP_FOOTER):
                    self.complete = True
                    return
                stream = ReadDataStream(io.BytesIO(body))
                if opcode == _OP_CHUNK:
                    record = Chunk.read(stream)
                    walked = self.walk(self.chunk_records(record), index_only=index_only)
                    item = ("chunk", record, walked)
                elif opcode == _OP_MESSAGE:
                    record = Message.read(stream, len(body))
                    if not index_only and record.channel_id not in self._wanted:
                        continue
                    item = ("message", record)
                elif opcode in (_OP_SCHEMA, _OP_CHANNEL):
                    self.register((Schema if opcode == _OP_SCHEMA else Channel).read(stream))
                    continue
                elif opcode == _OP_METADATA:
                    record = Metadata.read(stream)
                    self.metadata[record.name] = record.metadata
                    item = ("metadata", record)
                else:
                    record = Attachment.read(stream)
                    self.attachments.append(record)
                    item = ("attachment", record)
            except _Damaged as exc:
                self.damage = str(exc)
                if "the file ends" not in self.damage:
                    self.damage = f"damaged record at byte {offset}: {exc}"
                return
            except self.errors as exc:
                self.damage = f"damaged record at byte {offset}: {exc or type(exc).__name__}"
                return
            yield item

    def summary(self):
        """The summary section, or None when there is none or it is damaged."""
        from mcap.reader import SeekingReader

        try:
            self.stream.seek(0)
            summary = SeekingReader(self.stream, record_size_limit=self.size).get_summary()
        except (OSError, KeyError, IndexError, *self.errors):
            return None
        if summary is None:
            return None
        if any(ci.chunk_start_offset + ci.chunk_length > self.size for ci in summary.chunk_indexes):
            return None
        return summary

    def read_indexed(self, summary) -> None:
        """Schemas, channels, metadata and attachments through the summary's indexes."""
        from mcap.data_stream import ReadDataStream
        from mcap.records import Attachment, Metadata

        for schema in summary.schemas.values():
            self.register(schema)
        for channel in summary.channels.values():
            self.register(channel)
        for index in [*summary.metadata_indexes, *summary.attachment_indexes]:
            try:
                self._file.seek(index.offset)
                _, opcode, body = self._next_record()
                stream = ReadDataStream(io.BytesIO(body or b""))
                if opcode == _OP_METADATA:
                    record = Metadata.read(stream)
                    self.metadata[record.name] = record.metadata
                elif opcode == _OP_ATTACHMENT:
                    self.attachments.append(Attachment.read(stream))
            except (_Damaged, *self.errors):
                continue  # a damaged label record must not stop the replay of the signals

    def read_chunk(self, chunk_index) -> dict[int, tuple[list, list]]:
        """The chunk at a chunk index entry, walked; raises on damage."""
        from mcap.data_stream import ReadDataStream
        from mcap.records import Chunk

        self._file.seek(chunk_index.chunk_start_offset)
        _, opcode, body = self._next_record()
        if opcode != _OP_CHUNK:
            raise _Damaged("the chunk index points at a record that is not a chunk")
        chunk = Chunk.read(ReadDataStream(io.BytesIO(body)))
        return self.walk(self.chunk_records(chunk))

    # ------------------------------------------------------------------ run parts
    def labels(self) -> dict:
        return {
            k: _decode_metadata_value(v) for k, v in self.metadata.get(LABELS_METADATA, {}).items()
        }

    def info(self) -> dict:
        return self.metadata.get(INFO_METADATA, {})

    def scenario(self) -> dict:
        name = self.info().get("scenario_attachment", "scenario.json")
        for attachment in self.attachments:
            if attachment.name == name:
                try:
                    scenario = json.loads(attachment.data)
                except ValueError:
                    warnings.warn(
                        f"{self.path}: attachment {name} is not valid JSON; scenario left empty",
                        UserWarning,
                        stacklevel=4,
                    )
                    return {}
                return scenario if isinstance(scenario, dict) else {"scenario": scenario}
        return {}

    def no_topics_error(self) -> PRSMHealthError:
        present = sorted({c.topic for c in self.channels.values()})
        where = f" ({self.damage})" if self.damage else ""
        if not present:
            return PRSMHealthError(f"{self.path}: no channels could be read{where}")
        return PRSMHealthError(
            f"{self.path}: none of the topics {', '.join(self.topics)} is in the file; "
            f"topics present: {', '.join(present)}{where}"
        )


def _number(value) -> float:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    return np.nan


def _unchunked_batches(source: _Source, messages: list) -> list[_Batch]:
    grouped: dict[int, tuple[list, list]] = {}
    for message in messages:
        entry = grouped.setdefault(message.channel_id, ([], []))
        entry[0].append(message.log_time)
        entry[1].append(message.data)
    return [source.decode(cid, logs, data) for cid, (logs, data) in grouped.items()]


def _chunk_batches(source: _Source, walked: dict) -> list[_Batch]:
    return [source.decode(cid, logs, data) for cid, (logs, data) in walked.items()]


def _merge_topic(batches: list[_Batch]) -> _Batch:
    fields = []
    for batch in batches:
        fields += [f for f in batch.fields if f not in fields]
    log_time = np.concatenate([b.log_time for b in batches])
    values = np.full((len(fields), len(log_time)), np.nan)
    at = 0
    for batch in batches:
        rows = [fields.index(f) for f in batch.fields]
        values[rows, at : at + len(batch.log_time)] = batch.values
        at += len(batch.log_time)
    return _Batch(batches[0].topic, log_time, fields, values).sorted()


def _align(batches: dict[str, _Batch], *, trim: bool) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Common log-time grid of several topics and each contract channel on it (NaN: no sample).

    With ``trim``, the grid stops at the last time every topic reached (a truncated tail is
    incomplete).
    """
    grids = [b.log_time for b in batches.values()]
    same = all(np.array_equal(grids[0], g) for g in grids[1:])
    grid = grids[0] if same else np.unique(np.concatenate(grids))
    if trim and not same:
        grid = grid[grid <= min(g[-1] for g in grids if len(g))]
    channels = {}
    for topic, batch in batches.items():
        names = dict(TOPIC_FIELDS[topic])
        if same:
            placed = batch.values
        else:
            placed = np.full((len(batch.fields), len(grid)), np.nan)
            keep = batch.log_time <= grid[-1] if len(grid) else np.zeros(0, bool)
            placed[:, np.searchsorted(grid, batch.log_time[keep])] = batch.values[:, keep]
        for row, name in enumerate(batch.fields):
            channels[names[name]] = np.ascontiguousarray(placed[row])
    ordered = {name: channels[name] for name in CHANNEL_NAMES if name in channels}
    return grid, ordered


def _sample_rate(info: dict, grid: np.ndarray, path: Path) -> float:
    try:
        rate = float(info["sample_rate"])
        if rate > 0 and math.isfinite(rate):
            return rate
    except (KeyError, ValueError):
        pass
    if len(grid) > 1:
        step = float(np.median(np.diff(grid)))
        if step > 0:
            return 1e9 / step
    raise PRSMHealthError(f"{path}: cannot tell the sample rate from {len(grid)} sample(s)")


def _start_ns(info: dict, grid: np.ndarray) -> int:
    try:
        return int(info["start_time_ns"])
    except (KeyError, ValueError):
        return int(grid[0]) if len(grid) else 0


def _times(grid: np.ndarray, start_ns: int, rate: float, exact_grid: bool) -> np.ndarray:
    """Sample times [s]; exactly ``arange(n) / rate`` when the log times are that grid."""
    relative = grid - start_ns
    if exact_grid:
        regular = np.arange(len(grid)) / rate
        if np.array_equal(_to_ns(regular), relative):
            return regular
    return relative / 1e9


def read_mcap(path: str | os.PathLike) -> Run:
    """Read a run from an MCAP recording (the inverse of :func:`write_mcap`).

    Reads files with or without a summary section, chunked or not, by scanning the records in
    order. Floats come back exactly; ``time`` is exactly ``arange(n) / sample_rate`` when the
    file was written from such a run, else ``(log_time - start) / 1e9`` [s].

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Run
        Channels of the topics present; labels from the ``labels`` metadata, scenario from its
        attachment, sample rate and energy from the ``prsm_health`` metadata (the sample rate
        is estimated from the log-time spacing when that record is missing).

    Warns
    -----
    TruncatedRecordingWarning
        The file is truncated or damaged (an interrupted recording): the samples before the
        damage are returned, the incomplete tail dropped.

    Raises
    ------
    PRSMHealthError
        Missing, empty or non-MCAP file; no ``/prsm/*`` signal topic; no sample readable.
    """
    with _Source(path) as source:
        per_topic: dict[str, list[_Batch]] = {}
        loose: list = []
        for kind, *rest in source.scan():
            if kind == "chunk":
                for batch in _chunk_batches(source, rest[1]):
                    per_topic.setdefault(batch.topic, []).append(batch)
            elif kind == "message":
                loose.append(rest[0])
        for batch in _unchunked_batches(source, loose):
            per_topic.setdefault(batch.topic, []).append(batch)
        if not source._wanted:
            raise source.no_topics_error()
        batches = {
            topic: _merge_topic(per_topic[topic]) for topic in TOPIC_FIELDS if topic in per_topic
        }
        batches = {t: b for t, b in batches.items() if len(b.log_time) and b.fields}
        if not batches:
            where = f": {source.damage}" if source.damage else ""
            raise PRSMHealthError(f"{source.path}: no samples could be read{where}")
        grid, channels = _align(batches, trim=source.damage is not None)
        info = source.info()
        rate = _sample_rate(info, grid, source.path)
        start = _start_ns(info, grid)
        time = _times(grid, start, rate, exact_grid="sample_rate" in info)
        try:
            energy = json.loads(info.get("energy", "{}"))
        except ValueError:
            energy = {}
        run = Run(time, channels, rate, source.labels(), source.scenario(), energy)
        if source.damage:
            warnings.warn(
                f"{source.path}: {source.damage}; read {len(time)} samples "
                f"({len(time) / rate:.6g} s) before the damage",
                TruncatedRecordingWarning,
                stacklevel=2,
            )
        return run


# =================================================================================== replay
@dataclass(frozen=True, eq=False)
class Window:
    """A fixed-length stretch of a recording, as replayed by :func:`iter_windows`.

    Attributes
    ----------
    index : int
        Window number, from 0.
    start, end : float [s]
        Window span from the run start, ``[start, end)``.
    start_ns, end_ns : int [ns]
        The same span in log time (for messages written about this window).
    time : ndarray [s]
        Sample times from the run start.
    channels : dict of name → ndarray
        Contract channels, SI; NaN where a topic has no sample at a time another has.
    labels : dict
        Run labels of the recording.
    sample_rate : float [Hz]
    """

    index: int
    start: float
    end: float
    start_ns: int
    end_ns: int
    time: np.ndarray
    channels: dict[str, np.ndarray]
    labels: dict = field(default_factory=dict)
    sample_rate: float = 0.0

    def __len__(self) -> int:
        return len(self.time)

    def __getitem__(self, name: str) -> np.ndarray:
        return lookup_channel(self.time, self.channels, name)


class _TopicBuffer:
    """Buffered samples of one topic, consumed from the front."""

    def __init__(self, topic: str):
        self.topic = topic
        self.log_time = np.zeros(0, dtype=np.int64)
        self.fields: list[str] = []
        self.values = np.zeros((0, 0))

    def __len__(self) -> int:
        return len(self.log_time)

    def append(self, batch: _Batch) -> None:
        """Add samples, keeping the buffer in log-time order."""
        if not len(self):
            self.log_time, self.fields, self.values = batch.log_time, batch.fields, batch.values
            return
        if batch.fields != self.fields or batch.log_time[0] < self.log_time[-1]:
            merged = _merge_topic([self.as_batch(), batch])
            self.log_time, self.fields, self.values = merged.log_time, merged.fields, merged.values
            return
        self.log_time = np.concatenate([self.log_time, batch.log_time])
        self.values = np.concatenate([self.values, batch.values], axis=1)

    def as_batch(self) -> _Batch:
        return _Batch(self.topic, self.log_time, list(self.fields), self.values)

    def take(self, start: int, end: int, drop_before: int) -> _Batch:
        """Samples in ``[start, end)``; forget those before ``drop_before``."""
        a, b = np.searchsorted(self.log_time, [start, end])
        out = _Batch(self.topic, self.log_time[a:b], list(self.fields), self.values[:, a:b])
        keep = int(np.searchsorted(self.log_time, drop_before))
        self.log_time = self.log_time[keep:]
        self.values = self.values[:, keep:]
        return out


def _require_positive(name: str, value, unit: str) -> None:
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not (ok and 0 < value < math.inf):
        raise PRSMHealthError(f"{name} = {value!r} must be a finite number > 0 {unit}")


class WindowStream(Iterator[Window]):
    """Iterator of :class:`Window` over an MCAP recording (see :func:`iter_windows`).

    Attributes
    ----------
    peak_buffered : int
        Largest number of samples of one topic held at once: the unfinished window plus the
        chunk just decoded — not the file.
    late_samples : int
        Samples dropped because they arrived after their window was emitted (only possible
        in files without a summary whose messages are out of log-time order).
    """

    def __init__(self, path, window, *, step=None, rate=None, topics=None, partial=False):
        _require_positive("window", window, "[s]")
        step = window if step is None else step
        _require_positive("step", step, "[s]")
        if rate is not None:
            _require_positive("rate", rate, "(or None)")
        topics = tuple(
            TOPIC_FIELDS if topics is None else ([topics] if isinstance(topics, str) else topics)
        )
        unknown = [t for t in topics if t not in TOPIC_FIELDS]
        if unknown or not topics:
            raise PRSMHealthError(
                f"cannot replay topics {unknown or list(topics)}; signal topics are "
                f"{', '.join(TOPIC_FIELDS)}"
            )
        self.window_ns = int(round(window * 1e9))
        self.step_ns = int(round(step * 1e9))
        if self.window_ns < 1 or self.step_ns < 1:
            raise PRSMHealthError("window and step must be at least 1 ns")
        self.rate = rate
        self.partial = partial
        self.peak_buffered = 0
        self.late_samples = 0
        self._source = _Source(path, topics)
        self._buffers = {t: _TopicBuffer(t) for t in topics}
        self._index = 0
        self._origin: int | None = None  # log time of the run start
        self._first: int | None = None  # log time of window 0
        self._emitted_until: int | None = None
        self._wall0 = 0.0
        self._rate_hz: float | None = None
        self._windows = self._generate()

    def __next__(self) -> Window:
        return next(self._windows)

    def close(self) -> None:
        """Stop early and release the file."""
        self._windows.close()
        self._source.close()

    # ------------------------------------------------------------------ batches in time order
    def _batches(self) -> Iterator[list[_Batch]]:
        source = self._source
        summary = source.summary()
        if summary is not None and summary.chunk_indexes:
            source.read_indexed(summary)
            if not source._wanted:
                raise source.no_topics_error()
            yield from self._indexed_batches(summary)
        else:
            loose: list = []
            for kind, *rest in source.scan():
                if kind == "chunk":
                    yield [b.sorted() for b in _chunk_batches(source, rest[1])]
                elif kind == "message":
                    loose.append(rest[0])
                    if len(loose) >= 4096:
                        yield [b.sorted() for b in _unchunked_batches(source, loose)]
                        loose = []
            if loose:
                yield [b.sorted() for b in _unchunked_batches(source, loose)]
            if not source._wanted:
                raise source.no_topics_error()
        if source.damage:
            warnings.warn(
                f"{source.path}: {source.damage}; replay stopped there",
                TruncatedRecordingWarning,
                stacklevel=3,
            )

    def _indexed_batches(self, summary) -> Iterator[list[_Batch]]:
        """Chunks in start-time order; messages released once no later chunk can precede them.

        The same rule as mcap's log-time-order reader, applied to whole decoded chunks, so
        overlapping chunks (e.g. a diagnosis appended after the signals) stay in order.
        """
        source = self._source
        wanted = set(source._wanted)
        chunks = [
            ci
            for ci in summary.chunk_indexes
            if not ci.message_index_offsets or wanted.intersection(ci.message_index_offsets)
        ]
        chunks.sort(key=lambda ci: (ci.message_start_time, ci.chunk_start_offset))
        pending: dict[str, list[_Batch]] = {}
        for k, chunk_index in enumerate(chunks):
            try:
                walked = source.read_chunk(chunk_index)
            except (_Damaged, *source.errors) as exc:
                source.damage = f"damaged chunk at byte {chunk_index.chunk_start_offset}: {exc}"
                break
            for batch in _chunk_batches(source, walked):
                pending.setdefault(batch.topic, []).append(batch)
            bound = chunks[k + 1].message_start_time if k + 1 < len(chunks) else None
            ready = []
            for topic, batches in pending.items():
                merged = _merge_topic(batches)
                if bound is None:
                    cut = len(merged.log_time)
                else:
                    cut = int(np.searchsorted(merged.log_time, bound))
                ready.append(
                    _Batch(topic, merged.log_time[:cut], merged.fields, merged.values[:, :cut])
                )
                pending[topic] = [
                    _Batch(topic, merged.log_time[cut:], merged.fields, merged.values[:, cut:])
                ]
            yield ready
        else:
            return
        # Damage: release what was read so far.
        yield [_merge_topic(b) for b in pending.values() if b]

    # ------------------------------------------------------------------ windows
    def _generate(self) -> Iterator[Window]:
        try:
            for batches in self._batches():
                for batch in batches:
                    if not len(batch.log_time) or not batch.fields:
                        continue
                    self._start(batch)
                    buffer = self._buffers[batch.topic]
                    if self._emitted_until is not None:
                        late = batch.log_time < self._emitted_until
                        if late.any():
                            self.late_samples += int(late.sum())
                            batch = _Batch(
                                batch.topic,
                                batch.log_time[~late],
                                batch.fields,
                                batch.values[:, ~late],
                            )
                    buffer.append(batch)
                self._note_buffered()
                yield from self._ready(final=False)
            yield from self._ready(final=True)
            if self._first is None and not any(len(b) for b in self._buffers.values()):
                where = f": {self._source.damage}" if self._source.damage else ""
                raise PRSMHealthError(f"{self._source.path}: no samples could be read{where}")
        finally:
            self._source.close()
        if self.late_samples:
            warnings.warn(
                f"{self._source.path}: {self.late_samples} samples arrived after their window "
                "(messages out of log-time order in a file without a summary) and were dropped",
                UserWarning,
                stacklevel=2,
            )

    def _start(self, batch: _Batch) -> None:
        if self._first is not None:
            return
        info = self._source.info()
        self._origin = _start_ns(info, batch.log_time)
        self._first = min(self._origin, int(batch.log_time[0]))
        try:
            self._rate_hz = _sample_rate(info, batch.log_time, self._source.path)
        except PRSMHealthError:
            self._rate_hz = None
        self._wall0 = _time.monotonic()

    def _note_buffered(self) -> None:
        held = max(len(b) for b in self._buffers.values())
        self.peak_buffered = max(self.peak_buffered, held)

    def _ready(self, *, final: bool) -> Iterator[Window]:
        if self._first is None:
            return
        declared = set(self._source._wanted.values()) & set(self._buffers)
        # A window is complete once its last sample is in: a sample at most one sample period
        # (+1 ns of log-time rounding) before its end.
        period = 1e9 / self._rate_hz if self._rate_hz else 0.0
        while True:
            start = self._first + self._index * self.step_ns
            end = start + self.window_ns
            newest = {t: int(b.log_time[-1]) for t, b in self._buffers.items() if len(b)}
            if not newest:
                return
            latest = max(newest.values())
            if latest < start:
                return
            reached = end - period - 1
            if final:
                if latest < reached and not self.partial:
                    return
            elif any(newest.get(t, -1) < reached for t in declared):
                # A topic that stopped must not make the others pile up: wait at most one
                # window beyond the end.
                if latest < end + self.window_ns:
                    return
            parts = {
                t: b.take(start, end, start + self.step_ns)
                for t, b in self._buffers.items()
                if len(b)
            }
            self._emitted_until = start + self.step_ns
            self._index += 1
            parts = {t: p for t, p in parts.items() if len(p.log_time)}
            if not parts:
                continue
            grid, channels = _align(parts, trim=False)
            rate = self._rate_hz
            if rate is None:
                rate = 1e9 / float(np.median(np.diff(grid))) if len(grid) > 1 else 0.0
            self._pace(end)
            yield Window(
                index=self._index - 1,
                start=(start - self._origin) / 1e9,
                end=(end - self._origin) / 1e9,
                start_ns=start,
                end_ns=end,
                time=(grid - self._origin) / 1e9,
                channels=channels,
                labels=self._source.labels(),
                sample_rate=rate,
            )

    def _pace(self, end_ns: int) -> None:
        if self.rate is None:
            return
        due = self._wall0 + (end_ns - self._first) / 1e9 / self.rate
        now = _time.monotonic()
        if due > now:
            _time.sleep(due - now)


def iter_windows(
    path: str | os.PathLike,
    window: float,
    *,
    step: float | None = None,
    rate: float | None = None,
    topics: Iterable[str] | None = None,
    partial: bool = False,
) -> WindowStream:
    """Replay a recording as fixed-length windows, streaming (never the whole file in memory).

    Parameters
    ----------
    path : str or path-like
        MCAP recording (with or without summary; a damaged tail ends the replay with a
        :class:`TruncatedRecordingWarning`).
    window : float [s]
        Window length; window ``k`` spans ``[t0 + k·step, t0 + k·step + window)`` in log time,
        ``t0`` the run start.
    step : float [s], optional
        Hop between window starts (default ``window``: contiguous, no overlap).
    rate : float, optional
        Real-time factor: windows are released as log time advances ``rate`` times faster than
        wall time (``1`` = real time). None: as fast as possible.
    topics : iterable of str, optional
        Signal topics to replay (default both, :data:`TOPIC_NUT_ACCEL` and :data:`TOPIC_DRIVE`).
    partial : bool
        Also yield the last, incomplete window.

    Returns
    -------
    WindowStream
        Iterator of :class:`Window` in log-time order; its ``peak_buffered`` attribute reports
        the most samples held at once.

    Raises
    ------
    PRSMHealthError
        Bad parameters or a file that is missing or not MCAP (at the call); none of the
        topics or no sample in the file (when iteration starts).
    """
    return WindowStream(path, window, step=step, rate=rate, topics=topics, partial=partial)


def window_statistics(window: Window) -> dict[str, dict[str, float]]:
    """Classic indicators of each channel of a window, NaN samples ignored.

    Parameters
    ----------
    window : Window

    Returns
    -------
    dict
        Channel → ``{"mean", "rms", "peak", "crest_factor"}`` in the channel's unit (crest
        factor dimensionless): mean, root mean square and largest absolute value of the raw
        signal (mean included), and peak / rms (NaN when rms is 0 or no sample is finite).
    """
    out = {}
    for name, values in window.channels.items():
        x = np.asarray(values, dtype=np.float64)
        x = x[np.isfinite(x)]
        if len(x) == 0:
            out[name] = dict.fromkeys(("mean", "rms", "peak", "crest_factor"), math.nan)
            continue
        rms = float(np.sqrt(np.mean(x * x)))
        peak = float(np.max(np.abs(x)))
        out[name] = {
            "mean": float(np.mean(x)),
            "rms": rms,
            "peak": peak,
            "crest_factor": peak / rms if rms > 0 else math.nan,
        }
    return out


# ================================================================================ diagnosis
_DIAGNOSIS_UNITS = {"estimate": "m", "lower": "m", "upper": "m"}


def _infer_schema(value, key: str | None = None, parent: str | None = None) -> dict:
    if isinstance(value, dict):
        return {
            "type": "object",
            "properties": {str(k): _infer_schema(v, str(k), key) for k, v in value.items()},
        }
    if isinstance(value, bool | np.bool_):
        return {"type": "boolean"}
    if isinstance(value, (int, float, np.integer, np.floating)):
        schema = {"type": "number"}
        if parent == "clearance" and key in _DIAGNOSIS_UNITS:
            schema["description"] = f"clearance {key} [{_DIAGNOSIS_UNITS[key]}]"
        return schema
    if isinstance(value, str):
        return {"type": "string"}
    if isinstance(value, (list, tuple, np.ndarray)):
        return {"type": "array"}
    return {}


def _finite_or_none(value):
    """JSON-ready copy: numpy → Python, non-finite floats → None (JSON has no NaN)."""
    if isinstance(value, dict):
        return {str(k): _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_or_none(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_finite_or_none(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


class DiagnosisWriter:
    """Copy a recording and add diagnosis messages to it, one at a time.

    The source's schemas, channels, metadata, attachments and chunks are copied unchanged
    (chunks without recompression); each :meth:`add` appends one JSON message on ``topic``
    (on the source's channel of that topic if it has one, else on a new channel). The
    destination is written atomically on :meth:`close` (a context manager closes it; an
    exception inside the ``with`` block discards it).

    Parameters
    ----------
    src, dst : str or path-like
        Source recording and destination (may be the same path).
    topic : str
        Diagnosis topic.
    schema : dict, optional
        JSON schema of the diagnosis messages; default inferred from the first message
        (nested objects allowed, clearance fields documented in m).
    chunk_size : int [bytes]
        Uncompressed size of the diagnosis chunks.

    Warns
    -----
    TruncatedRecordingWarning
        The source is damaged; what precedes the damage is copied.
    """

    def __init__(
        self,
        src: str | os.PathLike,
        dst: str | os.PathLike,
        *,
        topic: str = TOPIC_DIAGNOSIS,
        schema: dict | None = None,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
    ):
        self.topic = topic
        self._schema = schema
        self._channel_id: int | None = None
        self._pending: list[tuple[int, bytes]] = []
        self._pending_bytes = 0
        self._chunk_size = int(chunk_size)
        self._sequence = 0
        self._closed = False
        self._target = _AtomicFile(Path(dst))
        try:
            self._writer = _FileWriter(self._target.stream, chunk_size=chunk_size)
            self._writer.start(_library())
            self._copy(src)
        except BaseException:
            self._target.abort()
            raise

    def _copy(self, src) -> None:
        writer = self._writer
        with _Source(src, topics=()) as source:
            loose = []
            done = set()
            for kind, *rest in source.scan(index_only=True):
                self._sync_definitions(source, done)
                if kind == "chunk":
                    chunk, walked = rest
                    if walked:
                        index = {
                            cid: (np.asarray(logs, np.uint64), np.asarray(offs, np.int64))
                            for cid, (logs, offs) in walked.items()
                        }
                        writer._write_chunk(
                            b"",
                            index,
                            chunk.message_start_time,
                            chunk.message_end_time,
                            compressed=(
                                chunk.compression,
                                chunk.data,
                                chunk.uncompressed_size,
                                chunk.uncompressed_crc,
                            ),
                        )
                elif kind == "message":
                    loose.append(rest[0])
                elif kind == "metadata":
                    writer.add_metadata(rest[0].name, rest[0].metadata)
                elif kind == "attachment":
                    a = rest[0]
                    writer.add_attachment(
                        a.name, a.media_type, a.data, log_time=a.log_time, create_time=a.create_time
                    )
            self._sync_definitions(source, done)
            if loose:
                writer.add_messages(
                    _MessageBlock.from_payloads(
                        [m.channel_id for m in loose],
                        [m.sequence for m in loose],
                        [m.log_time for m in loose],
                        [m.publish_time for m in loose],
                        [m.data for m in loose],
                    )
                )
            if source.damage:
                warnings.warn(
                    f"{source.path}: {source.damage}; copied what precedes it",
                    TruncatedRecordingWarning,
                    stacklevel=3,
                )

    def _sync_definitions(self, source: _Source, done: set) -> None:
        for sid, schema in source.schemas.items():
            if ("s", sid) not in done:
                self._writer.add_schema(schema.name, schema.encoding, schema.data, schema_id=sid)
                done.add(("s", sid))
        for cid, channel in source.channels.items():
            if ("c", cid) not in done:
                self._writer.add_channel(
                    channel.topic,
                    channel.message_encoding,
                    channel.schema_id,
                    channel.metadata,
                    channel_id=cid,
                )
                done.add(("c", cid))

    def _register(self, example: dict | None) -> None:
        for channel in self._writer.channels.values():
            if channel.topic == self.topic and channel.message_encoding == "json":
                # Diagnosing a diagnosed file again: one channel per topic, as Foxglove expects.
                self._channel_id = channel.id
                return
        schema = self._schema
        if schema is None:
            schema = _infer_schema(example) if example is not None else {"type": "object"}
            schema = {
                "$schema": "http://json-schema.org/draft-07/schema#",
                "title": "prsm_health.Diagnosis",
                "description": "Diagnosis of the preceding window (SI units)",
                **schema,
            }
        schema_id = self._writer.add_schema(
            "prsm_health.Diagnosis", "jsonschema", json.dumps(schema, indent=2).encode()
        )
        self._channel_id = self._writer.add_channel(self.topic, "json", schema_id)

    def add(self, log_time_ns: int, diagnosis: dict) -> None:
        """Append one diagnosis message.

        Parameters
        ----------
        log_time_ns : int [ns]
            Log time of the message (e.g. the end of the diagnosed window, ``Window.end_ns``).
        diagnosis : dict
            JSON-serialisable (numpy values allowed; NaN/inf are written as null).
        """
        if self._closed:
            raise PRSMHealthError("DiagnosisWriter is closed")
        if not isinstance(log_time_ns, (int, np.integer)) or not 0 <= log_time_ns < 2**64:
            raise PRSMHealthError(f"log_time_ns = {log_time_ns!r} must be an integer >= 0 [ns]")
        if not isinstance(diagnosis, dict):
            raise PRSMHealthError(f"diagnosis must be a dict, not {type(diagnosis).__name__}")
        if self._channel_id is None:
            self._register(diagnosis)
        try:
            payload = json.dumps(
                _finite_or_none(diagnosis), separators=(",", ":"), allow_nan=False
            ).encode()
        except TypeError as exc:
            raise PRSMHealthError(f"diagnosis is not JSON-serialisable: {exc}") from None
        self._pending.append((int(log_time_ns), payload))
        self._pending_bytes += len(payload) + _HEADER_SIZE
        if self._pending_bytes >= self._chunk_size:
            self._flush()

    def _flush(self) -> None:
        if not self._pending:
            return
        n = len(self._pending)
        log_time = [t for t, _ in self._pending]
        self._writer.add_messages(
            _MessageBlock.from_payloads(
                np.full(n, self._channel_id),
                np.arange(self._sequence, self._sequence + n),
                log_time,
                log_time,
                [p for _, p in self._pending],
            )
        )
        self._sequence += n
        self._pending = []
        self._pending_bytes = 0

    def close(self) -> Path:
        """Finish the file and move it onto ``dst``."""
        if self._closed:
            return self._target.path
        try:
            if self._channel_id is None:
                self._register(None)
            self._flush()
            self._writer.finish()
        except BaseException:
            self._target.abort()
            raise
        finally:
            self._closed = True
        return self._target.commit()

    def abort(self) -> None:
        """Discard the output."""
        if not self._closed:
            self._closed = True
            self._target.abort()

    def __enter__(self) -> DiagnosisWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def write_diagnosis_mcap(
    src: str | os.PathLike,
    dst: str | os.PathLike,
    diagnoses: Iterable[tuple[int, dict]],
    *,
    topic: str = TOPIC_DIAGNOSIS,
    schema: dict | None = None,
) -> Path:
    """Copy ``src`` to ``dst`` with diagnosis messages added on ``topic``.

    Parameters
    ----------
    src, dst : str or path-like
    diagnoses : iterable of (int [ns], dict)
        Log time and diagnosis (e.g. the Diagnosis contract dict) of each message.
    topic : str
    schema : dict, optional
        See :class:`DiagnosisWriter`.

    Returns
    -------
    Path
        ``dst``.
    """
    with DiagnosisWriter(src, dst, topic=topic, schema=schema) as writer:
        for log_time_ns, diagnosis in diagnoses:
            writer.add(log_time_ns, diagnosis)
    return writer._target.path
