"""The service's store: diagnoses per asset over time in an embedded SQLite database
(:class:`HistoryStore`, WAL journal), its default location (:func:`default_db_path`), its time
format (:func:`utc_now`, :func:`parse_time`) and each asset's latest window spectra
(:func:`spectra_row`). Each asset's own history — its baseline and accumulated evidence — is
kept in the store's asset tables (:mod:`.sqlite_assets`), through the
:class:`~.store.AssetStore` interface the CLI's file store offers too."""

from __future__ import annotations

import contextlib
import json
import os
import sqlite3
import threading
from collections.abc import Mapping
from datetime import datetime, timezone
from pathlib import Path
from typing import NamedTuple

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps, json_ready
from prsm_health.diagnostics.check_verdicts import check_verdicts

from .asset import OperatingRow
from .sqlite_assets import ASSET_SCHEMA, AssetTables, HistoryCache, insert_statement, named_rows
from .status import asset_status

#: Environment variable overriding the default history database path.
DB_ENV = "PRSM_HEALTH_DB"


def default_db_path() -> Path:
    """``$PRSM_HEALTH_DB``, else ``$XDG_DATA_HOME/prsm-health/history.sqlite``."""
    if os.environ.get(DB_ENV):
        return Path(os.environ[DB_ENV])
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "prsm-health" / "history.sqlite"


_SCHEMA = (
    """
CREATE TABLE IF NOT EXISTS diagnoses (
    id                  INTEGER PRIMARY KEY AUTOINCREMENT,
    asset_id            TEXT    NOT NULL,
    received_at         TEXT    NOT NULL,  -- server receive time, UTC ISO-8601 (microseconds)
    source              TEXT    NOT NULL,  -- 'json', 'arrow', 'parquet', 'mcap' or 'file'
    filename            TEXT,              -- uploaded file name (source 'file')
    window_index        INTEGER,           -- per-window rows of an upload
    window_start        REAL,              -- [s]
    window_end          REAL,              -- [s]
    speed               REAL,              -- nominal screw speed given by the client [rad/s]
    load                REAL,              -- nominal axial load given by the client [N]
    operating_hours     REAL,              -- asset's operating hours at the recording [h]
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
CREATE TABLE IF NOT EXISTS spectra (
    asset_id            TEXT    PRIMARY KEY,  -- one row per asset, replaced by each recording
    received_at         TEXT    NOT NULL,     -- as the diagnosis it came with
    source              TEXT    NOT NULL,
    filename            TEXT,
    window_index        INTEGER,              -- the recording's last window
    window_start        REAL,                 -- [s]
    window_end          REAL,                 -- [s]
    operating_hours     REAL,                 -- [h]
    channel             TEXT    NOT NULL,     -- 'nut_axial_accel'
    spectra             TEXT    NOT NULL      -- JSON: prsm_health.signals.envelope_analysis.window_spectra
);
"""
    + ASSET_SCHEMA
)
#: Version 1: the diagnoses table without ``operating_hours``; version 2 added it (a version 1
#: database gets the column on open, its existing rows NULL); version 3 added the ``spectra``
#: table (created on open: ``CREATE TABLE IF NOT EXISTS`` above); version 4 the
#: ``asset_histories`` and ``asset_recordings`` tables (created on open, empty: an asset's
#: baseline and evidence start with its next recording).
_SCHEMA_VERSION = 4


class DiagnosisRow(NamedTuple):
    """One row of the ``diagnoses`` table (every column but ``id``), named after its columns:
    plain numbers and text, JSON already encoded (:func:`history_rows`)."""

    asset_id: str
    received_at: str
    source: str
    filename: str | None
    window_index: int | None
    window_start: float | None
    window_end: float | None
    speed: float | None
    load: float | None
    operating_hours: float | None
    clearance_estimate: float | None
    clearance_lower: float | None
    clearance_upper: float | None
    fault_class: str | None
    class_probabilities: str
    model_name: str
    model_version: str
    diagnosis: str


class SpectraRow(NamedTuple):
    """One row of the ``spectra`` table, named after its columns (:func:`spectra_row`)."""

    asset_id: str
    received_at: str
    source: str
    filename: str | None
    window_index: int | None
    window_start: float | None
    window_end: float | None
    operating_hours: float | None
    channel: str
    spectra: str


