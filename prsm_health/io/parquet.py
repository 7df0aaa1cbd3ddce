"""One run as a single Parquet file: ``time``, the measured channels, ``check_phase`` (a health
check's phase of every sample, int16, −1 between phases) then ``truth_<name>`` for each truth
signal as columns, with the units, sample rate, labels, scenario, operating point
(``prsm_health.operating``) and the check's phases (``prsm_health.health_check``) in the schema
metadata (docs/formats.md), so pandas,
pyarrow, polars and duckdb read it as is. Datasets (many runs) are :mod:`prsm_health.datasets`.
"""

from __future__ import annotations

from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run

from .columns import run_from_table, run_table


def write_run_parquet(run: Run, path: str | Path) -> Path:
    """Write ``run`` to ``path`` atomically (temporary file, then rename)."""
    import pyarrow.parquet as pq

    path = Path(path)
    table = run_table(run)
    tmp = path.with_name(path.name + ".partial")
    pq.write_table(table, tmp, compression="zstd")
    tmp.replace(path)
    return path


def read_run_parquet(path: str | Path | bytes, *, name: str | None = None) -> Run:
    """Read a run written by :func:`write_run_parquet`, or any Parquet file with a ``time``
    column [s] and measured channel columns; ``truth_<name>`` columns go to ``Run.truth``.

    ``path`` may also be the file's bytes (a buffer); ``name`` then names it in messages."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    if isinstance(path, (bytes, bytearray, memoryview, pa.Buffer)):
        source, path = pa.BufferReader(path), Path(name or "recording")
    else:
        path = Path(path)
        source = path
    try:
        table = pq.read_table(source)
    except FileNotFoundError:
        raise PRSMHealthError(f"{path}: no such file") from None
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise PRSMHealthError(f"{path}: not a readable Parquet file ({exc})") from None
    return run_from_table(table, path)
