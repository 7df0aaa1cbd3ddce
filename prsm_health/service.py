"""HTTP diagnostics service: ``prsm-health serve`` (FastAPI on uvicorn).

The service only parses requests, calls the diagnosis library (:mod:`prsm_health.diagnosis`)
and formats its results; no physics and no feature logic live here. Endpoints (API reference
and curl examples in docs/service.md):

* ``POST /v1/diagnose`` — JSON body with ``sample_rate`` [Hz] and contract ``channels``;
  returns the Diagnosis contract of ../shared/DESIGN.md (``windows`` only when the recording
  spans more than one model window);
* ``POST /v1/diagnose/file`` — multipart upload of a ``.mcap`` or ``.parquet`` recording;
  returns the whole-recording diagnosis and the per-window diagnoses;
* ``GET /v1/assets/{asset_id}/history`` — diagnoses stored for an asset, oldest first;
* ``GET /v1/health``, ``GET /v1/model``, and the OpenAPI document at ``/openapi.json``.

Safety: the service binds 127.0.0.1 by default; with a bearer token (``token`` argument or
the ``PRSM_HEALTH_TOKEN`` environment variable) every endpoint requires
``Authorization: Bearer <token>``, and :func:`serve` refuses a non-loopback address without
one. Request bodies, recording lengths and sample rates are bounded (:class:`ServiceLimits`);
user errors are 4xx responses ``{"error": "…"}``. Uploads are streamed into a private
temporary directory removed after the request. Parsing and diagnosis run in worker threads
(at most :attr:`ServiceLimits.workers` at once) so ``/v1/health`` answers while they run.

History is kept in SQLite (:class:`HistoryStore`): WAL journal, one transaction per request,
the schema created when missing.
"""

import contextlib
import hmac
import ipaddress
import json
import logging
import math
import os
import socket
import sqlite3
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Annotated, Literal

import numpy as np

from .channels import CHANNEL_NAMES
from .design import PRESETS
from .errors import PRSMHealthError
from .features import MIN_SAMPLES

log = logging.getLogger("prsm_health.service")

#: Environment variable holding the bearer token when ``--token`` is not given.
TOKEN_ENV = "PRSM_HEALTH_TOKEN"
#: Environment variable overriding the default history database path.
DB_ENV = "PRSM_HEALTH_DB"
#: Largest magnitude accepted for any sample (SI units): far above any physical reading, far
#: below where squares and fourth powers of a window overflow float64 in the indicators.
MAX_ABS_VALUE = 1e12
#: Pattern of an asset id (also a URL path segment).
ASSET_ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._:-]{0,127}$"
UPLOAD_SUFFIXES = (".mcap", ".parquet")


def default_db_path() -> Path:
    """``$PRSM_HEALTH_DB``, else ``$XDG_DATA_HOME/prsm-health/history.sqlite``."""
    if os.environ.get(DB_ENV):
        return Path(os.environ[DB_ENV])
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "prsm-health" / "history.sqlite"


@dataclass(frozen=True)
class ServiceLimits:
    """Bounds on what one request may ask of the service.

    Attributes
    ----------
    max_body_bytes : int [bytes]
        Largest JSON body of ``POST /v1/diagnose``.
    max_upload_bytes : int [bytes]
        Largest multipart body of ``POST /v1/diagnose/file``.
    max_small_body_bytes : int [bytes]
        Largest body on every other endpoint.
    max_window_seconds : float [s]
        Longest recording ``POST /v1/diagnose`` accepts: ``max_window_seconds · sample_rate``
        samples.
    max_upload_samples : int
        Most samples an uploaded recording may hold (checked from the file's metadata before
        it is decoded, when the file has it, and again after).
    max_upload_decoded_bytes : int [bytes]
        Most bytes an uploaded file may decompress to (MCAP chunks, Parquet row groups).
    min_sample_rate, max_sample_rate : float [Hz]
        Accepted sample rates.
    workers : int
        Diagnoses (parse + diagnose) running at once in worker threads; more requests wait
        their turn. Default: half the CPUs. A diagnosis holds the GIL much of the time, so
        threads add little: on 2 CPUs, 40 in-process diagnoses of 1 s recordings ran at 22
        per s on one thread and 19 per s on two, and the service with one worker gave as much
        throughput as with two, a lower p99 latency and half the /v1/health p99
        (docs/service.md).
    max_pending : int
        Diagnose requests admitted at once (receiving, waiting for a worker or running);
        beyond, ``503`` with ``Retry-After``. Bounds the memory held by request bodies.
    max_history : int
        Largest ``limit`` of the history endpoint.
    """

    max_body_bytes: int = 16 * 2**20
    max_upload_bytes: int = 128 * 2**20
    max_small_body_bytes: int = 64 * 2**10
    max_window_seconds: float = 2.0
    max_upload_samples: int = 1_200_000
    max_upload_decoded_bytes: int = 2**30
    min_sample_rate: float = 1.0
    max_sample_rate: float = 200e3
    workers: int = max(1, (os.cpu_count() or 1) // 2)
    max_pending: int = 16
    max_history: int = 10_000

    def __post_init__(self):
        for name in (
            "max_body_bytes",
            "max_upload_bytes",
            "max_small_body_bytes",
            "max_upload_samples",
            "max_upload_decoded_bytes",
            "workers",
            "max_pending",
            "max_history",
        ):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 1):
                raise PRSMHealthError(f"ServiceLimits.{name} = {value!r} must be an integer >= 1")
        if not (math.isfinite(self.max_window_seconds) and self.max_window_seconds > 0):
            raise PRSMHealthError(
                "ServiceLimits.max_window_seconds must be a finite number > 0 [s]"
            )
        if not (0 < self.min_sample_rate <= self.max_sample_rate < math.inf):
            raise PRSMHealthError(
                "ServiceLimits: need 0 < min_sample_rate <= max_sample_rate < inf [Hz]"
            )


