"""Each asset against its own baseline, with the evidence of its recordings accumulated: the
service's side of :mod:`prsm_health.diagnostics.asset_history`.

A diagnose request that names an asset goes through three steps:

1. in the server, before the diagnosis: the asset's stored history gives its baseline
   (:func:`load_baseline`: ``AssetHistory.baseline`` with the model's priors,
   :func:`~prsm_health.diagnostics.asset_history.bundle_priors`), which crosses to the
   diagnosis worker as plain JSON (:class:`BaselineFor`);
2. in the worker: ``diagnose(run, bundle, baseline=…)``; what comes back for the asset is the
   recording's diagnosis (its windows left out) and the pieces of the answer around it
   (:class:`AssetPart`);
3. in the server, in one database transaction (:meth:`~.history.HistoryStore.update_asset`):
   the stored history read again, ``AssetHistory.record`` (idempotent per recording id), the
   new history, the request's diagnosis rows and the asset's state after the recording
   written, and the answer made with the diagnosis' ``asset`` part (:func:`record`).

A history's JSON grows with every recording; the store keeps it as a head (evidence, change
statistic) and one row per entry, so a recording writes one row, and the parsed histories are
held per asset and stored version (:class:`HistoryCache`), so a request parses nothing unless
another process changed the asset since.

The baseline read in step 1 and the history recorded in step 3 are read apart: a concurrent
request for the same asset may complete its baseline in between, and this recording's
diagnosis then was made without it — its record (baseline distance, evidence, change
statistic) is made in step 3 against the history as it is then, so no update is lost.
"""

from __future__ import annotations

import dataclasses
import hashlib
import re
import threading
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

from prsm_health.core.jsonable import dumps, json_ready
from prsm_health.diagnostics.asset_history import AssetHistory, bundle_priors
from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.contract import Diagnosis

from .history import AssetUpdate, HistoryStore, RecordingRow, StoredHistory
from .responses import encode

#: Length of a content hash used as a recording id (as ``prsm-health diagnose --asset``).
ID_LENGTH = 16


@dataclass(frozen=True)
class BaselineFor:
    """The baseline of the asset a request names, as it crosses to the diagnosis worker:
    ``Baseline.to_json()``, or None while the asset's baseline is incomplete."""

    asset_id: str
    baseline: dict | None = None

    def get(self, asset_id: str | None) -> Baseline | None:
        """The baseline, when the request's asset is the one it was loaded for (a JSON
        body's asset id is found before the body is parsed: :func:`peek_asset_id`)."""
        if self.baseline is None or asset_id != self.asset_id:
            return None
        return Baseline.from_json(self.baseline)


@dataclass(frozen=True)
class AssetPart:
    """What a diagnose request that names an asset gives back for the asset's history.

    The answer is made in the server once the diagnosis carries the asset's state
    (:meth:`answer`): ``head`` + the recording's diagnosis (``inner`` before its closing
    brace) + ``tail``. ``row``: the index of the history row that stores the recording's
    diagnosis (a JSON or binary body's one row; None for an upload, whose rows are its
    windows)."""

    asset_id: str
    recording_id: str
    diagnosis: Diagnosis
    source: str
    filename: str | None = None
    healthy: bool | None = None
    operating_hours: float | None = None
    head: bytes = b""
    inner: bytes = b""
    tail: bytes = b""
    row: int | None = None

    def answer(self, diagnosis: Diagnosis) -> tuple[bytes, bytes]:
        """(the answer, the recording's diagnosis) encoded, ``diagnosis`` as recorded."""
        recording = encode(json_ready(diagnosis.to_json()))
        recording = recording[:-1] + self.inner + b"}"
        return self.head + recording + self.tail, recording


def content_id(*parts: bytes | Path) -> str:
    """A recording id from content: SHA-256 over each part (bytes, or a file's bytes) followed
    by a NUL byte, its first :data:`ID_LENGTH` hex digits — for a file, the id
    :func:`prsm_health.diagnostics.asset_history.file_recording_id` gives it, so a file sent to
    the service and diagnosed with ``prsm-health diagnose --asset`` is one recording."""
    digest = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path):
            with open(part, "rb") as f:
                while chunk := f.read(1 << 20):
                    digest.update(chunk)
        else:
            digest.update(part)
        digest.update(b"\0")
    return digest.hexdigest()[:ID_LENGTH]


def run_id(run) -> str:
    """A recording id from a run's content: sample rate, first sample time, and each channel's
    name and float64 samples (in name order)."""
    import numpy as np

    parts = [f"{float(run.sample_rate)!r} {float(run.time[0])!r}".encode()]
    for name in sorted(run.channels):
        parts += [name.encode(), np.ascontiguousarray(run.channels[name], dtype=float).tobytes()]
    return content_id(*parts)


_ASSET_KEY = re.compile(rb'"asset_id"\s*:\s*"([A-Za-z0-9][A-Za-z0-9._:-]{0,127})"')


def peek_asset_id(body: bytes) -> str | None:
    """The asset id of a JSON body, found without parsing it (megabytes of samples): the last
    ``"asset_id": "…"`` key and plain value. Only a hint for loading the baseline before the
    diagnosis — the worker uses the baseline only for the asset id it parses
    (:meth:`BaselineFor.get`)."""
    at = body.rfind(b'"asset_id"')
    if at < 0:
        return None
    found = _ASSET_KEY.match(body, at)
    return None if found is None else found.group(1).decode()


