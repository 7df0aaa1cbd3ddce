"""Recordings in and out, one module per format (like pvlib's iotools).

- :mod:`prsm_health.io.parquet` — one run as a single Parquet file (``simulate --out x.parquet``);
- :mod:`prsm_health.io.csv` — a CSV table with contract channel names (a rig's export);
- :mod:`prsm_health.mcap` — MCAP recordings (writer, tolerant reader, replay);
- :mod:`prsm_health.dataset` — generated datasets (a directory of Parquet files).

:func:`read_recording` picks the reader from the file suffix.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import PRSMHealthError

SUFFIXES = (".mcap", ".parquet", ".csv")


def read_recording(path: str | Path):
    """A recording as a :class:`~prsm_health.run.Run`: ``.mcap``, ``.parquet`` or ``.csv``."""
    path = Path(path)
    if not path.exists():
        raise PRSMHealthError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".mcap":
        from ..mcap import read_mcap

        return read_mcap(path)
    if suffix == ".parquet":
        from .parquet import read_run_parquet

        return read_run_parquet(path)
    if suffix == ".csv":
        from .csv import read_csv

        return read_csv(path)
    raise PRSMHealthError(f"{path}: unsupported file type {suffix!r} (use {', '.join(SUFFIXES)})")
