"""prsm_health.core.disk_cache: where the cache lives, and what it never returns."""

import math
from pathlib import Path

from prsm_health.core.disk_cache import cache_dir, cached_float


def test_cache_dir_from_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("PRSM_HEALTH_CACHE_DIR", str(tmp_path / "mine"))
    assert cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("PRSM_HEALTH_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "xdg" / "prsm-health"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert cache_dir() == Path.home() / ".cache" / "prsm-health"


def test_an_entry_is_its_key_value_only(monkeypatch, tmp_path):
    monkeypatch.setenv("PRSM_HEALTH_CACHE_DIR", str(tmp_path))
    assert cached_float("k", {"x": 1}, lambda: 0.1 + 0.2) == 0.1 + 0.2
    (first,) = (tmp_path / "k").glob("*.json")
    assert cached_float("k", {"x": 1}, lambda: 9.0) == 0.1 + 0.2  # stored
    assert cached_float("k", {"x": 2}, lambda: 9.0) == 9.0  # another key
    (second,) = set((tmp_path / "k").glob("*.json")) - {first}
    # a file that is not an entry of its key (moved, or a hash collision) is not taken
    second.write_bytes(first.read_bytes())
    assert cached_float("k", {"x": 2}, lambda: 8.0) == 8.0
    # not a number, or not finite: never taken, never stored
    first.write_text('{"key": "{\\"x\\": 1}", "value": "0.3"}')
    assert cached_float("k", {"x": 1}, lambda: 7.0) == 7.0
    assert math.isnan(cached_float("k", {"x": 3}, lambda: math.nan))
    assert len(list((tmp_path / "k").glob("*.json"))) == 2


def test_a_cache_that_cannot_be_used_costs_the_computation_only(monkeypatch, tmp_path):
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    monkeypatch.setenv("PRSM_HEALTH_CACHE_DIR", str(blocked))
    assert cached_float("k", {"x": 1}, lambda: 2.5) == 2.5
    assert cached_float("k", {"x": 1}, lambda: 3.5) == 3.5
    # no cache directory at all: a service account without a home directory
    monkeypatch.delenv("PRSM_HEALTH_CACHE_DIR")
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)

    def no_home(cls):
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.setattr(Path, "home", classmethod(no_home))
    assert cached_float("k", {"x": 1}, lambda: 4.5) == 4.5