class HistoryCache:
    """Parsed asset histories by asset, each valid for one stored version: a request whose
    asset's stored version is the one held parses nothing (a history's JSON grows with every
    recording). Holds at most ``max_entries`` entries in all, the least recently used asset
    dropped first. Thread-safe; the histories are frozen values."""

    def __init__(self, max_entries: int = 20_000):
        self.max_entries = max_entries
        self._items: OrderedDict[str, tuple[int, AssetHistory]] = OrderedDict()
        self._baselines: dict[str, tuple[tuple, object, dict | None]] = {}
        self._lock = threading.Lock()

    def baseline(self, asset_id: str, members: tuple, bundle) -> tuple[bool, dict | None]:
        """(held?, ``Baseline.to_json()`` or None) of the asset's baseline on the recordings
        ``members`` with the priors of ``bundle``: a baseline is fitted on its members alone
        (``AssetHistory.baseline``), which change far less often than the history."""
        with self._lock:
            held = self._baselines.get(asset_id)
        if held is None or held[0] != members or held[1] is not bundle:
            return False, None
        return True, held[2]

    def put_baseline(self, asset_id: str, members: tuple, bundle, baseline: dict | None) -> None:
        with self._lock:
            self._baselines.pop(asset_id, None)
            self._baselines[asset_id] = (members, bundle, baseline)
            while len(self._baselines) > 1024:  # the least recently fitted first
                del self._baselines[next(iter(self._baselines))]

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


def _cache(store: HistoryStore) -> HistoryCache:
    """The store's cache of parsed histories (one per store: versions are per database)."""
    cache = getattr(store, "parsed_histories", None)
    if cache is None:
        cache = store.parsed_histories = HistoryCache()
    return cache


def _history(store: HistoryStore, asset_id: str, version: int, load) -> AssetHistory:
    """The asset's history at ``version`` (0: a new one), parsed by ``load()`` unless held."""
    if version == 0:
        return AssetHistory(asset_id)
    cache = _cache(store)
    history = cache.get(asset_id, version)
    if history is None:
        history = AssetHistory.from_json(load())
        cache.put(asset_id, version, history)
    return history


def load_baseline(store: HistoryStore, bundle, asset_id: str | None) -> BaselineFor | None:
    """The asset's baseline from its stored history (None without an asset)."""
    if asset_id is None:
        return None
    version = store.asset_history_version(asset_id)
    history = _history(store, asset_id, version, lambda: store.asset_history(asset_id)[1])
    members = tuple(e.recording_id for e in history.entries if e.baseline)
    held, baseline = _cache(store).baseline(asset_id, members, bundle)
    if not held:
        # the check baseline: only a health check is read against a baseline (diagnose)
        prior_scale, _, names = bundle_priors(bundle, check=True)
        fitted = history.baseline(prior_scale, names)
        baseline = None if fitted is None else fitted.to_json()
        _cache(store).put_baseline(asset_id, members, bundle, baseline)
    return BaselineFor(asset_id, baseline)


def _head(history: AssetHistory) -> dict:
    """The history's JSON without its entries (stored apart, one row each)."""
    head = dataclasses.replace(history, entries=()).to_json()
    head.pop("entries")
    return head


def record(
    store: HistoryStore,
    bundle,
    part: AssetPart,
    rows: list,
    spectra: tuple | None,
    received_at: str,
) -> bytes:
    """Record the recording in its asset's history and store it with the request's diagnosis
    rows and spectra, in one transaction; the answer, its diagnosis with ``asset``."""
    # the priors and baseline of this kind of recording (a check read phase by phase, or windows)
    kind = bool(part.diagnosis.check_phases)
    prior_scale, training_prior, names = bundle_priors(bundle, check=kind)

    def update(stored: StoredHistory) -> AssetUpdate:
        history = _history(store, part.asset_id, stored.version, stored.load)
        new, diagnosis = history.record(
            part.recording_id,
            part.diagnosis,
            healthy=part.healthy,
            operating_hours=part.operating_hours,
            time=received_at,
            prior_scale=prior_scale,
            training_prior=training_prior,
            names=names,
            source=part.filename or part.source,
        )
        answer, recording = part.answer(diagnosis)
        stored_rows = list(rows)
        if part.row is not None:
            stored_rows[part.row] = stored_rows[part.row]._replace(diagnosis=recording.decode())
        if new is history:  # recorded before: nothing changes but the request's rows
            return AssetUpdate(None, stored_rows, spectra, answer=(None, answer))
        entry = new.entry(part.recording_id)
        entry_json = entry.to_json()
        state = entry_json.pop("state")
        row = RecordingRow(
            asset_id=part.asset_id,
            recording_id=part.recording_id,
            received_at=received_at,
            source=part.source,
            filename=part.filename,
            operating_hours=part.operating_hours,
            healthy=part.healthy,
            baseline=entry.baseline,
            distance=entry.distance,
            fault_class=entry.fault_class,
            class_probabilities=dumps(entry.class_probabilities, compact=True),
            asset=dumps(state, compact=True),
            entry=dumps(entry_json, compact=True),
        )
        # the new history is the old with one entry more at its end (the store writes that
        # entry alone); else every entry is rewritten
        appended = len(new.entries) == len(history.entries) + 1 and all(
            a is b for a, b in zip(new.entries, history.entries)
        )
        entries = None if appended else [e.to_json() for e in new.entries]
        return AssetUpdate(_head(new), stored_rows, spectra, row, entries, (new, answer))

    version, result = store.update_asset(part.asset_id, update, updated_at=received_at)
    new, answer = result.answer
    if new is not None:
        _cache(store).put(part.asset_id, version, new)
    return answer
