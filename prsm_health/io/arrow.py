"""One run as an Arrow IPC stream (``application/vnd.apache.arrow.stream``): the same columns
and schema metadata as the single-run Parquet file (:mod:`prsm_health.io.parquet`) — ``time``
[s], the measured channels, optionally ``truth_<name>`` — without the Parquet encoding, so a
client sends a recording in a few copies of memory (``pyarrow.ipc.new_stream``, or polars'
``DataFrame.write_ipc_stream``).

:func:`arrow_stream_sizes` reads what a stream declares (rows, decompressed bytes, columns)
from its message headers without decompressing or materialising anything, so a caller can
refuse a small compressed stream that would inflate past its limits (the service does, before
:func:`read_run_arrow`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run

from .columns import run_from_table, run_table

#: Media type of an Arrow IPC stream (IANA registration).
ARROW_STREAM_MEDIA_TYPE = "application/vnd.apache.arrow.stream"


def write_run_arrow(run: Run, path: str | Path | None = None, *, compression: str | None = None):
    """``run`` as an Arrow IPC stream: the bytes, or written to ``path`` (returns the path).

    Columns and schema metadata are those of :func:`~prsm_health.io.parquet.write_run_parquet`
    (``time``, channels, ``truth_<name>``; units, sample rate, labels, scenario, operating
    point).
    ``compression``: None, ``"zstd"`` or ``"lz4"`` (Arrow IPC buffer compression).
    """
    import pyarrow as pa

    table = run_table(run)
    sink = pa.BufferOutputStream()
    options = pa.ipc.IpcWriteOptions(compression=compression)
    with pa.ipc.new_stream(sink, table.schema, options=options) as writer:
        writer.write_table(table)
    data = sink.getvalue().to_pybytes()
    if path is None:
        return data
    path = Path(path)
    tmp = path.with_name(path.name + ".partial")
    tmp.write_bytes(data)
    tmp.replace(path)
    return path


@dataclass(frozen=True)
class StreamSizes:
    """What an Arrow IPC stream declares, read from its message headers.

    Attributes
    ----------
    rows : int
        Rows of all record batches (samples).
    decoded_bytes : int
        Bytes the record batches' buffers take once decompressed (compressed buffers: the
        length each announces; uncompressed ones: their length).
    columns : int
        Columns of the schema.
    """

    rows: int
    decoded_bytes: int
    columns: int


def arrow_stream_sizes(data, name: str = "recording") -> StreamSizes:
    """Rows, decompressed size and columns an Arrow IPC stream declares, without decompressing
    or decoding any record batch (each message's flatbuffer header is read directly).

    Raises
    ------
    PRSMHealthError
        Not an Arrow IPC stream, a damaged or cut message, a dictionary-encoded column.
    """
    import pyarrow as pa

    try:
        reader = pa.ipc.MessageReader.open_stream(pa.BufferReader(pa.py_buffer(data)))
        rows = decoded = 0
        columns = None
        while True:
            try:
                message = reader.read_next_message()
            except StopIteration:
                break
            kind = message.type
            if kind == "schema":
                columns = len(pa.ipc.read_schema(message))
            elif kind == "record batch":
                if columns is None:
                    raise PRSMHealthError(
                        f"{name}: Arrow IPC stream with a record batch before its schema"
                    )
                length, buffers, compressed = _record_batch_header(memoryview(message.metadata))
                rows += length
                decoded += _decoded_bytes(buffers, compressed, message.body)
            elif kind == "dictionary":
                raise PRSMHealthError(
                    f"{name}: dictionary-encoded Arrow columns are not accepted (send numbers)"
                )
            else:
                raise PRSMHealthError(f"{name}: unexpected Arrow IPC message {kind!r}")
    except PRSMHealthError:
        raise
    except (pa.ArrowException, OSError, ValueError, struct.error, IndexError) as exc:
        raise PRSMHealthError(f"{name}: not a readable Arrow IPC stream ({_short(exc)})") from None
    if columns is None:
        raise PRSMHealthError(f"{name}: not an Arrow IPC stream (no schema message)")
    return StreamSizes(rows, decoded, columns)


def read_run_arrow(data, name: str = "recording") -> Run:
    """Read a run from an Arrow IPC stream (bytes or a buffer; the inverse of
    :func:`write_run_arrow`): a ``time`` column [s] and measured channel columns, as the
    Parquet reader; ``truth_<name>`` columns go to ``Run.truth``. ``name`` names the stream in
    messages. The sample rate is the ``prsm_health.sample_rate`` schema metadata, else
    1/(median time step).

    Check :func:`arrow_stream_sizes` first when the stream comes from someone else: this
    decompresses and decodes every record batch.
    """
    import pyarrow as pa

    try:
        with pa.ipc.open_stream(pa.py_buffer(data)) as reader:
            table = reader.read_all()
    except (pa.ArrowException, OSError, ValueError) as exc:
        raise PRSMHealthError(f"{name}: not a readable Arrow IPC stream ({_short(exc)})") from None
    return run_from_table(table, name)


# ----------------------------------------------------------------------------- flatbuffers
# The Arrow IPC message header (format/Message.fbs) is a flatbuffer; the few fields the size
# check needs are read here directly rather than through a flatbuffers dependency.
_U8, _I16, _U16, _I32, _U32, _I64 = (struct.Struct(f"<{c}") for c in "BhHiIq")
_HEADER_RECORD_BATCH = 3  # MessageHeader union: Schema 1, DictionaryBatch 2, RecordBatch 3


def _table(buf: memoryview, pos: int) -> tuple[int, int, int]:
    """(table position, vtable position, vtable size) of the table at ``pos``."""
    vtable = pos - _I32.unpack_from(buf, pos)[0]
    return pos, vtable, _U16.unpack_from(buf, vtable)[0]


def _field(buf: memoryview, table: tuple[int, int, int], index: int) -> int | None:
    """Absolute position of field ``index`` of a table, None when absent."""
    pos, vtable, size = table
    slot = 4 + 2 * index
    if slot + 2 > size:
        return None
    offset = _U16.unpack_from(buf, vtable + slot)[0]
    return pos + offset if offset else None


def _deref(buf: memoryview, at: int) -> int:
    return at + _U32.unpack_from(buf, at)[0]


def _record_batch_header(buf: memoryview) -> tuple[int, list[tuple[int, int]], bool]:
    """(length, [(buffer offset, buffer length), ...], compressed) of a record-batch message
    header."""
    message = _table(buf, _U32.unpack_from(buf, 0)[0])
    kind = _field(buf, message, 1)
    if kind is None or _U8.unpack_from(buf, kind)[0] != _HEADER_RECORD_BATCH:
        raise ValueError("message header is not a record batch")
    header = _field(buf, message, 2)
    if header is None:
        raise ValueError("record batch without header")
    batch = _table(buf, _deref(buf, header))
    at = _field(buf, batch, 0)
    length = _I64.unpack_from(buf, at)[0] if at is not None else 0
    buffers: list[tuple[int, int]] = []
    at = _field(buf, batch, 2)
    if at is not None:
        vector = _deref(buf, at)
        count = _U32.unpack_from(buf, vector)[0]
        if vector + 4 + 16 * count > len(buf):
            raise ValueError("buffer list runs past the message header")
        for i in range(count):
            offset = _I64.unpack_from(buf, vector + 4 + 16 * i)[0]
            size = _I64.unpack_from(buf, vector + 12 + 16 * i)[0]
            buffers.append((offset, size))
    if length < 0:
        raise ValueError(f"negative record batch length {length}")
    return length, buffers, _field(buf, batch, 3) is not None


def _decoded_bytes(buffers: list[tuple[int, int]], compressed: bool, body) -> int:
    """Bytes the buffers take decompressed. Uncompressed: their lengths. Compressed: each
    non-empty buffer starts with the int64 length it inflates to (-1: stored uncompressed)."""
    view = memoryview(body) if body is not None else memoryview(b"")
    total = 0
    for offset, size in buffers:
        if size < 0 or offset < 0 or offset + size > len(view):
            raise ValueError("buffer outside the message body")
        if not compressed or size == 0:
            total += size
            continue
        if size < 8:
            raise ValueError("compressed buffer shorter than its length prefix")
        announced = _I64.unpack_from(view, offset)[0]
        if announced < -1:
            raise ValueError(f"compressed buffer announces {announced} bytes")
        total += size - 8 if announced == -1 else announced
    return total


def _short(exc: Exception) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__
