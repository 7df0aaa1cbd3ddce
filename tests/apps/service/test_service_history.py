"""History store of the HTTP service (``prsm_health.apps.service.HistoryStore``), without a server."""

import pytest

from prsm_health import PRSMHealthError
from prsm_health.apps.service import HistoryStore, default_db_path, parse_time


def test_history_store(tmp_path):
    path = tmp_path / "h.sqlite"
    store = HistoryStore(path)
    d = {
        "clearance": {"estimate": 1e-5, "lower": 0.5e-5, "upper": 2e-5},
        "fault_class": "wear",
        "class_probabilities": {"wear": 1.0},
        "indicators": {},
        "model": {"name": "m", "version": "1"},
    }
    store.add("a", [d], received_at="2024-01-01T00:00:00.000000+00:00")
    store.add("a", [d, d], received_at="2024-01-02T00:00:00.000000+00:00", source="file")
    store.add("b", [d])
    h = store.history("a")
    assert h["count"] == 3 and [e["received_at"][:10] for e in h["diagnoses"]] == [
        "2024-01-01",
        "2024-01-02",
        "2024-01-02",
    ]
    assert store.history("a", since="2024-01-01T12:00:00")["count"] == 2
    assert store.history("a", since="2024-01-02T01:00:00+02:00")["count"] == 2  # 23:00 UTC
    assert store.history("a", limit=1)["diagnoses"][0]["id"] == h["diagnoses"][-1]["id"]
    with pytest.raises(PRSMHealthError, match="ISO-8601"):
        store.history("a", since="not a time")
    mode = store._conn.execute("PRAGMA journal_mode").fetchone()[0]
    assert mode == "wal"
    store.close()
    assert HistoryStore(path).history("a")["count"] == 3  # reopened: still there

    (tmp_path / "junk.sqlite").write_bytes(b"this is not a database" * 100)
    with pytest.raises(PRSMHealthError, match="not a usable history database"):
        HistoryStore(tmp_path / "junk.sqlite")
    with pytest.raises(PRSMHealthError, match="does not exist"):
        HistoryStore(tmp_path / "missing" / "h.sqlite")


def test_parse_time_and_default_db_path(monkeypatch, tmp_path):
    assert parse_time("2024-05-01T12:00:00Z") == "2024-05-01T12:00:00.000000+00:00"
    assert parse_time("2024-05-01T14:00:00+02:00") == "2024-05-01T12:00:00.000000+00:00"
    assert parse_time("2024-05-01") == "2024-05-01T00:00:00.000000+00:00"  # no zone: UTC
    with pytest.raises(PRSMHealthError, match="until = 'soon' is not an ISO-8601 time"):
        parse_time("soon", "until")
    monkeypatch.setenv("PRSM_HEALTH_DB", str(tmp_path / "x.sqlite"))
    assert default_db_path() == tmp_path / "x.sqlite"
    monkeypatch.delenv("PRSM_HEALTH_DB")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    assert default_db_path() == tmp_path / "prsm-health" / "history.sqlite"
