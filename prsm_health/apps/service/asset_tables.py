"""The store's tables of each asset's own history (:class:`AssetTables`, a part of
:class:`~.history.HistoryStore`): the history the library keeps
(:class:`prsm_health.diagnostics.asset_history.AssetHistory`) stored as its head
(``asset_histories``: evidence, change statistic, a version) and one row per entry
(``asset_recordings``: the recording, whether it is in the baseline, its distance, the asset's
state after it), written a recording at a time in the transaction of the request's diagnosis
rows (:meth:`AssetTables.update_asset`), and read back as the asset's baseline, evidence and
per-recording states."""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable, Mapping
from typing import NamedTuple

from prsm_health.core.jsonable import dumps
from prsm_health.diagnostics.baseline import EVIDENCE_NAME_PROBABILITY

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


class AssetUpdate(NamedTuple):
    """What :meth:`HistoryStore.update_asset` writes in one transaction.

    ``head``: the asset's history without its entries (``AssetHistory.to_json()`` but
    ``entries``; None: the history is unchanged); ``recording``: its new last entry (None:
    none); ``entries``: only when the history's earlier entries changed too — every entry
    (``AssetEntry.to_json()``), rewritten in place by recording id, those no longer there
    removed; ``rows``, ``spectra``: the request's diagnosis rows and latest spectra;
    ``answer``: whatever the caller wants back (not stored)."""

    head: dict | None
    rows: list
    spectra: tuple | None = None
    recording: RecordingRow | None = None
    entries: list | None = None
    answer: object = None


class StoredHistory(NamedTuple):
    """An asset's stored history as :meth:`HistoryStore.update_asset` hands it over: its
    ``version`` (0: none stored) and, on demand, its JSON (``AssetHistory.to_json()``,
    reassembled from its head and entry rows: ``load()``, None when none is stored), so that
    a caller holding that version already parses nothing."""

    version: int
    load: Callable[[], dict | None]


def _insert(verb: str, table: str, row_type: type[NamedTuple]) -> str:
    """The ``INSERT`` statement of a row type, its values bound by column name."""
    columns = row_type._fields
    return (
        f"{verb} INTO {table} ({', '.join(columns)}) VALUES ({', '.join(':' + c for c in columns)})"
    )


# (a row of the same recording id is replaced: the history's new entry is its last)
_INSERT_RECORDING = _insert("INSERT OR REPLACE", "asset_recordings", RecordingRow)


def _named(cursor: sqlite3.Cursor) -> list[dict]:
    """A query's rows as dicts by column name (``AS`` names for expressions)."""
    names = [d[0] for d in cursor.description]
    return [dict(zip(names, row)) for row in cursor.fetchall()]


class AssetTables:
    """The asset-history part of :class:`~.history.HistoryStore`: it uses the store's
    connection, lock and transaction, and its :meth:`~.history.HistoryStore._write_rows`."""

    def asset_history(self, asset_id: str) -> tuple[int, dict | None]:
        """The asset's stored history: (version, ``AssetHistory.to_json()``); (0, None)
        when none is stored."""
        with self._lock:
            version = self._history_version(asset_id)
            return version, self._load_history(asset_id)

    def asset_history_version(self, asset_id: str) -> int:
        """The version of the asset's stored history (0: none)."""
        with self._lock:
            return self._history_version(asset_id)

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

    def update_asset(
        self, asset_id: str, update: Callable[[StoredHistory], AssetUpdate], *, updated_at: str
    ) -> tuple[int, AssetUpdate]:
        """Read, change and write the asset's history in one transaction: ``update`` is given
        the stored history (:class:`StoredHistory`) and returns the :class:`AssetUpdate` to
        write — the new history's head and entry, the request's diagnosis rows and spectra.
        Returns the history's version after it, and the update.

        The write lock is taken before the read (``BEGIN IMMEDIATE``), so concurrent requests
        for one asset, from this process or another, apply one after the other and none loses
        the other's update; ``update`` raising writes nothing. A new recording writes its one
        entry row and the head, whatever the length of the history."""
        with self._lock, self._transaction():
            version = self._history_version(asset_id)
            result = update(StoredHistory(version, lambda: self._load_history(asset_id)))
            if result.head is not None:
                version += 1
                self._write_head(asset_id, version, updated_at, result.head)
            if result.entries is not None:
                self._rewrite_entries(asset_id, result.entries)
            self._write_rows(result.rows, result.spectra)
            if result.recording is not None:
                self._conn.execute(_INSERT_RECORDING, result.recording._asdict())
        return version, result

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
                dumps({k: v for k, v in head.items() if k != "entries"}, compact=True),
            ),
        )

    def _rewrite_entries(self, asset_id: str, entries: list[dict]) -> None:
        """The stored entries replaced by ``entries`` (by recording id, in place: their order
        stays the order recorded); rows of recording ids no longer there removed."""
        kept = []
        for e in entries:
            kept.append(e["recording_id"])
            self._conn.execute(
                "UPDATE asset_recordings SET baseline = ?, distance = ?, asset = ?, entry = ?"
                " WHERE asset_id = ? AND recording_id = ?",
                (
                    bool(e.get("baseline")),
                    e.get("distance"),
                    dumps(e.get("state"), compact=True),
                    dumps({k: v for k, v in e.items() if k != "state"}, compact=True),
                    asset_id,
                    e["recording_id"],
                ),
            )
        marks = ", ".join("?" * len(kept))
        self._conn.execute(
            f"DELETE FROM asset_recordings WHERE asset_id = ? AND recording_id NOT IN ({marks})",
            (asset_id, *kept),
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
            rows = _named(
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
        members = _named(
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
