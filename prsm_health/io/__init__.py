"""Recordings in and out, one module per format (like pvlib's iotools).

- :mod:`prsm_health.io.parquet` — one run as a single Parquet file (``simulate --out x.parquet``);
- :mod:`prsm_health.io.arrow` — one run as an Arrow IPC stream (the Parquet file's columns);
- :mod:`prsm_health.io.csv` — a CSV table with contract channel names (a rig's export);
- :mod:`prsm_health.io.mcap` — MCAP recordings (writer, tolerant reader, replay);
- :mod:`prsm_health.datasets.dataset` — generated datasets (a directory of Parquet files).

:func:`read_recording` picks the reader from the file suffix; :func:`read_recording_bytes`
reads a recording held in memory (a request body).
"""

from __future__ import annotations

from pathlib import Path

from prsm_health.core.errors import PRSMHealthError

SUFFIXES = (".mcap", ".parquet", ".csv")
#: Formats :func:`read_recording_bytes` reads.
BYTE_FORMATS = ("arrow", "parquet", "mcap")


def read_recording(path: str | Path):
    """A recording as a :class:`~prsm_health.core.run.Run`: ``.mcap``, ``.parquet`` or ``.csv``."""
    path = Path(path)
    if not path.exists():
        raise PRSMHealthError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".mcap":
        from .mcap import read_mcap

        return read_mcap(path)
    if suffix == ".parquet":
        from .parquet import read_run_parquet

        return read_run_parquet(path)
    if suffix == ".csv":
        from .csv import read_csv

        return read_csv(path)
    raise PRSMHealthError(f"{path}: unsupported file type {suffix!r} (use {', '.join(SUFFIXES)})")


def read_recording_bytes(data: bytes, fmt: str, name: str = "recording"):
    """A recording held in memory as a :class:`~prsm_health.core.run.Run`: ``fmt`` is ``"arrow"``
    (Arrow IPC stream), ``"parquet"`` or ``"mcap"``; ``name`` names it in messages and
    warnings.

    Decodes everything: check what the bytes declare first when they come from someone else
    (:func:`prsm_health.io.arrow.arrow_stream_sizes`, the Parquet footer, the MCAP chunk
    headers). An MCAP recording is read through a private temporary file (the MCAP reader
    scans files); its path never appears in a message.
    """
    if fmt == "arrow":
        from .arrow import read_run_arrow

        return read_run_arrow(data, name)
    if fmt == "parquet":
        from .parquet import read_run_parquet

        return read_run_parquet(data, name=name)
    if fmt == "mcap":
        return _read_mcap_bytes(data, name)
    raise PRSMHealthError(f"{name}: unsupported format {fmt!r} (use {', '.join(BYTE_FORMATS)})")


def _read_mcap_bytes(data: bytes, name: str):
    import tempfile
    import warnings

    from prsm_health.core.errors import TruncatedRecordingWarning

    from .mcap import read_mcap

    with tempfile.TemporaryDirectory(prefix="prsm-health-mcap-") as tmp:
        path = Path(tmp) / "recording.mcap"
        path.write_bytes(data)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", TruncatedRecordingWarning)
            try:
                run = read_mcap(path)
            except PRSMHealthError as exc:
                raise PRSMHealthError(str(exc).replace(str(path), name)) from None
    for w in caught:
        text = str(w.message).replace(str(path), name)
        if issubclass(w.category, TruncatedRecordingWarning):
            warnings.warn(text, TruncatedRecordingWarning, stacklevel=2)
        else:
            warnings.warn_explicit(text, w.category, w.filename, w.lineno)
    return run
