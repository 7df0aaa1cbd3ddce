"""The SQLite store's tables of each asset's own history (:class:`AssetTables`, a part of
:class:`~.sqlite_store.HistoryStore`): the :class:`~.store.AssetStore` interface on SQLite.
A history (:class:`~.asset.AssetHistory`) is stored as its head (``asset_histories``: evidence,
change statistic, the version) and one row per entry (``asset_recordings``: the recording,
whether it is in the baseline, its distance, the asset's state after it); a recording adds one
row and rewrites the head, whatever the length of the history, in the transaction that also
writes the request's diagnosis rows (:meth:`AssetTables.save`'s ``extra``)."""

from __future__ import annotations

import contextlib
import dataclasses
import json
import sqlite3
import threading
from collections import OrderedDict
from collections.abc import Iterator, Mapping
from typing import NamedTuple

from prsm_health.core.jsonable import dumps

from .asset import AssetEntry, AssetHistory, validate_asset_id
from .evidence import EVIDENCE_NAME_PROBABILITY
from .store import AssetStore, Stored, VersionConflict

#: The tables (schema version 4 of the history database).
ASSET_SCHEMA = """
CREATE TABLE IF NOT EXISTS asset_histories (
    asset_id            TEXT    PRIMARY KEY,  -- one row per asset, replaced by each recording
    version             INTEGER NOT NULL,     -- +1 with every change of the asset's history
    updated_at          TEXT    NOT NULL,     -- receive time of the recording that last changed it
    change_reference    REAL,                 -- its change statistic's (CUSUM) reference k
    change_threshold    REAL,                 -- and threshold h (as in the history)
    head                TEXT    NOT NULL      -- JSON: AssetHistory.to_json() without its entries
);
CREATE TABLE IF NOT EXISTS asset_recordings (  -- the history's entries, in rowid order
    asset_id            TEXT    NOT NULL,
    recording_id        TEXT    NOT NULL,     -- as given, else the recording's content hash
    received_at         TEXT    NOT NULL,     -- when it was first received
    source              TEXT    NOT NULL,
    filename            TEXT,
    operating_hours     REAL,                 -- [h]
    healthy             INTEGER,              -- as the client marked it: 1, 0, NULL (not said)
    baseline            INTEGER NOT NULL,     -- 1: the recording is in the asset's baseline
    distance            REAL,                 -- its distance from the baseline (NULL: none yet)
    fault_class         TEXT,                 -- the recording's own diagnosis
    class_probabilities TEXT    NOT NULL,     -- JSON object, the recording's own
    asset               TEXT    NOT NULL,     -- JSON: Diagnosis.asset after it (the entry's state)
    entry               TEXT    NOT NULL,     -- JSON: its AssetEntry without the state
    PRIMARY KEY (asset_id, recording_id)
);
"""


class RecordingRow(NamedTuple):
    """One row of the ``asset_recordings`` table, named after its columns: an entry of an
    asset's history — a recording and the asset's state after it
    (:meth:`HistoryStore.update_asset`); JSON already encoded."""

    asset_id: str
    recording_id: str
    received_at: str
    source: str
    filename: str | None
    operating_hours: float | None
    healthy: bool | None
    baseline: bool
    distance: float | None
    fault_class: str | None
    class_probabilities: str
    asset: str
    entry: str


def insert_statement(verb: str, table: str, row_type: type[NamedTuple]) -> str:
    """The ``INSERT`` statement of a row type, its values bound by column name."""
    columns = row_type._fields
    return (
        f"{verb} INTO {table} ({', '.join(columns)}) VALUES ({', '.join(':' + c for c in columns)})"
    )


# (a row of the same recording id is replaced: the history's new entry is its last)
_INSERT_RECORDING = insert_statement("INSERT OR REPLACE", "asset_recordings", RecordingRow)


def named_rows(cursor: sqlite3.Cursor) -> list[dict]:
    """A query's rows as dicts by column name (``AS`` names for expressions)."""
    names = [d[0] for d in cursor.description]
    return [dict(zip(names, row)) for row in cursor.fetchall()]


class HistoryCache:
    """Parsed asset histories by asset, each valid for one stored version: a load at the
    version held parses nothing (a history's JSON grows with every recording). Holds at most
    ``max_entries`` entries in all, the least recently used asset dropped first."""

    def __init__(self, max_entries: int = 20_000):
        self.max_entries = max_entries
        self._items: OrderedDict[str, tuple[int, AssetHistory]] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, asset_id: str, version: int) -> AssetHistory | None:
        with self._lock:
            held = self._items.get(asset_id)
            if held is None or held[0] != version:
                return None
            self._items.move_to_end(asset_id)
            return held[1]

    def put(self, asset_id: str, version: int, history: AssetHistory) -> None:
        with self._lock:
            self._items[asset_id] = (version, history)
            self._items.move_to_end(asset_id)
            total = sum(len(h.entries) for _, h in self._items.values())
            while total > self.max_entries and len(self._items) > 1:
                _, (_, dropped) = self._items.popitem(last=False)
                total -= len(dropped.entries)


