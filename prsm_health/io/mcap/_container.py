"""The hand-framed MCAP container writer (private: use :func:`~prsm_health.io.mcap.write_mcap` and
:class:`~prsm_health.io.mcap.DiagnosisWriter`).

The per-message work — record headers and message indexes — is assembled with numpy rather
than one :meth:`mcap.writer.Writer.add_message` call per message (see tools/bench/bench_mcap.py); the
record classes of :mod:`mcap.records` serialise every other record, and the summary section
follows what :meth:`mcap.writer.Writer.finish` writes. Files are written atomically
(:class:`_AtomicFile`).
"""

from __future__ import annotations

import os
import secrets
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError

from ._framing import _MAGIC, _OP_MESSAGE, _OP_MESSAGE_INDEX

#: Default uncompressed chunk size [bytes]: about 10 000 messages, 0.25 s of a 20 kHz run.
DEFAULT_CHUNK_SIZE = 1 << 20

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
# library default (3), measured on 2 s of 20 kHz signals (tools/bench/bench_mcap.py).
_ZSTD_LEVEL = 1


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

    def copy_chunk(self, chunk, messages: dict[int, tuple[list, list]]) -> None:
        """Copy an existing :class:`mcap.records.Chunk` as is (no recompression).

        ``messages``: per channel id, the log times and record offsets of the chunk's messages
        (as :meth:`~._scan._Source.walk` gives them with ``index_only``), for its message
        indexes.
        """
        index = {
            cid: (np.asarray(logs, np.uint64), np.asarray(offsets, np.int64))
            for cid, (logs, offsets) in messages.items()
        }
        self._write_chunk(
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
    """The Header record's library field: this package and the mcap library, with versions."""
    from mcap.writer import LIBRARY_IDENTIFIER

    from prsm_health.core.version import __version__

    return f"prsm_health/{__version__}; {LIBRARY_IDENTIFIER}"