# ============================================================================ history store
_SCHEMA = """
CREATE TABLE IF NOT EXISTS diagnoses (
    id                  INTEGER PRIMARY KEY AUTOINCREMENT,
    asset_id            TEXT    NOT NULL,
    received_at         TEXT    NOT NULL,  -- server receive time, UTC ISO-8601 (microseconds)
    source              TEXT    NOT NULL,  -- 'json' or 'file'
    filename            TEXT,              -- uploaded file name (source 'file')
    window_index        INTEGER,           -- per-window rows of an upload
    window_start        REAL,              -- [s]
    window_end          REAL,              -- [s]
    speed               REAL,              -- nominal screw speed given by the client [rad/s]
    load                REAL,              -- nominal axial load given by the client [N]
    clearance_estimate  REAL,              -- [m]
    clearance_lower     REAL,              -- [m]
    clearance_upper     REAL,              -- [m]
    fault_class         TEXT,
    class_probabilities TEXT    NOT NULL,  -- JSON object
    model_name          TEXT    NOT NULL,
    model_version       TEXT    NOT NULL,
    diagnosis           TEXT    NOT NULL   -- the full Diagnosis contract JSON
);
CREATE INDEX IF NOT EXISTS diagnoses_asset_time ON diagnoses (asset_id, received_at, id);
"""
_SCHEMA_VERSION = 1


def utc_now() -> str:
    """Current UTC time as ISO-8601 with microseconds (fixed width, so it sorts as text)."""
    return datetime.now(timezone.utc).isoformat(timespec="microseconds")


def parse_time(text: str, field: str = "since") -> str:
    """An ISO-8601 time as the store's UTC text form (a time without zone is UTC)."""
    try:
        value = datetime.fromisoformat(text.strip())
    except (ValueError, AttributeError):
        raise PRSMHealthError(
            f"{field} = {text!r} is not an ISO-8601 time (e.g. 2024-05-01T12:00:00Z)"
        ) from None
    if value.tzinfo is None:
        value = value.replace(tzinfo=timezone.utc)
    try:
        return value.astimezone(timezone.utc).isoformat(timespec="microseconds")
    except (OverflowError, ValueError):
        raise PRSMHealthError(f"{field} = {text!r} is out of range") from None


class HistoryStore:
    """Diagnoses per asset over time, in an embedded SQLite database.

    The database uses the WAL journal (readers never block the writer, a crash never leaves a
    half-written row) with ``synchronous=FULL`` (a committed diagnosis survives power loss);
    every :meth:`add` is one transaction. One connection is shared by the server's threads
    behind a lock; several processes may open the same file (SQLite locks it, writers wait up
    to ``timeout`` seconds).

    Parameters
    ----------
    path : str or Path
        Database file; its directory must exist (``":memory:"`` for a throw-away store).
    timeout : float [s]
        How long a write waits for another process's lock.
    """

    def __init__(self, path: str | os.PathLike, *, timeout: float = 30.0):
        self.path = str(path)
        if self.path != ":memory:":
            parent = Path(self.path).expanduser().resolve().parent
            if not parent.is_dir():
                raise PRSMHealthError(f"{self.path}: directory {parent} does not exist")
            if Path(self.path).is_dir():
                raise PRSMHealthError(f"{self.path}: is a directory, not a database file")
        self._lock = threading.Lock()
        try:
            self._conn = sqlite3.connect(
                self.path, timeout=timeout, isolation_level=None, check_same_thread=False
            )
        except sqlite3.Error as exc:
            raise PRSMHealthError(
                f"{self.path}: cannot open the history database ({exc})"
            ) from None
        try:
            self._conn.execute("PRAGMA journal_mode=WAL")
            self._conn.execute("PRAGMA synchronous=FULL")
            with self._transaction():
                version = self._conn.execute("PRAGMA user_version").fetchone()[0]
                if version > _SCHEMA_VERSION:
                    raise PRSMHealthError(
                        f"{self.path}: history schema version {version} is newer than this "
                        f"prsm_health ({_SCHEMA_VERSION}); upgrade prsm_health"
                    )
                for statement in _SCHEMA.split(";"):
                    if statement.strip():
                        self._conn.execute(statement)
                self._conn.execute(f"PRAGMA user_version = {_SCHEMA_VERSION}")
        except BaseException as exc:
            self._conn.close()
            if isinstance(exc, sqlite3.DatabaseError):
                raise PRSMHealthError(
                    f"{self.path}: not a usable history database ({exc})"
                ) from None
            raise

    @contextlib.contextmanager
    def _transaction(self):
        self._conn.execute("BEGIN IMMEDIATE")
        try:
            yield
        except BaseException:
            self._conn.execute("ROLLBACK")
            raise
        else:
            self._conn.execute("COMMIT")

    def add(
        self,
        asset_id: str,
        diagnoses: list[dict],
        *,
        received_at: str | None = None,
        source: str = "json",
        filename: str | None = None,
        speed: float | None = None,
        load: float | None = None,
    ) -> list[int]:
        """Store diagnoses (contract dicts; a ``window`` key places one in its recording) in
        one transaction; returns their ids."""
        received_at = received_at or utc_now()
        rows = []
        for d in diagnoses:
            c = d.get("clearance") or {}
            w = d.get("window") or {}
            model = d.get("model") or {}
            rows.append(
                (
                    asset_id,
                    received_at,
                    source,
                    filename,
                    w.get("index"),
                    w.get("start"),
                    w.get("end"),
                    speed,
                    load,
                    c.get("estimate"),
                    c.get("lower"),
                    c.get("upper"),
                    d.get("fault_class"),
                    json.dumps(d.get("class_probabilities", {})),
                    str(model.get("name", "")),
                    str(model.get("version", "")),
                    json.dumps(d, allow_nan=False),
                )
            )
        ids = []
        with self._lock, self._transaction():
            for row in rows:
                cur = self._conn.execute(
                    "INSERT INTO diagnoses (asset_id, received_at, source, filename, window_index,"
                    " window_start, window_end, speed, load, clearance_estimate, clearance_lower,"
                    " clearance_upper, fault_class, class_probabilities, model_name, model_version,"
                    " diagnosis) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    row,
                )
                ids.append(cur.lastrowid)
        return ids

    def history(self, asset_id: str, *, since: str | None = None, limit: int = 100) -> dict:
        """The most recent ``limit`` diagnoses of an asset at or after ``since`` (ISO-8601),
        oldest first: ``{"asset_id", "count", "total", "truncated", "diagnoses": [...]}``."""
        where, args = "asset_id = ?", [asset_id]
        if since is not None:
            where += " AND received_at >= ?"
            args.append(parse_time(since))
        with self._lock:
            total = self._conn.execute(
                f"SELECT COUNT(*) FROM diagnoses WHERE {where}", args
            ).fetchone()[0]
            rows = self._conn.execute(
                "SELECT id, received_at, source, filename, window_index, window_start, window_end,"
                f" speed, load, diagnosis FROM diagnoses WHERE {where}"
                " ORDER BY received_at DESC, id DESC LIMIT ?",
                [*args, int(limit)],
            ).fetchall()
        entries = []
        for row in reversed(rows):
            id_, received_at, source, filename, w_index, w_start, w_end, speed, load, blob = row
            entries.append(
                {
                    "id": id_,
                    "received_at": received_at,
                    "source": source,
                    "filename": filename,
                    "window": None
                    if w_index is None
                    else {"index": w_index, "start": w_start, "end": w_end},
                    "speed": speed,
                    "load": load,
                    "diagnosis": json.loads(blob),
                }
            )
        return {
            "asset_id": asset_id,
            "count": len(entries),
            "total": total,
            "truncated": total > len(entries),
            "diagnoses": entries,
        }

    def has_asset(self, asset_id: str) -> bool:
        with self._lock:
            row = self._conn.execute(
                "SELECT 1 FROM diagnoses WHERE asset_id = ? LIMIT 1", (asset_id,)
            ).fetchone()
        return row is not None

    def close(self) -> None:
        with self._lock:
            self._conn.close()