def recording_row(asset_id: str, entry: AssetEntry) -> RecordingRow:
    """The ``asset_recordings`` row of a history's entry."""
    data = entry.to_json()
    state = data.pop("state")
    return RecordingRow(
        asset_id=asset_id,
        recording_id=entry.recording_id,
        received_at=entry.time,
        source=entry.source,
        filename=entry.filename,
        operating_hours=entry.operating_hours,
        healthy=entry.healthy,
        baseline=entry.baseline,
        distance=entry.distance,
        fault_class=entry.fault_class,
        class_probabilities=dumps(entry.class_probabilities, compact=True),
        asset=dumps(state, compact=True),
        entry=dumps(data, compact=True),
    )


class AssetTables(AssetStore):
    """The asset-history part of :class:`~.sqlite_store.HistoryStore`: the store interface
    on its connection, lock (``self._lock``, re-entrant) and transactions. The lock of an
    asset (:meth:`locked`) is the database's write lock (``BEGIN IMMEDIATE``): concurrent
    recordings, from this process or another, apply one after the other."""

    def _history_version(self, asset_id: str) -> int:
        row = self._conn.execute(
            "SELECT version FROM asset_histories WHERE asset_id = ?", (asset_id,)
        ).fetchone()
        return 0 if row is None else row[0]

    def _load_history(self, asset_id: str) -> dict | None:
        # under self._lock
        head = self._conn.execute(
            "SELECT head FROM asset_histories WHERE asset_id = ?", (asset_id,)
        ).fetchone()
        if head is None:
            return None
        entries = [
            {**json.loads(entry), "state": json.loads(state)}
            for entry, state in self._conn.execute(
                "SELECT entry, asset FROM asset_recordings WHERE asset_id = ? ORDER BY rowid",
                (asset_id,),
            )
        ]
        return {**json.loads(head[0]), "entries": entries}

    def load(self, asset_id: str) -> Stored:
        """The asset's stored history and version (a new, empty one at version 0); parsed
        only when the version held in the cache is not the stored one."""
        validate_asset_id(asset_id)
        with self._lock:
            version = self._history_version(asset_id)
            if version == 0:
                return Stored(0, AssetHistory(asset_id))
            history = self._parsed.get(asset_id, version)
            if history is None:
                history = AssetHistory.from_json(self._load_history(asset_id))
                self._parsed.put(asset_id, version, history)
        return Stored(version, history)

    def save(self, history: AssetHistory, *, expected_version: int, extra=None) -> int:
        """Write ``history`` if the stored version is ``expected_version`` (else
        :class:`VersionConflict`), with ``extra`` — ``(diagnosis rows, spectra row)`` of the
        request (:meth:`~.sqlite_store.HistoryStore.add_rows`) — in the same transaction.
        A history that is the one stored plus one entry writes that entry alone."""
        asset_id = history.asset_id
        with self.locked(asset_id):
            version = self._history_version(asset_id)
            if version != expected_version:
                raise VersionConflict(
                    f"{self.path}: asset {asset_id!r} is at version {version}, not "
                    f"{expected_version}: another request changed it; load it again"
                )
            old = self._parsed.get(asset_id, version) if version else AssetHistory(asset_id)
            appended = (
                old is not None
                and len(history.entries) == len(old.entries) + 1
                and all(a is b for a, b in zip(history.entries, old.entries))
            )
            if not appended:
                self._conn.execute("DELETE FROM asset_recordings WHERE asset_id = ?", (asset_id,))
            for entry in history.entries[-1:] if appended else history.entries:
                self._conn.execute(_INSERT_RECORDING, recording_row(asset_id, entry)._asdict())
            updated_at = history.entries[-1].time if history.entries else ""
            self._write_head(asset_id, version + 1, updated_at, _head(history))
            if extra is not None:
                self._write_rows(*extra)
            self._parsed.put(asset_id, version + 1, history)
            return version + 1

    def store_beside(self, asset_id: str, extra) -> None:
        """The request's diagnosis rows and spectra (``extra``), the history unchanged."""
        if extra is not None:
            with self.locked(asset_id):
                self._write_rows(*extra)

    @contextlib.contextmanager
    def locked(self, asset_id: str) -> Iterator[None]:
        """The database's write lock for the block (one transaction; re-entrant)."""
        with self._lock, self._transaction():
            yield

    def asset_ids(self) -> list[str]:
        with self._lock:
            rows = self._conn.execute("SELECT asset_id FROM asset_histories ORDER BY asset_id")
            return [r[0] for r in rows]

    def _write_head(self, asset_id: str, version: int, updated_at: str, head: dict) -> None:
        cusum = head.get("cusum") or {}
        self._conn.execute(
            "INSERT OR REPLACE INTO asset_histories (asset_id, version, updated_at,"
            " change_reference, change_threshold, head) VALUES (?, ?, ?, ?, ?, ?)",
            (
                asset_id,
                version,
                updated_at,
                cusum.get("reference"),
                cusum.get("threshold"),
                dumps(head, compact=True),
            ),
        )

    def recordings(self, asset_id: str, *, limit: int = 100) -> dict:
        """The asset's state after each of its ``limit`` most recent recordings, in the order
        they were recorded (oldest first): ``{"asset_id", "count", "total", "truncated",
        "recordings": [...]}``, each with the recording's id, provenance, operating hours,
        whether the client marked it healthy and whether it is in the baseline, its distance
        from the baseline, its own fault class and class probabilities, and ``asset`` (the
        Diagnosis contract's ``asset`` after it: baseline and accumulated evidence)."""
        with self._lock:
            total = self._conn.execute(
                "SELECT COUNT(*) FROM asset_recordings WHERE asset_id = ?", (asset_id,)
            ).fetchone()[0]
            rows = named_rows(
                self._conn.execute(
                    "SELECT recording_id, received_at, source, filename, operating_hours,"
                    " healthy, baseline, distance, fault_class, class_probabilities, asset"
                    " FROM asset_recordings WHERE asset_id = ? ORDER BY rowid DESC LIMIT ?",
                    (asset_id, int(limit)),
                )
            )
        entries = [_recording(row) for row in reversed(rows)]
        return {
            "asset_id": asset_id,
            "count": len(entries),
            "total": total,
            "truncated": total > len(entries),
            "recordings": entries,
        }

    def _asset_state(self, asset_id: str) -> tuple[dict | None, dict | None]:
        """The asset's baseline (how many recordings it has and needs, which they are) and
        its evidence after its latest recording, from the stored states (None, None: none
        recorded). Under self._lock."""
        latest = self._conn.execute(
            "SELECT asset, distance, recording_id FROM asset_recordings WHERE asset_id = ?"
            " ORDER BY rowid DESC LIMIT 1",
            (asset_id,),
        ).fetchone()
        if latest is None:
            return None, None
        state = json.loads(latest[0])
        members = named_rows(
            self._conn.execute(
                "SELECT recording_id, received_at, source, filename, operating_hours, healthy"
                " FROM asset_recordings WHERE asset_id = ? AND baseline ORDER BY rowid",
                (asset_id,),
            )
        )
        for member in members:
            member["healthy"] = _flag(member["healthy"])
        change = self._conn.execute(
            "SELECT change_reference, change_threshold FROM asset_histories WHERE asset_id = ?",
            (asset_id,),
        ).fetchone() or (None, None)
        base = state.get("baseline") or {}
        baseline = {
            "recordings": base.get("recordings", len(members)),
            "needed": base.get("needed"),
            "members": members,
        }
        evidence = {
            **(state.get("evidence") or {}),
            "name_probability": EVIDENCE_NAME_PROBABILITY,
            "change_reference": change[0],
            "change_threshold": change[1],
            "latest_recording": latest[2],
            "distance": latest[1],
        }
        return baseline, evidence


def _flag(value) -> bool | None:
    return None if value is None else bool(value)


def _recording(row: Mapping) -> dict:
    """A stored ``asset_recordings`` row (by column name) as the API gives it."""
    return {
        "recording_id": row["recording_id"],
        "received_at": row["received_at"],
        "source": row["source"],
        "filename": row["filename"],
        "operating_hours": row["operating_hours"],
        "healthy": _flag(row["healthy"]),
        "baseline": bool(row["baseline"]),
        "distance": row["distance"],
        "fault_class": row["fault_class"],
        "class_probabilities": json.loads(row["class_probabilities"]),
        "asset": json.loads(row["asset"]),
    }


def _head(history: AssetHistory) -> dict:
    """The history's JSON without its entries (stored apart, one row each)."""
    head = dataclasses.replace(history, entries=()).to_json()
    head.pop("entries")
    return head
