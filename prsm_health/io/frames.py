"""Table files (CSV, Parquet) as pandas DataFrames, and their columns as checked float arrays:
what the CSV reader and the column maps share."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from prsm_health.core.errors import PRSMHealthError


def read_frame(source: Path | bytes, fmt: str, where: str):
    """A CSV or Parquet table (a file, or its bytes) as a DataFrame; ``where`` names it."""
    import pandas as pd

    data = io.BytesIO(source) if isinstance(source, (bytes, bytearray, memoryview)) else source
    try:
        return pd.read_csv(data) if fmt == "csv" else pd.read_parquet(data)
    except FileNotFoundError:
        raise PRSMHealthError(f"{where}: no such file") from None
    except Exception as exc:  # pandas and pyarrow raise many types for bad or truncated files
        kind = "CSV" if fmt == "csv" else "Parquet"
        raise PRSMHealthError(
            f"{where}: not a readable {kind} file ({type(exc).__name__}: {exc})"
        ) from None


def frame_column(frame, column: str, where: str) -> np.ndarray:
    """Column ``column`` of ``frame`` as finite floats.

    Raises
    ------
    PRSMHealthError
        A cell that is empty, not a number or not finite, naming ``where`` (the file), the
        column and the 1-based data row (the row under the header: line row + 1 of a CSV
        file with one header line).
    """
    import pandas as pd

    series = frame[column]
    try:
        values = series.to_numpy(dtype=float)
    except (TypeError, ValueError):
        values = pd.to_numeric(series, errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    if len(bad):
        row = int(bad[0])
        cell = series.iloc[row]
        what = "is empty or NaN" if _empty(cell) else f"{str(cell)[:40]!r} is not a finite number"
        more = f" ({len(bad)} such cells in the column)" if len(bad) > 1 else ""
        raise PRSMHealthError(f"{where}: column {column!r}, data row {row + 1}: {what}{more}")
    return values


def _empty(cell) -> bool:
    if cell is None:
        return True
    if isinstance(cell, str):
        return not cell.strip()
    try:
        return bool(np.isnan(cell))
    except TypeError:
        return False
