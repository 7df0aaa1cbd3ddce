"""Files written whole or not at all: a reader (another process, a crash) sees the old file or
the whole new one, never half of it."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import PRSMHealthError


def write_atomic(path: Path, data: bytes, what: str = "file") -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename: a reader sees the old
    file or the whole new one, never half of it."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as err:
        raise PRSMHealthError(f"{path}: cannot write {what} ({err.strerror})") from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
