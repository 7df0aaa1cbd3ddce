"""Uploaded recordings: the multipart body streamed to a private temporary directory
(:func:`receive_upload`), and checks of a file's metadata before the library decodes it
(:func:`precheck_upload`)."""

from __future__ import annotations

import contextlib
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import anyio
from python_multipart.multipart import MultipartParser, parse_options_header
from starlette.requests import Request

from ..channels import UNITS
from .limits import ServiceLimits
from .responses import HTTPError
from .schemas import ASSET_ID_PATTERN

UPLOAD_SUFFIXES = (".mcap", ".parquet")


def precheck_upload(path: Path, suffix: str, limits: ServiceLimits) -> None:
    """Refuse uploads whose metadata already announce more than the limits allow, before the
    library decodes them (a small compressed file can inflate to gigabytes)."""
    if suffix == ".parquet":
        try:
            import pyarrow.parquet as pq

            meta = pq.read_metadata(path)
        except Exception:
            return  # not readable: the library's reader reports it with its own message
        decoded = sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
        if meta.num_columns > 4 * len(UNITS):
            raise HTTPError(
                422,
                f"Parquet file has {meta.num_columns} columns; a recording has time, channels "
                "and (simulated) truth columns",
            )
        if meta.num_rows > limits.max_upload_samples:
            raise HTTPError(
                413,
                f"recording too long: {meta.num_rows} samples, at most "
                f"{limits.max_upload_samples} accepted",
            )
    else:
        decoded = 0
        try:
            from mcap.records import Chunk
            from mcap.stream_reader import StreamReader

            with open(path, "rb") as f:
                for record in StreamReader(f, emit_chunks=True).records:
                    if isinstance(record, Chunk):
                        decoded += int(record.uncompressed_size)
                        if decoded > limits.max_upload_decoded_bytes:
                            break
        except Exception:
            pass  # damaged or not MCAP: the library's tolerant reader decides
    if decoded > limits.max_upload_decoded_bytes:
        raise HTTPError(
            413,
            f"recording decompresses to more than {limits.max_upload_decoded_bytes} bytes",
        )


@dataclass(frozen=True)
class ReceivedUpload:
    """What a received upload is to the diagnosis: the file on disk and how the client named
    it (plain data: it crosses to a diagnosis process)."""

    path: Path | None
    filename: str | None
    suffix: str | None
    file_bytes: int


class Upload:
    """Streams a multipart/form-data body: the ``file`` part straight into ``directory``
    (under a fixed name; the client's file name only gives the suffix), small text fields in
    memory."""

    FIELDS = ("file", "asset_id")
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
                f"unknown form field {name!r}; expected 'file' (the recording) and optional 'asset_id'",
            )
        if name in self.fields or (name == "file" and self.filename is not None):
            raise HTTPError(422, f"form field {name!r} given twice")
        self._name = name
        if name == "file":
            raw = options.get(b"filename")
            if raw is None:
                raise HTTPError(422, "form field 'file' must be a file upload with a file name")
            filename = Path(raw.decode("utf-8", "replace").replace("\\", "/")).name[:255]
            suffix = Path(filename).suffix.lower()
            if suffix not in UPLOAD_SUFFIXES:
                raise HTTPError(
                    415,
                    f"unsupported recording type {suffix or filename!r}: upload a .mcap or .parquet file",
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
            if len(self._value) > 1024:
                raise HTTPError(422, f"form field {self._name!r} longer than 1024 bytes")

    def on_part_end(self):
        if not self._is_file and self._name is not None:
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
        return ReceivedUpload(self.path, self.filename, self.suffix, self.file_bytes)

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
    return upload