_INSERT_DIAGNOSIS = insert_statement("INSERT", "diagnoses", DiagnosisRow)
_INSERT_SPECTRA = insert_statement("INSERT OR REPLACE", "spectra", SpectraRow)


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


class HistoryStore(AssetTables):
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
        self._lock = threading.RLock()
        #: Parsed asset histories, by asset and stored version (versions are per database)
        self._parsed = HistoryCache()
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
                self._migrate()
                self._conn.execute(f"PRAGMA user_version = {_SCHEMA_VERSION}")
        except BaseException as exc:
            self._conn.close()
            if isinstance(exc, sqlite3.DatabaseError):
                raise PRSMHealthError(
                    f"{self.path}: not a usable history database ({exc})"
                ) from None
            raise

    def _migrate(self) -> None:
        """Bring older tables up to the current schema (inside the opening transaction, so
        two processes opening the same file migrate it once): version 1 → 2 adds the nullable
        ``operating_hours`` column; version 2 → 3 adds the ``spectra`` table, which the schema's
        ``CREATE TABLE IF NOT EXISTS`` has created just before (empty: spectra come with the
        next recordings); version 3 → 4 adds the ``asset_histories`` and ``asset_recordings``
        tables the same way (empty: each asset's baseline and evidence start with its next
        recording; its stored diagnoses are not replayed into them)."""
        columns = {row[1] for row in self._conn.execute("PRAGMA table_info(diagnoses)")}
        if "operating_hours" not in columns:
            self._conn.execute("ALTER TABLE diagnoses ADD COLUMN operating_hours REAL")

    @contextlib.contextmanager
    def _transaction(self):
        """One write transaction (under ``self._lock``); inside one already, that one."""
        if self._conn.in_transaction:
            yield
            return
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
        operating_hours: float | None = None,
    ) -> list[int]:
        """Store diagnoses (contract dicts; a ``window`` key places one in its recording) in
        one transaction; returns their ids."""
        return self.add_rows(
            history_rows(
                asset_id,
                diagnoses,
                received_at=received_at,
                source=source,
                filename=filename,
                speed=speed,
                load=load,
                operating_hours=operating_hours,
            )
        )

    def add_rows(self, rows: list[DiagnosisRow], spectra: SpectraRow | None = None) -> list[int]:
        """Store rows made by :func:`history_rows` (possibly in another process) and, when
        given, the asset's latest spectra (a :func:`spectra_row`, replacing the asset's
        previous one) in one transaction; returns the rows' ids. Plain tuples in column
        order are taken too."""
        with self._lock, self._transaction():
            return self._write_rows(rows, spectra)

    def _write_rows(self, rows: list, spectra: tuple | None) -> list[int]:
        # under self._lock, in a transaction
        if spectra is not None:
            self._conn.execute(_INSERT_SPECTRA, SpectraRow._make(spectra)._asdict())
        return [
            self._conn.execute(_INSERT_DIAGNOSIS, DiagnosisRow._make(row)._asdict()).lastrowid
            for row in rows
        ]

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
            rows = named_rows(
                self._conn.execute(
                    "SELECT id, received_at, source, filename, window_index, window_start,"
                    " window_end, speed, load, operating_hours, diagnosis FROM diagnoses"
                    f" WHERE {where} ORDER BY received_at DESC, id DESC LIMIT ?",
                    [*args, int(limit)],
                )
            )
        entries = [
            {
                "id": row["id"],
                **_provenance(row),
                "speed": row["speed"],
                "load": row["load"],
                "operating_hours": row["operating_hours"],
                "diagnosis": json.loads(row["diagnosis"]),
            }
            for row in reversed(rows)
        ]
        return {
            "asset_id": asset_id,
            "count": len(entries),
            "total": total,
            "truncated": total > len(entries),
            "diagnoses": entries,
        }

    def operating_history(self, asset_id: str) -> list[OperatingRow]:
        """The asset's diagnoses stored with operating hours, by operating hours, then by
        receive time and id (the latest received last), the design being the diagnosing
        model's (``model.design`` of the stored diagnosis)."""
        with self._lock:
            rows = named_rows(
                self._conn.execute(
                    "SELECT operating_hours, clearance_estimate, clearance_lower,"
                    " clearance_upper, fault_class,"
                    " json_extract(diagnosis, '$.model.design') AS design FROM diagnoses"
                    " WHERE asset_id = ? AND operating_hours IS NOT NULL"
                    " ORDER BY operating_hours, received_at, id",
                    (asset_id,),
                )
            )
        return [OperatingRow(**row) for row in rows]

    def spectra(self, asset_id: str) -> dict | None:
        """The asset's latest stored spectra (:func:`spectra_row`), or None."""
        with self._lock:
            rows = named_rows(
                self._conn.execute("SELECT * FROM spectra WHERE asset_id = ?", (asset_id,))
            )
        if not rows:
            return None
        row = rows[0]
        return {
            "asset_id": asset_id,
            **_provenance(row),
            "operating_hours": row["operating_hours"],
            "channel": row["channel"],
            **json.loads(row["spectra"]),
        }

    def assets(self, *, limit: int = 100) -> dict:
        """The ``limit`` most recently seen assets, most recent first, each as
        :meth:`asset_summary` gives it: ``{"count", "total", "truncated", "assets": [...]}``."""
        with self._lock:
            total = self._conn.execute("SELECT COUNT(DISTINCT asset_id) FROM diagnoses").fetchone()[
                0
            ]
            page = self._conn.execute(
                "SELECT asset_id, COUNT(*), MIN(received_at), MAX(received_at) FROM diagnoses"
                " GROUP BY asset_id ORDER BY MAX(received_at) DESC, asset_id LIMIT ?",
                (int(limit),),
            ).fetchall()
            summaries = [self._summary(*row) for row in page]
        return {
            "count": len(summaries),
            "total": total,
            "truncated": total > len(summaries),
            "assets": summaries,
        }

    def asset_summary(self, asset_id: str) -> dict | None:
        """One asset: ``asset_id``, ``diagnoses`` (how many are stored), ``with_operating_hours``
        (how many of them have operating hours), ``operating_hours`` (the largest sent [h] or
        None), ``first_received_at``, ``last_received_at``, ``latest`` (the latest stored
        diagnosis in brief: receive time, source, file name, window, operating hours,
        clearance, fault class, class probabilities, warnings, model, observability, undecided
        (null when the diagnosis names a class) and, of a health check,
        ``check``: its phases' verdicts, :func:`~prsm_health.diagnostics.check_verdicts.check_verdicts`),
        ``spectra_received_at`` (when its stored spectra came, or None), ``baseline``,
        ``evidence`` and ``status`` (:func:`~.status.asset_status`); None when nothing is
        stored for it."""
        with self._lock:
            row = self._conn.execute(
                "SELECT asset_id, COUNT(*), MIN(received_at), MAX(received_at) FROM diagnoses"
                " WHERE asset_id = ? GROUP BY asset_id",
                (asset_id,),
            ).fetchone()
            return None if row is None else self._summary(*row)

    def _summary(self, asset_id: str, count: int, first: str, last: str) -> dict:
        # under self._lock
        (latest,) = named_rows(
            self._conn.execute(
                "SELECT received_at, source, filename, window_index, window_start, window_end,"
                " operating_hours, clearance_estimate, clearance_lower, clearance_upper,"
                " fault_class, class_probabilities,"
                " json_extract(diagnosis, '$.warnings') AS warnings,"
                " json_extract(diagnosis, '$.model') AS model,"
                " json_extract(diagnosis, '$.observability') AS observability,"
                " json_extract(diagnosis, '$.undecided') AS undecided,"
                # the whole diagnosis of a check only: its phases' verdicts are read from it
                " CASE WHEN json_extract(diagnosis, '$.check_phases') IS NOT NULL"
                " THEN diagnosis END AS check_diagnosis FROM diagnoses WHERE asset_id = ?"
                " ORDER BY received_at DESC, id DESC LIMIT 1",
                (asset_id,),
            )
        )
        with_hours, max_hours = self._conn.execute(
            "SELECT COUNT(operating_hours), MAX(operating_hours) FROM diagnoses WHERE asset_id = ?",
            (asset_id,),
        ).fetchone()
        spectra = self._conn.execute(
            "SELECT received_at FROM spectra WHERE asset_id = ?", (asset_id,)
        ).fetchone()
        baseline, evidence = self._asset_state(asset_id)
        warnings, model = latest["warnings"], latest["model"]
        check = latest["check_diagnosis"]
        return {
            "asset_id": asset_id,
            "diagnoses": count,
            "with_operating_hours": with_hours,
            "operating_hours": max_hours,
            "first_received_at": first,
            "last_received_at": last,
            "latest": {
                **_provenance(latest),
                "operating_hours": latest["operating_hours"],
                "clearance": {
                    "estimate": latest["clearance_estimate"],
                    "lower": latest["clearance_lower"],
                    "upper": latest["clearance_upper"],
                },
                "fault_class": latest["fault_class"],
                "class_probabilities": json.loads(latest["class_probabilities"]),
                "warnings": json.loads(warnings) if warnings else [],
                "model": json.loads(model) if model else None,
                # what the pages need to show a target the model could not see as such
                "observability": _json_or_none(latest["observability"]),
                "undecided": _json_or_none(latest["undecided"]),
                "check": check_verdicts(json.loads(check)) if check else None,
            },
            "spectra_received_at": None if spectra is None else spectra[0],
            "baseline": baseline,
            "evidence": evidence,
            "status": asset_status(evidence, baseline, latest["fault_class"]),
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


def _json_or_none(text: str | None):
    """A JSON value read by ``json_extract`` (None where the diagnosis has no such field)."""
    return None if text is None else json.loads(text)


def _provenance(row: Mapping) -> dict:
    """Where a stored row (by column name) came from: when, which body kind and file, which
    window."""
    return {
        "received_at": row["received_at"],
        "source": row["source"],
        "filename": row["filename"],
        "window": None
        if row["window_index"] is None
        else {"index": row["window_index"], "start": row["window_start"], "end": row["window_end"]},
    }


def history_rows(
    asset_id: str,
    diagnoses: list[dict],
    *,
    received_at: str | None = None,
    source: str = "json",
    filename: str | None = None,
    speed: float | None = None,
    load: float | None = None,
    operating_hours: float | None = None,
    texts: list[str] | None = None,
) -> list[DiagnosisRow]:
    """The database rows of diagnoses (contract dicts; a ``window`` key places one in its
    recording) for :meth:`HistoryStore.add_rows`; ``texts``: their JSON when already encoded
    (the service's answer, stored as it was sent), else encoded here."""
    received_at = received_at or utc_now()
    rows = []
    for i, d in enumerate(diagnoses):
        c = d.get("clearance") or {}
        w = d.get("window") or {}
        model = d.get("model") or {}
        rows.append(
            DiagnosisRow(
                asset_id=asset_id,
                received_at=received_at,
                source=source,
                filename=filename,
                window_index=w.get("index"),
                window_start=w.get("start"),
                window_end=w.get("end"),
                speed=speed,
                load=load,
                operating_hours=operating_hours,
                clearance_estimate=c.get("estimate"),
                clearance_lower=c.get("lower"),
                clearance_upper=c.get("upper"),
                fault_class=d.get("fault_class"),
                class_probabilities=dumps(d.get("class_probabilities", {})),
                model_name=str(model.get("name", "")),
                model_version=str(model.get("version", "")),
                diagnosis=dumps(d) if texts is None else texts[i],
            )
        )
    return rows


def spectra_row(
    asset_id: str,
    spectra: dict,
    *,
    received_at: str,
    source: str,
    filename: str | None = None,
    window: dict | None = None,
    operating_hours: float | None = None,
    channel: str = "nut_axial_accel",
) -> SpectraRow:
    """The ``spectra`` row of an asset's latest window (``spectra``:
    :func:`prsm_health.signals.envelope_analysis.window_spectra`, JSON encoded here) for
    :meth:`HistoryStore.add_rows`."""
    w = window or {}
    # The spectra's thousands of plain floats go to json.dumps directly (json_ready would
    # visit each); the line ratios, NaN where a line lies outside the band, become null.
    small = {k: v for k, v in spectra.items() if k not in ("spectrum", "envelope")}
    try:
        text = json.dumps(
            {**json_ready(small), "spectrum": spectra["spectrum"], "envelope": spectra["envelope"]},
            separators=(",", ":"),
            allow_nan=False,
        )
    except (ValueError, TypeError):  # a non-finite or non-plain value among them after all
        text = dumps(spectra, compact=True)
    return SpectraRow(
        asset_id=asset_id,
        received_at=received_at,
        source=source,
        filename=filename,
        window_index=w.get("index"),
        window_start=w.get("start"),
        window_end=w.get("end"),
        operating_hours=operating_hours,
        channel=channel,
        spectra=text,
    )
