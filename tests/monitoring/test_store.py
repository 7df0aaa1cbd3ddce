"""The store interface (prsm_health.monitoring.store.AssetStore), run against both backends —
the CLI's JSON files and the service's SQLite database: versioned load, compare-and-swap
save, the lock, the update sequence, and the steps of monitoring on top of it. Synthetic
diagnoses, no model; the file backend's own failure modes (atomic save, a damaged file) at
the end."""

import json
import os
import threading

import pytest
from test_asset_history import BASE, PRIOR, WEAR, diagnosis, recorded

from prsm_health.core.errors import PRSMHealthError
from prsm_health.monitoring import AssetHistory, FileAssetStore, VersionConflict
from prsm_health.monitoring.sqlite_store import HistoryStore
from prsm_health.monitoring.steps import record_diagnosis


@pytest.fixture(params=["files", "sqlite"])
def store(request, tmp_path):
    if request.param == "files":
        yield FileAssetStore(tmp_path / "assets")
    else:
        db = HistoryStore(tmp_path / "history.sqlite")
        yield db
        db.close()


def test_an_unknown_asset_loads_empty_at_version_0(store):
    stored = store.load("pump:7")
    assert stored.version == 0 and stored.history == AssetHistory("pump:7")
    assert store.asset_ids() == []


def test_save_then_load_round_trips_with_a_new_version(store):
    h, _ = recorded(BASE)
    assert store.save(h, expected_version=0) == 1
    stored = store.load("unit-1")
    assert stored.version == 1 and stored.history == h
    longer, _ = recorded([*BASE, (1.5, 12.0, WEAR)])
    assert store.save(longer, expected_version=1) == 2
    assert store.load("unit-1").history == longer
    store.save(AssetHistory("A1"), expected_version=0)
    assert store.asset_ids() == ["A1", "unit-1"]


def test_a_save_at_a_stale_version_is_refused_and_writes_nothing(store):
    h, _ = recorded(BASE)
    store.save(h, expected_version=0)
    longer, _ = recorded([*BASE, (1.5, 12.0, WEAR)])
    with pytest.raises(VersionConflict, match="version 1, not 0"):
        store.save(longer, expected_version=0)
    assert store.load("unit-1").history == h


def test_a_history_rewritten_not_appended_is_stored_whole(store):
    # a history whose earlier entries differ from the stored ones (not one entry appended)
    h, _ = recorded(BASE)
    store.save(h, expected_version=0)
    other, _ = recorded([(2.0, 20.0, None), (2.1, 20.5, None)])
    store.save(other, expected_version=1)
    assert store.load("unit-1").history == other


def test_update_loads_changes_and_saves_under_the_lock(store):
    def change(history):
        return history.record("r0", diagnosis(), prior_scale=PRIOR)

    version, recorded_diagnosis = store.update("unit-1", change)
    assert version == 1 and recorded_diagnosis.asset.baseline.recordings == 1
    # the same recording again: nothing written, the state stored then
    version, again = store.update("unit-1", change)
    assert version == 1 and again.asset == recorded_diagnosis.asset
    assert len(store.load("unit-1").history.entries) == 1


def test_concurrent_updates_of_one_asset_lose_nothing(store):
    # eight threads record eight recordings of one asset: under the lock each update sees
    # the one before (a lost update would leave fewer than eight entries)
    errors = []

    def record(i):
        try:
            store.update(
                "unit-1",
                lambda h: h.record(f"r{i}", diagnosis(1.0 + i / 10), prior_scale=PRIOR),
            )
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=record, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    stored = store.load("unit-1")
    assert stored.version == 8
    assert sorted(e.recording_id for e in stored.history.entries) == [f"r{i}" for i in range(8)]


def test_record_diagnosis_is_the_history_rule_through_the_store(store):
    # the step gives what AssetHistory.record gives on the stored history, and stores it
    bundle = None  # no model: no priors (bundle_priors of None gives none)
    for i, (a, b, p) in enumerate([*BASE, (1.5, 12.0, WEAR)]):
        got = record_diagnosis(store, bundle, "unit-1", f"r{i}", diagnosis(a, b, p))
    # the history's own rule with the same (absent) priors
    plain = AssetHistory("unit-1")
    for i, (a, b, p) in enumerate([*BASE, (1.5, 12.0, WEAR)]):
        plain, want = plain.record(f"r{i}", diagnosis(a, b, p))
    assert got.asset == want.asset
    assert store.load("unit-1").history == plain


def test_the_file_store_refuses_extra_rows(tmp_path):
    with pytest.raises(PRSMHealthError, match="history only"):
        FileAssetStore(tmp_path).save(AssetHistory("u"), expected_version=0, extra=([], None))


# ----------------------------------------------------------------------------- files only
def test_file_names_and_no_temporary_file_left(tmp_path):
    store = FileAssetStore(tmp_path)
    store.save(AssetHistory("pump:7"), expected_version=0)
    assert store.path("pump:7").name == "pump%3A7.json"
    assert [p.name for p in tmp_path.iterdir() if not p.name.startswith(".")] == ["pump%3A7.json"]


def test_a_file_written_before_versions_loads_as_version_1(tmp_path):
    store = FileAssetStore(tmp_path)
    h, _ = recorded(BASE)
    store.path("unit-1").write_text(json.dumps(h.to_json()))
    assert store.load("unit-1").version == 1


def test_save_is_atomic(tmp_path, monkeypatch):
    store = FileAssetStore(tmp_path)
    h, _ = recorded(BASE[:1])
    store.save(h, expected_version=0)
    before = store.path("unit-1").read_bytes()

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", fail)
    longer, _ = recorded(BASE)
    with pytest.raises(OSError):
        store.save(longer, expected_version=1)
    # the old history intact, the temporary file removed
    assert store.path("unit-1").read_bytes() == before
    assert [p.name for p in tmp_path.iterdir() if not p.name.startswith(".")] == ["unit-1.json"]


def test_a_damaged_file_is_an_error_naming_it(tmp_path):
    store = FileAssetStore(tmp_path)
    h, _ = recorded(BASE)
    store.save(h, expected_version=0)
    path = store.path("unit-1")
    text = path.read_text()
    path.write_text(text[: len(text) // 2])  # truncated
    with pytest.raises(PRSMHealthError, match="unit-1.json: not a readable asset history"):
        store.load("unit-1")
    assert path.read_text() == text[: len(text) // 2]  # left as it is
    path.write_text(json.dumps({"format": 1, "asset_id": "unit-1"}))
    with pytest.raises(PRSMHealthError, match="unit-1.json"):
        store.load("unit-1")
    path.write_text(json.dumps({**h.to_json(), "asset_id": "Unit-1"}))
    with pytest.raises(PRSMHealthError, match="holds asset 'Unit-1'"):
        store.load("unit-1")
