"""Numbers slow to compute and the same in every process, kept on disk between processes (as
numba keeps its compiled kernels): one small JSON file per key under :func:`cache_dir`.

An entry is found by the hash of its key and holds the key itself, so a file of another key, a
half-written or a corrupt file is never taken for the value: it is computed again and the file
rewritten (atomically: a reader sees the old file or the whole new one). A cache that cannot be
read or written costs the computation only, never an error.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable
from pathlib import Path

from .atomic import write_atomic
from .errors import PRSMHealthError

#: Environment variable overriding the cache directory.
CACHE_ENV = "PRSM_HEALTH_CACHE_DIR"


def cache_dir() -> Path:
    """``$PRSM_HEALTH_CACHE_DIR``, else ``$XDG_CACHE_HOME/prsm-health`` (``~/.cache/prsm-health``)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "prsm-health"


def cached_float(kind: str, key: dict, compute: Callable[[], float]) -> float:
    """``compute()``, read from the cache when an entry of ``key`` exists, stored otherwise.

    ``kind`` names the cache's folder; ``key`` must hold everything the value depends on (its
    inputs and a fingerprint of the code that computes it), as JSON (other values by ``repr``).
    """
    text = json.dumps(key, sort_keys=True, default=repr)
    path = None
    try:
        path = cache_dir() / kind / f"{hashlib.sha256(text.encode()).hexdigest()}.json"
        entry = json.loads(path.read_bytes())
        if entry["key"] == text and isinstance(entry["value"], float):
            return entry["value"]
    except (OSError, RuntimeError, ValueError, KeyError, TypeError):
        pass  # no entry, one unreadable, or no home directory: computed (again) below
    value = float(compute())
    if path is not None and math.isfinite(value):
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(path, json.dumps({"key": text, "value": value}).encode(), "cache entry")
        except (OSError, PRSMHealthError):
            pass  # a read-only or full disk: computed in each process, as without a cache
    return value