# ============================================================================ request / response
def _models(limits: "ServiceLimits"):
    """Pydantic models of the API (built lazily: pydantic is imported with the service only)."""
    from pydantic import BaseModel, ConfigDict, Field, create_model

    finite = Annotated[float, Field(allow_inf_nan=False)]
    samples = Annotated[list[finite], Field(description="samples in the channel's SI unit")]
    # One optional array per contract channel; any other name is an error (extra="forbid").
    Channels = create_model(
        "Channels",
        __config__=ConfigDict(strict=True, extra="forbid"),
        __doc__="Contract channels (docs/formats.md): equal-length arrays, SI units.",
        **{name: (samples, Field(None)) for name in CHANNEL_NAMES},
    )

    class DiagnoseRequest(BaseModel):
        """A recording to diagnose: uniformly sampled contract channels."""

        model_config = ConfigDict(strict=True, extra="forbid")
        sample_rate: finite = Field(
            ge=limits.min_sample_rate, le=limits.max_sample_rate, description="sample rate [Hz]"
        )
        channels: Channels
        design: Literal[tuple(sorted(PRESETS))] | None = Field(  # type: ignore[valid-type]
            None, description="design preset of the actuator (must match the model's)"
        )
        speed: finite | None = Field(None, description="nominal screw speed [rad/s] (stored)")
        load: finite | None = Field(None, description="nominal axial load [N] (stored)")
        asset_id: str | None = Field(
            None,
            pattern=ASSET_ID_PATTERN,
            description="store the diagnosis in this asset's history",
        )
        time_start: finite = Field(0.0, ge=-1e7, le=1e7, description="time of the first sample [s]")

    class Clearance(BaseModel):
        estimate: float | None = Field(description="clearance estimate [m]")
        lower: float | None = Field(description="lower bound of the 90 % interval [m]")
        upper: float | None = Field(description="upper bound of the 90 % interval [m]")

    class ModelRef(BaseModel):
        name: str
        version: str

    class WindowRef(BaseModel):
        index: int
        start: float = Field(description="[s]")
        end: float = Field(description="[s]")

    class WindowDiagnosis(BaseModel):
        clearance: Clearance
        fault_class: str | None
        class_probabilities: dict[str, float]
        indicators: dict[str, float | None]
        model: ModelRef
        window: WindowRef

    class Diagnosis(BaseModel):
        """The Diagnosis contract (../shared/DESIGN.md)."""

        clearance: Clearance
        fault_class: str | None
        class_probabilities: dict[str, float]
        indicators: dict[str, float | None]
        model: ModelRef
        windows: list[WindowDiagnosis] | None = Field(
            None, description="per-window diagnoses, present when there is more than one window"
        )

    class RecordingInfo(BaseModel):
        filename: str
        samples: int
        sample_rate: float = Field(description="[Hz]")
        duration: float = Field(description="[s]")
        channels: list[str]

    class FileDiagnosis(BaseModel):
        diagnosis: Diagnosis
        windows: list[WindowDiagnosis]
        recording: RecordingInfo
        warnings: list[str]

    class HistoryEntry(BaseModel):
        id: int
        received_at: str = Field(description="server receive time, UTC ISO-8601")
        source: str = Field(description="'json' or 'file'")
        filename: str | None
        window: WindowRef | None
        speed: float | None = Field(description="[rad/s]")
        load: float | None = Field(description="[N]")
        diagnosis: dict

    class History(BaseModel):
        asset_id: str
        count: int
        total: int = Field(description="diagnoses stored at or after `since`")
        truncated: bool
        diagnoses: list[HistoryEntry]

    class Health(BaseModel):
        status: str
        model: str
        version: str
        uptime_s: float
        warm: bool
        active_diagnoses: int

    class ModelInfo(BaseModel):
        name: str
        version: str
        window: float = Field(description="window length [s]")
        design: str
        sample_rate: float | None = Field(description="training sample rate [Hz]")
        feature_names: list[str]
        classes: list[str]
        clearance_range: list[float] | None = Field(description="[m]")
        saved_at: str | None
        versions: dict
        metrics: dict | None

    class Error(BaseModel):
        error: str

    return {
        m.__name__: m
        for m in (
            Channels,
            DiagnoseRequest,
            Clearance,
            ModelRef,
            WindowRef,
            WindowDiagnosis,
            Diagnosis,
            RecordingInfo,
            FileDiagnosis,
            HistoryEntry,
            History,
            Health,
            ModelInfo,
            Error,
        )
    }


