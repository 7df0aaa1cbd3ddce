"""CSV recordings: a header row of contract channel names, ``time`` in seconds (docs/formats.md).

Every column named like a measured contract channel (:mod:`prsm_health.core.channels`) is read as
that channel in its SI unit, a ``truth_<name>`` column of a truth signal into
:attr:`Run.truth <prsm_health.core.run.Run.truth>` (never a channel); other columns are ignored. Sampling must be uniform; the sample rate is
1/median(Δt). A time column in milliseconds is the usual mistake: name it ``time_ms`` and it is
converted, and a time axis that implies a sample rate below 100 Hz gets a hint.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run, ms_hint

from .columns import contract_channels, rate_from_time, truth_columns


def read_csv(path: str | Path) -> Run:
    """Read a CSV recording as a :class:`~prsm_health.core.run.Run` (SI units)."""
    import pandas as pd

    path = Path(path)
    try:
        frame = pd.read_csv(path)
    except FileNotFoundError:
        raise PRSMHealthError(f"{path}: no such file") from None
    except Exception as exc:  # pandas raises many types for bad CSVs
        raise PRSMHealthError(f"{path}: not a readable CSV ({exc})") from None
    if "time" in frame.columns:
        time = frame["time"].to_numpy(float)
    elif "time_ms" in frame.columns:
        time = frame["time_ms"].to_numpy(float) / 1000.0
    else:
        raise PRSMHealthError(f"{path}: no 'time' column [s] (or 'time_ms' [ms])")
    channels = contract_channels(path, frame.columns, lambda c: frame[c].to_numpy())
    truth = truth_columns(frame.columns, lambda c: frame[c].to_numpy())
    rate = rate_from_time(path, time)
    hint = ms_hint(rate)
    if hint:
        warnings.warn(f"{path}: {hint.lstrip(' —')}", UserWarning, stacklevel=2)
    return Run(time, channels, rate, truth=truth)
