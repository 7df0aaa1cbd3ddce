"""CSV recordings: a header row of contract channel names, ``time`` in seconds (docs/formats.md).

Every column named like a measured contract channel (:mod:`prsm_health.core.channels`) is read as
that channel in its SI unit, a ``truth_<name>`` column of a truth signal into
:attr:`Run.truth <prsm_health.core.run.Run.truth>` (never a channel); other columns are ignored.
Sampling must be uniform; the sample rate is 1/median(Δt). A time column in milliseconds is the
usual mistake: name it ``time_ms`` and it is converted, and a time axis that implies a sample
rate below 100 Hz gets a hint. A cell that is empty or not a number is an error naming the file,
the column and the row. Files with other column names or units are read through a column map
(:mod:`prsm_health.io.column_map`, ``read_recording(path, column_map=…)``).
"""

from __future__ import annotations

import warnings
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run, ms_hint

from .columns import contract_channels, rate_from_time, truth_columns
from .frames import frame_column, read_frame


def read_csv(path: str | Path | bytes, *, name: str | None = None) -> Run:
    """Read a CSV recording as a :class:`~prsm_health.core.run.Run` (SI units).

    ``path`` may also be the file's bytes; ``name`` then names it in messages."""
    if isinstance(path, (bytes, bytearray, memoryview)):
        source, where = path, name or "recording"
    else:
        source = Path(path)
        where = name or str(source)
    frame = read_frame(source, "csv", where)
    if "time" in frame.columns:
        time = frame_column(frame, "time", where)
    elif "time_ms" in frame.columns:
        time = frame_column(frame, "time_ms", where) / 1000.0
    else:
        raise PRSMHealthError(f"{where}: no 'time' column [s] (or 'time_ms' [ms])")

    def column(c):
        return frame_column(frame, c, where)

    channels = contract_channels(where, frame.columns, column)
    truth = truth_columns(frame.columns, column)
    rate = rate_from_time(where, time)
    hint = ms_hint(rate)
    if hint:
        warnings.warn(f"{where}: {hint.lstrip(' —')}", UserWarning, stacklevel=2)
    return Run(time, channels, rate, truth=truth)