def _format_errors(errors: list[dict], prefix: str = "") -> str:
    """One message from pydantic errors: unknown channels first, then the first few others."""
    unknown_channels = [
        str(e["loc"][1])
        for e in errors
        if e["type"] == "extra_forbidden" and len(e["loc"]) == 2 and e["loc"][0] == "channels"
    ]
    parts = []
    if unknown_channels:
        names = ", ".join(repr(n) for n in unknown_channels)
        parts.append(f"unknown channel(s) {names}; contract channels: {', '.join(CHANNEL_NAMES)}")
    others = [
        e for e in errors if not (e["type"] == "extra_forbidden" and e["loc"][:1] == ("channels",))
    ]
    for e in others[:3]:
        loc = ".".join(str(p) for p in e["loc"])
        where = f"{prefix}{loc}" if loc else (prefix.rstrip(".") or "body")
        if e["type"] == "extra_forbidden":
            parts.append(f"unknown field {where!r}")
        else:
            parts.append(f"{where}: {e['msg']}")
    if len(others) > 3:
        parts.append(f"and {len(others) - 3} more error(s)")
    return "; ".join(parts) or "invalid request"


class _HTTPError(Exception):
    """A 4xx answer raised from worker code: ``{"error": message}`` with ``status``."""

    def __init__(self, status: int, message: str, headers: dict | None = None):
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers


class _BodyTooLarge(_HTTPError):
    def __init__(self, limit: int):
        super().__init__(413, f"request body larger than {limit} bytes (limit of this endpoint)")


