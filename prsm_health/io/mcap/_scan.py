"""The tolerant low-level MCAP scanner (private): :class:`_Source` frames the records itself,
stops at the first damaged or missing byte and says where (:attr:`_Source.damage`), keeping
everything before it usable — an interrupted recording still replays up to the interruption.

Record bodies are parsed by :mod:`mcap.records`; message payloads of the signal topics are
decoded into :class:`~._samples._Batch` es, one per channel and chunk.
"""

from __future__ import annotations

import io
import json
import os
import struct
import warnings
import zlib
from collections.abc import Iterable, Iterator
from operator import itemgetter
from pathlib import Path

import numpy as np

from prsm_health.core.channels import TOPIC_FIELDS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.operating_point import OPERATING_METADATA, OperatingPoint

from ._framing import (
    _MAGIC,
    _OP_ATTACHMENT,
    _OP_CHANNEL,
    _OP_CHUNK,
    _OP_DATA_END,
    _OP_FOOTER,
    _OP_MESSAGE,
    _OP_METADATA,
    _OP_SCHEMA,
)
from ._samples import _Batch
from .schema import INFO_METADATA, LABELS_METADATA, decode_metadata_value

# Records the scan parses; the others (message indexes, summary records) are skipped.
_SCANNED = frozenset(
    (_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK)
    + (_OP_ATTACHMENT, _OP_METADATA, _OP_DATA_END)
)


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
    """Damaged or missing bytes; the message says what (the caller adds where)."""


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
        self.wanted: dict[int, str] = {}  # channel id → signal topic, for the topics asked for
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
                self.wanted[record.id] = record.topic
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
        wanted = self.wanted
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
        topic = self.wanted[channel_id]
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
                    if not index_only and record.channel_id not in self.wanted:
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
            k: decode_metadata_value(v) for k, v in self.metadata.get(LABELS_METADATA, {}).items()
        }

    def operating(self) -> OperatingPoint:
        """The ``operating`` record; a file written before it: read from the labels."""
        if OPERATING_METADATA not in self.metadata:
            return OperatingPoint.from_labels(self.labels())
        record = self.metadata[OPERATING_METADATA]
        return OperatingPoint.from_labels({k: decode_metadata_value(v) for k, v in record.items()})

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
    """A JSON number as a float; anything else (null, strings, booleans) as NaN."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    return np.nan


def _unchunked_batches(source: _Source, messages: list) -> list[_Batch]:
    """Messages found outside chunks, decoded per channel."""
    grouped: dict[int, tuple[list, list]] = {}
    for message in messages:
        entry = grouped.setdefault(message.channel_id, ([], []))
        entry[0].append(message.log_time)
        entry[1].append(message.data)
    return [source.decode(cid, logs, data) for cid, (logs, data) in grouped.items()]


def _chunk_batches(source: _Source, walked: dict) -> list[_Batch]:
    """The messages of a walked chunk, decoded per channel."""
    return [source.decode(cid, logs, data) for cid, (logs, data) in walked.items()]
