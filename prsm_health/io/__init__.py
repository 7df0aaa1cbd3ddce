"""Recordings in and out, one module per format (like pvlib's iotools).

- :mod:`prsm_health.io.parquet` — one run as a single Parquet file (``simulate --out x.parquet``);
- :mod:`prsm_health.io.arrow` — one run as an Arrow IPC stream (the Parquet file's columns);
- :mod:`prsm_health.io.csv` — a CSV table with contract channel names (a rig's export);
- :mod:`prsm_health.io.mcap` — MCAP recordings (writer, tolerant reader, replay);
- :mod:`prsm_health.io.column_map` — column maps (MAP.toml): a rig's column names and units;
- :mod:`prsm_health.io.derived` — channels derived from others (screw speed from the angle);
- :mod:`prsm_health.datasets.dataset` — generated datasets (a directory of Parquet files).

One reader (:mod:`prsm_health.io.reader`) serves every path: :func:`read_recording` picks the
format from the file suffix, :func:`read_recording_bytes` reads a recording held in memory (a
request body), both through a column map when given one and with the derivable channels
added; :func:`read_with_warnings` returns the reader's warnings as sentences too.
"""

from __future__ import annotations

from pathlib import Path

from .column_map import ColumnMap, load_column_map
from .reader import BYTE_FORMATS, Recording, read_with_warnings

SUFFIXES = (".mcap", ".parquet", ".csv")

__all__ = [
    "BYTE_FORMATS",
    "SUFFIXES",
    "ColumnMap",
    "Recording",
    "load_column_map",
    "read_recording",
    "read_recording_bytes",
    "read_with_warnings",
]


def read_recording(path: str | Path, *, column_map: ColumnMap | str | Path | None = None):
    """A recording as a :class:`~prsm_health.core.run.Run`: ``.mcap``, ``.parquet`` or ``.csv``.

    Parameters
    ----------
    path : str or Path
    column_map : ColumnMap, path of a MAP.toml, or None
        How a CSV or Parquet file names and scales its columns (docs/import.md). None: the
        contract's column names, SI units.

    The reader's warnings (a truncated recording, …) are raised as Python warnings; see
    :func:`read_with_warnings` to have them as sentences. Derivable channels the recording
    lacks are added (``screw_speed`` from ``screw_angle``).
    """
    recording = read_with_warnings(path, column_map=column_map)
    recording.warn(stacklevel=2)
    return recording.run


def read_recording_bytes(
    data: bytes,
    fmt: str,
    name: str = "recording",
    *,
    column_map: ColumnMap | str | Path | None = None,
):
    """A recording held in memory as a :class:`~prsm_health.core.run.Run`: ``fmt`` is ``"arrow"``
    (Arrow IPC stream), ``"parquet"``, ``"mcap"`` or ``"csv"``; ``name`` names it in messages
    and warnings; ``column_map`` as for :func:`read_recording`.

    Decodes everything: check what the bytes declare first when they come from someone else
    (:func:`prsm_health.io.arrow.arrow_stream_sizes`, the Parquet footer, the MCAP chunk
    headers). An MCAP recording is read through a private temporary file (the MCAP reader
    scans files); its path never appears in a message.
    """
    recording = read_with_warnings(data, fmt=fmt, name=name, column_map=column_map)
    recording.warn(stacklevel=2)
    return recording.run
