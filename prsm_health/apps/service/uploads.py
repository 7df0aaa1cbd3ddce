"""Uploaded recordings: the multipart body streamed to a private temporary directory
(:func:`receive_upload`) — the recording (``file``: MCAP, Parquet or CSV), an optional column
map (``map``: TOML, held in memory) and the ``asset_id`` — and checks of a file's metadata
before the library decodes it (:func:`precheck_upload`)."""

from __future__ import annotations

import contextlib
import mmap
import os
import re
import struct
import tempfile
from dataclasses import dataclass
from pathlib import Path

import anyio
from python_multipart.multipart import MultipartParser, parse_options_header
from starlette.requests import Request

from prsm_health.core.channels import UNITS
from prsm_health.core.errors import PRSMHealthError

from .limits import ServiceLimits
from .responses import HTTPError
from .schemas import ASSET_ID_PATTERN, RECORDING_ID_PATTERN

UPLOAD_SUFFIXES = (".mcap", ".parquet", ".csv")
#: Largest column map (the ``map`` field) accepted [bytes]: a map is a few hundred bytes.
MAX_MAP_BYTES = 64 * 1024
#: Largest plain form field (``asset_id``, ``healthy``, ``recording_id``,
#: ``operating_hours``) [bytes].
MAX_FIELD_BYTES = 1024


def precheck_upload(path: Path, suffix: str, limits: ServiceLimits) -> None:
    """Refuse uploads whose metadata already announce more than the limits allow, before the
    library decodes them (a small compressed file can inflate to gigabytes)."""
    precheck_recording(
        path,
        suffix.lstrip("."),
        max_samples=limits.max_upload_samples,
        max_decoded_bytes=limits.max_upload_decoded_bytes,
    )


def precheck_recording(
    source: Path | bytes,
    fmt: str,
    *,
    max_samples: int,
    max_decoded_bytes: int,
    samples_hint: str = "",
    decoded_hint: str = "",
    name: str = "recording",
) -> None:
    """Refuse a recording (a file, or a body in memory) whose metadata already announce more
    than ``max_samples`` rows or ``max_decoded_bytes`` decompressed (413), or an implausible
    number of columns (422), before anything is decompressed or decoded. ``fmt``:
    ``"parquet"`` (footer: rows, row-group sizes), ``"mcap"`` (chunk headers: uncompressed
    sizes), ``"arrow"`` (message headers: rows, buffer sizes), ``"csv"`` (lines and header
    fields: rows × columns float64 values). The hints end the messages
    (which limit, what to do). A body the metadata cannot be read from is left to the reader,
    which reports it with its own message — except an Arrow stream, whose headers are the
    reader's first step (422 here; ``name`` names the recording)."""
    rows = None
    columns = 0
    if fmt == "parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq

            meta = pq.read_metadata(source if isinstance(source, Path) else pa.BufferReader(source))
        except Exception:
            return  # not readable: the library's reader reports it with its own message
        decoded = sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
        rows, columns, kind = meta.num_rows, meta.num_columns, "Parquet file"
    elif fmt == "arrow":
        from prsm_health.io.arrow import arrow_stream_sizes

        try:
            data = source.read_bytes() if isinstance(source, Path) else source
            sizes = arrow_stream_sizes(data, name)
        except PRSMHealthError as exc:
            raise HTTPError(422, str(exc)) from None
        rows, decoded, columns = sizes.rows, sizes.decoded_bytes, sizes.columns
        kind = "Arrow stream"
    elif fmt == "csv":
        rows, columns = _csv_shape(source)
        decoded, kind = 8 * rows * columns, "CSV file"
    else:
        decoded = _mcap_chunk_bytes(source, max_decoded_bytes)
    if columns > 4 * len(UNITS):
        raise HTTPError(
            422,
            f"{kind} has {columns} columns; a recording has time, channels "
            "and (simulated) truth columns",
        )
    if rows is not None and rows > max_samples:
        raise HTTPError(
            413,
            f"recording too long: {rows} samples, at most {max_samples} accepted{samples_hint}",
        )
    if decoded > max_decoded_bytes:
        raise HTTPError(
            413,
            f"recording decompresses to more than {max_decoded_bytes} bytes{decoded_hint}",
        )


_MCAP_MAGIC = b"\x89MCAP0\r\n"
_MCAP_CHUNK = 0x06
_RECORD = struct.Struct("<BQ")
_U64 = struct.Struct("<Q")