def _json_ready(value):
    """Plain JSON values: numpy scalars/arrays to Python, non-finite floats to null."""
    if isinstance(value, dict):
        return {str(k): _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return _json_ready(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _dumps(value) -> bytes:
    return json.dumps(_json_ready(value), allow_nan=False, separators=(",", ":")).encode()


# ============================================================================ recording checks
def _where(what: str) -> str:
    return f"{what}: " if what else ""


def _check_rate(rate: float, limits: ServiceLimits, what: str = "") -> None:
    rate = float(rate)
    if not (math.isfinite(rate) and limits.min_sample_rate <= rate <= limits.max_sample_rate):
        raise _HTTPError(
            422,
            f"{_where(what)}sample_rate = {rate:g} Hz is outside the accepted range "
            f"[{limits.min_sample_rate:g}, {limits.max_sample_rate:g}] Hz",
        )


def _check_run(run, limits: ServiceLimits, *, what: str, max_samples: int) -> None:
    """Bounds the library does not enforce itself (sample rate, length, time axis, sample
    magnitude): beyond them its indicators overflow or its spectra have no bins."""
    _check_rate(run.sample_rate, limits, what)
    rate = float(run.sample_rate)
    n = len(run)
    if n < MIN_SAMPLES:
        raise _HTTPError(
            422,
            f"{_where(what)}recording too short: {n} samples, need at least {MIN_SAMPLES} "
            f"({MIN_SAMPLES / rate:.3g} s at {rate:g} Hz)",
        )
    if n > max_samples:
        raise _HTTPError(
            413,
            f"{_where(what)}recording too long: {n} samples ({n / rate:.6g} s at {rate:g} Hz); "
            f"at most {max_samples} samples accepted here",
        )
    time_axis = np.asarray(run.time, dtype=float)
    if not (np.all(np.isfinite(time_axis)) and np.all(np.diff(time_axis) > 0)):
        raise _HTTPError(422, f"{_where(what)}time must be finite and strictly increasing")
    if float(np.max(np.abs(time_axis))) > 1e7:
        raise _HTTPError(
            422, f"{_where(what)}time beyond ±1e7 s (use time from the recording start)"
        )
    for name, values in run.channels.items():
        values = np.asarray(values, dtype=float)
        if len(values) != n:
            raise _HTTPError(
                422, f"{_where(what)}channel {name} has {len(values)} samples, time has {n}"
            )
        if not np.all(np.isfinite(values)):
            raise _HTTPError(422, f"{_where(what)}channel {name} contains NaN or infinite values")
        if values.size and float(np.max(np.abs(values))) > MAX_ABS_VALUE:
            raise _HTTPError(
                422,
                f"{_where(what)}channel {name} has samples beyond ±{MAX_ABS_VALUE:g} "
                "(SI units expected: m, rad, N, N·m, m/s²)",
            )


def _precheck_upload(path: Path, suffix: str, limits: ServiceLimits) -> None:
    """Refuse uploads whose metadata already announce more than the limits allow, before the
    library decodes them (a small compressed file can inflate to gigabytes)."""
    if suffix == ".parquet":
        try:
            import pyarrow.parquet as pq

            meta = pq.read_metadata(path)
        except Exception:
            return  # not readable: the library's reader reports it with its own message
        decoded = sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
        if meta.num_columns > 4 * len(CHANNEL_NAMES):
            raise _HTTPError(
                422, f"Parquet file has {meta.num_columns} columns; a recording has time + channels"
            )
        if meta.num_rows > limits.max_upload_samples:
            raise _HTTPError(
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
        raise _HTTPError(
            413,
            f"recording decompresses to more than {limits.max_upload_decoded_bytes} bytes",
        )


# ============================================================================ multipart upload
class _Upload:
    """Streams a multipart/form-data body: the ``file`` part straight into ``directory``
    (under a fixed name; the client's file name only gives the suffix), small text fields in
    memory."""

    FIELDS = ("file", "asset_id")

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
        from python_multipart.multipart import parse_options_header

        _, options = parse_options_header(self._disposition)
        if b"name" not in options:
            raise _HTTPError(422, "multipart part without a name in Content-Disposition")
        name = options[b"name"].decode("utf-8", "replace")
        if name not in self.FIELDS:
            raise _HTTPError(
                422,
                f"unknown form field {name!r}; expected 'file' (the recording) and optional 'asset_id'",
            )
        if name in self.fields or (name == "file" and self.filename is not None):
            raise _HTTPError(422, f"form field {name!r} given twice")
        self._name = name
        if name == "file":
            raw = options.get(b"filename")
            if raw is None:
                raise _HTTPError(422, "form field 'file' must be a file upload with a file name")
            filename = Path(raw.decode("utf-8", "replace").replace("\\", "/")).name[:255]
            suffix = Path(filename).suffix.lower()
            if suffix not in UPLOAD_SUFFIXES:
                raise _HTTPError(
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
                raise _HTTPError(422, f"form field {self._name!r} longer than 1024 bytes")

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

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


# ============================================================================ ASGI guard
class _Guard:
    """Outermost ASGI layer: bearer token on every request, then body size limits.

    The token is compared in constant time. The body limit is checked on ``Content-Length``
    before anything is read, and again on the bytes actually received (chunked bodies).
    """

    def __init__(self, app, token: str | None, limit_for):
        self.app = app
        self.token = token.encode() if token else None
        self.limit_for = limit_for

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            if scope["type"] == "websocket" and self.token is not None:
                await send({"type": "websocket.close", "code": 1008})
                return
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers") or [])
        if self.token is not None:
            given = headers.get(b"authorization", b"")
            scheme, _, credentials = given.partition(b" ")
            if scheme.lower() != b"bearer" or not hmac.compare_digest(
                credentials.strip(), self.token
            ):
                message = "missing bearer token" if not given else "invalid bearer token"
                await _send_error(
                    send,
                    401,
                    f"{message}: send 'Authorization: Bearer <token>'",
                    [(b"www-authenticate", b'Bearer realm="prsm-health"')],
                )
                return
        limit = self.limit_for(scope["path"])
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
            except ValueError:
                await _send_error(send, 400, "invalid Content-Length header")
                return
            if declared > limit:
                await _send_error(
                    send,
                    413,
                    f"request body of {declared} bytes is larger than the {limit} bytes this endpoint accepts",
                )
                return
        received = 0

        async def limited_receive():
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise _BodyTooLarge(limit)
            return message

        await self.app(scope, limited_receive, send)


async def _send_error(send, status: int, message: str, headers=()):
    body = _dumps({"error": message})
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                *headers,
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})


# ============================================================================ the app
def _metrics_summary(model_path: Path | None, metadata: dict) -> dict | None:
    """Training metrics: from the bundle metadata, else the ``<stem>.metrics.json`` that
    :func:`prsm_health.training.train` writes beside the model."""
    metrics = metadata.get("metrics")
    if metrics is None and model_path is not None:
        side = model_path.with_name(model_path.stem + ".metrics.json")
        if side.is_file():
            try:
                metrics = json.loads(side.read_text())
            except (OSError, ValueError):
                metrics = None
    if not isinstance(metrics, dict):
        return None
    keep = {
        "clearance_cv": (
            "mae",
            "rmse",
            "interval_coverage",
            "nominal_coverage",
            "mean_interval_width",
            "n_samples",
            "n_splits",
        ),
        "clearance_test": ("n", "mae", "rmse", "interval_coverage", "mean_interval_width"),
        "fault_cv": ("accuracy", "macro_f1", "log_loss", "n_samples", "n_splits", "classes"),
        "fault_test": ("n", "accuracy", "macro_f1", "classes"),
        "off_grid": (
            "n",
            "clearance_mae",
            "interval_coverage",
            "mean_interval_width",
            "fault_macro_f1",
        ),
        "runs": None,
        "recipe": None,
    }
    out = {}
    for key, fields in keep.items():
        if key not in metrics:
            continue
        value = metrics[key]
        if fields is not None and isinstance(value, dict):
            value = {k: value[k] for k in fields if k in value}
        out[key] = value
    return _json_ready(out) or None


def create_app(
    model_path: str | os.PathLike | None = None,
    db_path: str | os.PathLike | None = None,
    token: str | None = None,
    limits: ServiceLimits | None = None,
    *,
    bundle=None,
    warmup: bool = True,
):
    """The ASGI application.

    Parameters
    ----------
    model_path : path or None
        Model bundle (default: the shipped model). Loaded once, here.
    db_path : path or None
        History database (default :func:`default_db_path`, its directory created).
    token : str or None
        Bearer token required on every endpoint; None: no authentication (this function does
        not read ``PRSM_HEALTH_TOKEN``; :func:`serve` does).
    limits : ServiceLimits or None
    bundle : ModelBundle or None
        An already loaded bundle (overrides ``model_path``).
    warmup : bool
        Diagnose a blank recording in the background at start-up, so the first request does
        not pay for one-time compilation and caches.

    Raises
    ------
    PRSMHealthError
        Unreadable model or database, empty token.
    """
    import anyio
    from fastapi import FastAPI, Query, Request
    from fastapi import Path as PathParam
    from fastapi.exceptions import RequestValidationError
    from fastapi.openapi.utils import get_openapi
    from fastapi.responses import Response
    from pydantic import ValidationError
    from starlette.exceptions import HTTPException as StarletteHTTPException
    from starlette.requests import ClientDisconnect

    from . import __version__
    from .diagnosis import diagnose, load_bundle, read_recording
    from .run import Run

    limits = limits or ServiceLimits()
    if token is not None and (
        not token or token != token.strip() or any(c.isspace() for c in token)
    ):
        raise PRSMHealthError("token must be a non-empty string without whitespace")
    if model_path is not None:
        model_file = Path(model_path)
    elif bundle is None:
        from .diagnosis import DEFAULT_MODEL

        model_file = DEFAULT_MODEL
    else:
        model_file = None  # a bundle handed in without its path: no metrics file to look up
    if bundle is None:
        bundle = load_bundle(model_path)
    if db_path is None:
        db_path = default_db_path()
        if str(db_path) != ":memory:":
            Path(db_path).parent.mkdir(parents=True, exist_ok=True)
    store = HistoryStore(db_path)
    models = _models(limits)
    started = time.monotonic()
    state = {"warm": not warmup, "active": 0}
    limiter = anyio.CapacityLimiter(limits.workers)
    warnings_lock = threading.Lock()
    model_info = _json_ready(
        {
            "name": bundle.name,
            "version": bundle.version,
            "window": bundle.window,
            "design": bundle.design,
            "sample_rate": bundle.metadata.get("sample_rate"),
            "feature_names": list(bundle.feature_names),
            "classes": [str(c) for c in getattr(bundle.fault, "classes_", [])],
            "clearance_range": bundle.metadata.get("clearance_range"),
            "saved_at": bundle.metadata.get("saved_at"),
            "versions": bundle.metadata.get("versions", {}),
            "metrics": _metrics_summary(model_file, bundle.metadata),
        }
    )

    def _warm():
        # A blank recording walks the whole diagnosis path once (JIT compilation, caches).
        try:
            rate = float(bundle.metadata.get("sample_rate") or 20000.0)
            n = max(MIN_SAMPLES, int(round(bundle.window * rate)))
            blank = {name: np.zeros(n) for name in CHANNEL_NAMES}
            diagnose(Run(np.arange(n) / rate, blank, rate), bundle)
        except Exception:  # warm-up is an optimisation; a failure shows on the first request
            log.warning("warm-up diagnosis failed", exc_info=True)
        finally:
            state["warm"] = True

    @contextlib.asynccontextmanager
    async def lifespan(app):
        if warmup:
            threading.Thread(target=_warm, name="prsm-health-warmup", daemon=True).start()
        try:
            yield
        finally:
            store.close()

    error_responses = {
        401: {"model": models["Error"], "description": "missing or invalid bearer token"},
        413: {"model": models["Error"], "description": "request or recording too large"},
        422: {"model": models["Error"], "description": "invalid request"},
        503: {"model": models["Error"], "description": "too many diagnoses in progress"},
    }
    app = FastAPI(
        title="prsm-health diagnostics service",
        version=__version__,
        description=(
            "Health diagnosis of planetary roller screw mechanisms: clearance estimate with "
            "interval, fault class, condition indicators, and per-asset history. SI units."
        ),
        docs_url=None,
        redoc_url=None,
        lifespan=lifespan,
        responses={401: error_responses[401]},
    )
    app.state.store = store
    app.state.bundle = bundle
    app.state.limits = limits

    def json_response(payload, status: int = 200, headers=None) -> Response:
        body = payload if isinstance(payload, bytes) else _dumps(payload)
        return Response(body, status_code=status, media_type="application/json", headers=headers)

    # ---------------------------------------------------------------- errors
    @app.exception_handler(_HTTPError)
    async def _on_http_error(request, exc: _HTTPError):
        return json_response({"error": exc.message}, exc.status, exc.headers)

    @app.exception_handler(PRSMHealthError)
    async def _on_library_error(request, exc: PRSMHealthError):
        return json_response({"error": str(exc)}, 422)

    @app.exception_handler(RequestValidationError)
    async def _on_validation(request, exc: RequestValidationError):
        return json_response({"error": _format_errors(list(exc.errors()))}, 422)

    @app.exception_handler(StarletteHTTPException)
    async def _on_starlette(request, exc: StarletteHTTPException):
        message = exc.detail if isinstance(exc.detail, str) else json.dumps(exc.detail)
        if exc.status_code == 404 and message == "Not Found":
            message = f"no such endpoint: {request.url.path}"
        elif exc.status_code == 405:
            message = f"method {request.method} not allowed on {request.url.path}"
        return json_response({"error": message}, exc.status_code, getattr(exc, "headers", None))

    @app.exception_handler(ClientDisconnect)
    async def _on_disconnect(request, exc):
        return json_response({"error": "client disconnected"}, 400)

    @app.exception_handler(Exception)
    async def _on_bug(request, exc: Exception):
        log.error("internal error on %s %s", request.method, request.url.path, exc_info=exc)
        return json_response({"error": "internal server error (logged on the server)"}, 500)

    # ---------------------------------------------------------------- helpers
    async def in_worker(fn, *args):
        return await anyio.to_thread.run_sync(fn, *args, limiter=limiter)

    @contextlib.contextmanager
    def admitted():
        # Runs on the event loop thread only: no lock needed around the counter.
        if state["active"] >= limits.max_pending:
            raise _HTTPError(
                503,
                f"busy: {limits.max_pending} diagnoses in progress; retry in a few seconds",
                {"Retry-After": "2"},
            )
        state["active"] += 1
        try:
            yield
        finally:
            state["active"] -= 1

    def require_json(request: Request) -> None:
        ctype = request.headers.get("content-type", "")
        if ctype.split(";")[0].strip().lower() != "application/json":
            raise _HTTPError(
                415, f"Content-Type must be application/json, not {ctype or 'missing'!r}"
            )

    def run_from_request(req) -> Run:
        given = {name: getattr(req.channels, name) for name in CHANNEL_NAMES}
        channels = {
            name: np.asarray(values, dtype=float)
            for name, values in given.items()
            if values is not None
        }
        if not channels:
            raise _HTTPError(
                422, f"channels: give at least one contract channel ({', '.join(CHANNEL_NAMES)})"
            )
        lengths = {name: len(v) for name, v in channels.items()}
        if len(set(lengths.values())) > 1:
            described = ", ".join(f"{k} {v}" for k, v in lengths.items())
            raise _HTTPError(422, f"channels must have equal lengths; got {described}")
        if req.design is not None and req.design != bundle.design:
            raise _HTTPError(
                422,
                f"design = {req.design!r}: model {bundle.name!r} was trained on design "
                f"{bundle.design!r}; load a model for {req.design!r} (prsm-health serve --model)",
            )
        n = next(iter(lengths.values()))
        rate = float(req.sample_rate)  # range checked by the caller
        labels = {"design": bundle.design}
        if req.speed is not None:
            labels["screw_speed"] = float(req.speed)
        if req.load is not None:
            labels["axial_load"] = float(req.load)
        return Run(float(req.time_start) + np.arange(n) / rate, channels, rate, labels)

    def diagnose_body(body: bytes):
        try:
            req = models["DiagnoseRequest"].model_validate_json(body)
        except ValidationError as exc:
            raise _HTTPError(
                422, _format_errors(exc.errors(include_url=False, include_input=False))
            ) from None
        _check_rate(req.sample_rate, limits)
        run = run_from_request(req)
        max_samples = int(limits.max_window_seconds * run.sample_rate)
        if len(run) > max_samples:
            raise _HTTPError(
                413,
                f"recording too long: {len(run)} samples = {len(run) / run.sample_rate:.6g} s at "
                f"{run.sample_rate:g} Hz; /v1/diagnose accepts at most "
                f"{limits.max_window_seconds:g} s per request (upload longer recordings to "
                "/v1/diagnose/file)",
            )
        _check_run(run, limits, what="", max_samples=max(max_samples, MIN_SAMPLES))
        result = diagnose(run, bundle)
        if len(result.get("windows", [])) <= 1:
            result.pop("windows", None)
        result = _json_ready(result)
        return req, result, _dumps(result)

    def diagnose_upload(upload: _Upload):
        def hide_path(text: str) -> str:
            return text.replace(str(upload.path), upload.filename or "upload")

        if upload.path is None or upload.file_bytes == 0:
            raise _HTTPError(422, "no recording: send the file in the multipart field 'file'")
        _precheck_upload(upload.path, upload.suffix, limits)
        from .mcap import TruncatedRecordingWarning

        with warnings_lock, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", TruncatedRecordingWarning)
            try:
                run = read_recording(upload.path)
            except PRSMHealthError as exc:
                raise _HTTPError(422, hide_path(str(exc))) from None
            except (ValueError, TypeError, OverflowError, KeyError, IndexError) as exc:
                # Decoding client bytes: the readers let a few of these through for files
                # with non-numeric channel columns; the file is at fault, not the server.
                log.warning("unreadable upload %r", upload.filename, exc_info=True)
                raise _HTTPError(
                    422,
                    f"{upload.filename}: not a readable recording "
                    f"({type(exc).__name__}: {hide_path(str(exc))})",
                ) from None
        notes = [
            hide_path(str(w.message))
            for w in caught
            if issubclass(w.category, TruncatedRecordingWarning)
        ]
        _check_run(
            run, limits, what=upload.filename or "upload", max_samples=limits.max_upload_samples
        )
        result = _json_ready(diagnose(run, bundle))
        per_window = result.pop("windows")
        recording = {
            "filename": upload.filename,
            "samples": len(run),
            "sample_rate": float(run.sample_rate),
            "duration": float(len(run) / run.sample_rate),
            "channels": [c for c in CHANNEL_NAMES if c in run.channels],
        }
        answer = {
            "diagnosis": result,
            "windows": per_window,
            "recording": recording,
            "warnings": notes,
        }
        return answer, _dumps(answer)

    # ---------------------------------------------------------------- endpoints
    @app.post(
        "/v1/diagnose",
        summary="Diagnose a recording sent as JSON",
        response_model=None,
        responses={
            200: {"model": models["Diagnosis"], "description": "the Diagnosis contract"},
            **error_responses,
            415: {"model": models["Error"], "description": "not JSON"},
        },
        openapi_extra={
            "requestBody": {
                "required": True,
                "content": {
                    "application/json": {"schema": {"$ref": "#/components/schemas/DiagnoseRequest"}}
                },
            }
        },
    )
    async def post_diagnose(request: Request):
        """Diagnose uniformly sampled contract channels (at most `max_window_seconds`, 2 s by
        default). With `asset_id` the diagnosis is stored in the asset's history."""
        received_at = utc_now()
        require_json(request)
        with admitted():
            body = await request.body()
            req, result, encoded = await in_worker(diagnose_body, body)
        if req.asset_id is not None:
            await anyio.to_thread.run_sync(
                lambda: store.add(
                    req.asset_id,
                    [result],
                    received_at=received_at,
                    source="json",
                    speed=req.speed,
                    load=req.load,
                )
            )
        return json_response(encoded)

    @app.post(
        "/v1/diagnose/file",
        summary="Diagnose an uploaded MCAP or Parquet recording",
        response_model=None,
        responses={
            200: {
                "model": models["FileDiagnosis"],
                "description": "whole-recording and per-window diagnoses",
            },
            **error_responses,
            415: {
                "model": models["Error"],
                "description": "not multipart, or not a .mcap/.parquet file",
            },
        },
        openapi_extra={
            "requestBody": {
                "required": True,
                "content": {
                    "multipart/form-data": {
                        "schema": {
                            "type": "object",
                            "required": ["file"],
                            "properties": {
                                "file": {
                                    "type": "string",
                                    "format": "binary",
                                    "description": "recording (.mcap or .parquet, by file name)",
                                },
                                "asset_id": {
                                    "type": "string",
                                    "pattern": ASSET_ID_PATTERN,
                                    "description": "store every window in this asset's history",
                                },
                            },
                        }
                    }
                },
            }
        },
    )
    async def post_diagnose_file(request: Request):
        """Stream the upload into a private temporary directory (removed afterwards), read it
        with the library and diagnose every window."""
        from python_multipart.multipart import parse_options_header

        received_at = utc_now()
        ctype, options = parse_options_header(request.headers.get("content-type", ""))
        if ctype.lower() != b"multipart/form-data" or b"boundary" not in options:
            raise _HTTPError(415, "send the recording as multipart/form-data (field 'file')")
        with admitted():
            (result, encoded), asset_id, filename = await receive_and_diagnose(request, options)
        if asset_id is not None:
            await anyio.to_thread.run_sync(
                lambda: store.add(
                    asset_id,
                    result["windows"],
                    received_at=received_at,
                    source="file",
                    filename=filename,
                )
            )
        return json_response(encoded)

    async def receive_and_diagnose(request: Request, options: dict):
        from python_multipart.multipart import MultipartParser

        tmp = tempfile.TemporaryDirectory(prefix="prsm-health-upload-")
        upload = _Upload(Path(tmp.name))
        try:
            callbacks = {
                name: getattr(upload, name)
                for name in (
                    "on_part_begin",
                    "on_part_data",
                    "on_part_end",
                    "on_header_field",
                    "on_header_value",
                    "on_header_end",
                    "on_headers_finished",
                )
            }
            try:
                parser = MultipartParser(options[b"boundary"], callbacks)
                async for chunk in request.stream():
                    parser.write(chunk)
                    data = upload.take_pending()
                    if data:
                        await anyio.to_thread.run_sync(upload.write, data)
                parser.finalize()
            except _HTTPError:
                raise
            except (ValueError, LookupError) as exc:  # python-multipart's parse errors
                raise _HTTPError(422, f"malformed multipart body ({exc})") from None
            await anyio.to_thread.run_sync(upload.write, upload.take_pending())
            upload.close()
            asset_id = upload.fields.get("asset_id")
            if asset_id is not None:
                import re

                if not re.fullmatch(ASSET_ID_PATTERN, asset_id):
                    raise _HTTPError(422, f"asset_id {asset_id!r} must match {ASSET_ID_PATTERN}")
            result = await in_worker(diagnose_upload, upload)
        finally:
            upload.close()
            await anyio.to_thread.run_sync(tmp.cleanup)
        return result, asset_id, upload.filename

    @app.get(
        "/v1/assets/{asset_id}/history",
        summary="Stored diagnoses of an asset, oldest first",
        response_model=None,
        responses={
            200: {"model": models["History"]},
            404: {"model": models["Error"], "description": "no diagnosis stored for this asset"},
            422: error_responses[422],
        },
    )
    async def get_history(
        asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
        limit: Annotated[
            int, Query(ge=1, le=limits.max_history, description="most recent N")
        ] = 100,
        since: Annotated[
            str | None,
            Query(
                max_length=64,
                description="ISO-8601 time, inclusive; without zone: UTC",
                json_schema_extra={"format": "date-time"},
            ),
        ] = None,
    ):
        """The most recent `limit` diagnoses at or after `since`, returned oldest first."""
        if since is not None:
            parse_time(since)  # 422 before touching the store

        def read():
            if not store.has_asset(asset_id):
                raise _HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
            return _dumps(store.history(asset_id, since=since, limit=limit))

        return json_response(await anyio.to_thread.run_sync(read))

    @app.get(
        "/v1/health",
        summary="Liveness and model identity",
        response_model=None,
        responses={200: {"model": models["Health"]}},
    )
    async def get_health():
        return json_response(
            {
                "status": "ok",
                "model": bundle.name,
                "version": bundle.version,
                "uptime_s": round(time.monotonic() - started, 3),
                "warm": state["warm"],
                "active_diagnoses": state["active"],
            }
        )

    @app.get(
        "/v1/model",
        summary="Model metadata",
        response_model=None,
        responses={200: {"model": models["ModelInfo"]}},
    )
    async def get_model():
        return json_response(model_info)

    def openapi():
        # FastAPI documents the routes; the JSON request body (validated in a worker thread,
        # not by FastAPI on the event loop) is added from the same pydantic model.
        if app.openapi_schema:
            return app.openapi_schema
        schema = get_openapi(
            title=app.title, version=app.version, description=app.description, routes=app.routes
        )
        request_schema = models["DiagnoseRequest"].model_json_schema(
            ref_template="#/components/schemas/{model}"
        )
        components = schema.setdefault("components", {}).setdefault("schemas", {})
        components.update(request_schema.pop("$defs", {}))
        components["DiagnoseRequest"] = request_schema
        if token is not None:
            schema["components"]["securitySchemes"] = {
                "bearerAuth": {"type": "http", "scheme": "bearer"}
            }
            schema["security"] = [{"bearerAuth": []}]
        app.openapi_schema = schema
        return schema

    app.openapi = openapi

    def limit_for(path: str) -> int:
        if path == "/v1/diagnose":
            return limits.max_body_bytes
        if path == "/v1/diagnose/file":
            return limits.max_upload_bytes
        return limits.max_small_body_bytes

    app.add_middleware(_GuardMiddleware, token=token, limit_for=limit_for)
    return app


class _GuardMiddleware(_Guard):
    """:class:`_Guard` with the keyword signature Starlette's ``add_middleware`` uses."""

    def __init__(self, app, *, token, limit_for):
        super().__init__(app, token, limit_for)


# ============================================================================ serving
def is_loopback(host: str) -> bool:
    """Whether ``host`` (address or name) reaches this machine only."""
    host = host.strip().strip("[]")
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(host, None)
    except OSError:
        return False
    addresses = {info[4][0] for info in infos}
    return bool(addresses) and all(
        ipaddress.ip_address(a.split("%")[0]).is_loopback for a in addresses
    )


def check_bind(host: str, token: str | None) -> None:
    """Refuse to expose the service beyond this machine without a token."""
    if not is_loopback(host) and not token:
        raise PRSMHealthError(
            f"refusing to bind {host}: a non-loopback address requires a bearer token "
            f"(--token or the {TOKEN_ENV} environment variable); bind 127.0.0.1 to serve "
            "this machine only"
        )


def serve(
    host: str = "127.0.0.1",
    port: int = 8000,
    model_path: str | os.PathLike | None = None,
    db_path: str | os.PathLike | None = None,
    token: str | None = None,
    *,
    limits: ServiceLimits | None = None,
    log_level: str = "info",
) -> None:
    """Run the service on uvicorn until interrupted.

    Parameters
    ----------
    host : str
        Address to bind; a non-loopback one requires a token.
    port : int
    model_path, db_path : path or None
        Model bundle and history database (see :func:`create_app`).
    token : str or None
        Bearer token; None reads ``PRSM_HEALTH_TOKEN`` (unset or empty: no token).
    limits : ServiceLimits or None
    log_level : str
        uvicorn log level.

    Raises
    ------
    PRSMHealthError
        Non-loopback host without a token, bad port, unreadable model or database.
    """
    import uvicorn

    if token is None:
        token = os.environ.get(TOKEN_ENV) or None
    if not (isinstance(port, int) and 0 <= port <= 65535):
        raise PRSMHealthError(f"port = {port!r} must be an integer in [0, 65535]")
    check_bind(host, token)
    app = create_app(model_path, db_path, token, limits)
    sock = bind_socket(host, port)
    config = uvicorn.Config(
        app,
        log_level=log_level,
        server_header=False,
        proxy_headers=False,
        timeout_graceful_shutdown=10,
    )
    logging.getLogger("uvicorn.error").info(
        "prsm-health serving on http://%s:%d: model %s v%s, history %s, bearer token %s",
        f"[{host.strip('[]')}]" if ":" in host else host,
        sock.getsockname()[1],
        app.state.bundle.name,
        app.state.bundle.version,
        app.state.store.path,
        "required" if token else "not required (loopback only)",
    )
    try:
        uvicorn.Server(config).run(sockets=[sock])
    finally:
        sock.close()


def bind_socket(host: str, port: int) -> socket.socket:
    """A listening-ready TCP socket on ``host:port``; a clear error when that fails."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(
            host.strip("[]"), port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )[0]
    except socket.gaierror as exc:
        raise PRSMHealthError(f"--host {host}: cannot resolve ({exc.strerror})") from None
    sock = socket.socket(family, kind, proto)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
    except OSError as exc:
        sock.close()
        raise PRSMHealthError(f"cannot bind {host}:{port} ({exc.strerror or exc})") from None
    sock.set_inheritable(True)
    return sock