def _mcap_chunk_bytes(source: Path | bytes, stop_above: int) -> int:
    """Sum of the uncompressed sizes the chunk records of an MCAP recording declare (stops
    once above ``stop_above``), from the record headers alone: nothing is decompressed. 0 for
    what is not MCAP; the scan ends at the first record running past the end (the library's
    tolerant reader decides about damage)."""
    if isinstance(source, Path):
        with open(source, "rb") as f:
            if os.fstat(f.fileno()).st_size == 0:
                return 0
            with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
                return _mcap_chunk_bytes(memoryview(data), stop_above)
    data = source
    if bytes(data[: len(_MCAP_MAGIC)]) != _MCAP_MAGIC:
        return 0
    total, pos, size = 0, len(_MCAP_MAGIC), len(data)
    while pos + _RECORD.size <= size:
        opcode, length = _RECORD.unpack_from(data, pos)
        body = pos + _RECORD.size
        if body + length > size:
            break
        if opcode == _MCAP_CHUNK and length >= 24:
            # chunk: message start time u64, end time u64, uncompressed size u64, ...
            total += _U64.unpack_from(data, body + 16)[0]
            if total > stop_above:
                break
        pos = body + length
    return total


def _csv_shape(source: Path | bytes) -> tuple[int, int]:
    """Data rows and header fields of a CSV file, from its line breaks and first line alone
    (nothing parsed; a row is at least one line, so rows are never undercounted)."""
    if isinstance(source, Path):
        lines, header, last = 0, b"", b""
        with open(source, "rb") as f:
            while block := f.read(1 << 20):
                if lines == 0 and not header:
                    header = block.split(b"\n", 1)[0]
                lines += block.count(b"\n")
                last = block[-1:]
        lines += 1 if last and last != b"\n" else 0
    else:
        data = bytes(source)
        header = data.split(b"\n", 1)[0]
        lines = data.count(b"\n") + (1 if data and not data.endswith(b"\n") else 0)
    return max(lines - 1, 0), (header.count(b",") + 1 if header.strip() else 0)


@dataclass(frozen=True)
class ReceivedUpload:
    """What a received upload is to the diagnosis: the file on disk and how the client named
    it, and the column map sent with it (plain data: it crosses to a diagnosis process)."""

    path: Path | None
    filename: str | None
    suffix: str | None
    file_bytes: int
    column_map: bytes | None = None
    map_name: str | None = None


class Upload:
    """Streams a multipart/form-data body: the ``file`` part straight into ``directory``
    (under a fixed name; the client's file name only gives the suffix), the column map
    (``map``, at most :data:`MAX_MAP_BYTES`) and small text fields in memory."""

    FIELDS = ("file", "map", "asset_id", "healthy", "recording_id", "operating_hours")
    #: python-multipart callbacks this class implements.
    CALLBACKS = (
        "on_part_begin",
        "on_part_data",
        "on_part_end",
        "on_header_field",
        "on_header_value",
        "on_header_end",
        "on_headers_finished",
    )

    def __init__(self, directory: Path):
        self.directory = directory
        self.filename: str | None = None
        self.suffix: str | None = None
        self.path: Path | None = None
        self.fields: dict[str, str] = {}
        self.column_map: bytes | None = None
        self.map_name: str | None = None
        self.file_bytes = 0
        self._file = None
        self._name: str | None = None
        self._is_file = False
        self._header_name = b""
        self._header_value = b""
        self._disposition = b""
        self._value = bytearray()
        self._pending: list[bytes] = []

    # python-multipart callbacks (synchronous: no I/O here, data is queued for a thread)
    def on_part_begin(self):
        self._disposition = b""
        self._value = bytearray()
        self._name = None
        self._is_file = False

    def on_header_field(self, data, start, end):
        self._header_name += data[start:end]

    def on_header_value(self, data, start, end):
        self._header_value += data[start:end]

    def on_header_end(self):
        if self._header_name.strip().lower() == b"content-disposition":
            self._disposition = self._header_value
        self._header_name = b""
        self._header_value = b""

    def on_headers_finished(self):
        _, options = parse_options_header(self._disposition)
        if b"name" not in options:
            raise HTTPError(422, "multipart part without a name in Content-Disposition")
        name = options[b"name"].decode("utf-8", "replace")
        if name not in self.FIELDS:
            raise HTTPError(
                422,
                f"unknown form field {name!r}; expected 'file' (the recording), optional 'map' "
                "(its column map, TOML), optional 'asset_id', 'healthy', 'recording_id' and "
                "'operating_hours'",
            )
        if (
            name in self.fields
            or (name == "file" and self.filename is not None)
            or (name == "map" and self.map_name is not None)
        ):
            raise HTTPError(422, f"form field {name!r} given twice")
        self._name = name
        if name == "map":
            raw = options.get(b"filename")
            given = raw.decode("utf-8", "replace").replace("\\", "/") if raw else ""
            self.map_name = Path(given).name[:255] or "map"
        if name == "file":
            raw = options.get(b"filename")
            if raw is None:
                raise HTTPError(422, "form field 'file' must be a file upload with a file name")
            filename = Path(raw.decode("utf-8", "replace").replace("\\", "/")).name[:255]
            suffix = Path(filename).suffix.lower()
            if suffix not in UPLOAD_SUFFIXES:
                raise HTTPError(
                    415,
                    f"unsupported recording type {suffix or filename!r}: upload a .mcap, "
                    ".parquet or .csv file",
                )
            self.filename, self.suffix, self._is_file = filename, suffix, True
            self.path = self.directory / f"recording{suffix}"
            self._file = open(self.path, "xb")  # noqa: SIM115 - closed in close()

    def on_part_data(self, data, start, end):
        if self._is_file:
            self._pending.append(bytes(data[start:end]))
            self.file_bytes += end - start
        else:
            self._value += data[start:end]
            limit = MAX_MAP_BYTES if self._name == "map" else MAX_FIELD_BYTES
            if len(self._value) > limit:
                raise HTTPError(422, f"form field {self._name!r} longer than {limit} bytes")

    def on_part_end(self):
        if self._name == "map":
            self.column_map = bytes(self._value)
        elif not self._is_file and self._name is not None:
            self.fields[self._name] = self._value.decode("utf-8", "replace")

    def take_pending(self) -> bytes:
        data = b"".join(self._pending)
        self._pending.clear()
        return data

    def write(self, data: bytes) -> None:
        if self._file is not None and data:
            self._file.write(data)

    def received(self) -> ReceivedUpload:
        """The received file, for the diagnosis."""
        return ReceivedUpload(
            self.path, self.filename, self.suffix, self.file_bytes, self.column_map, self.map_name
        )

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


def multipart_boundary(request: Request) -> bytes:
    """The boundary of a ``multipart/form-data`` request; 415 for any other body."""
    ctype, options = parse_options_header(request.headers.get("content-type", ""))
    if ctype.lower() != b"multipart/form-data" or b"boundary" not in options:
        raise HTTPError(415, "send the recording as multipart/form-data (field 'file')")
    return options[b"boundary"]


@contextlib.asynccontextmanager
async def upload_directory():
    """A private temporary directory, removed (in a thread) whatever happens."""
    tmp = tempfile.TemporaryDirectory(prefix="prsm-health-upload-")
    try:
        yield Path(tmp.name)
    finally:
        await anyio.to_thread.run_sync(tmp.cleanup)


async def receive_upload(request: Request, boundary: bytes, directory: Path) -> Upload:
    """Stream the multipart body into an :class:`Upload` in ``directory`` (file writes in a
    thread); the file is closed on return. 422 for a malformed body or ``asset_id``."""
    upload = Upload(directory)
    callbacks = {name: getattr(upload, name) for name in Upload.CALLBACKS}
    try:
        try:
            parser = MultipartParser(boundary, callbacks)
            async for chunk in request.stream():
                parser.write(chunk)
                data = upload.take_pending()
                if data:
                    await anyio.to_thread.run_sync(upload.write, data)
            parser.finalize()
        except HTTPError:
            raise
        except (ValueError, LookupError) as exc:  # python-multipart's parse errors
            raise HTTPError(422, f"malformed multipart body ({exc})") from None
        await anyio.to_thread.run_sync(upload.write, upload.take_pending())
    finally:
        upload.close()
    asset_id = upload.fields.get("asset_id")
    if asset_id is not None and not re.fullmatch(ASSET_ID_PATTERN, asset_id):
        raise HTTPError(422, f"asset_id {asset_id!r} must match {ASSET_ID_PATTERN}")
    recording_id = upload.fields.get("recording_id")
    if recording_id is not None and not re.fullmatch(RECORDING_ID_PATTERN, recording_id):
        raise HTTPError(422, f"recording_id {recording_id!r} must match {RECORDING_ID_PATTERN}")
    return upload
