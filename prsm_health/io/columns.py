"""What the column-table formats (CSV, Parquet, Arrow IPC) share: a run as one Arrow table
with its metadata, picking the measured channels and the truth columns, and the sample rate
from the time axis."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from prsm_health.core.channels import CHANNEL_NAMES, TRUTH_NAMES, TRUTH_PREFIX, UNITS, truth_column
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps


def run_table(run):
    """``run`` as a pyarrow Table (``time``, channels, ``truth_<name>``) whose schema metadata
    carries the units, sample rate, labels and scenario (what the Parquet and Arrow writers
    store)."""
    import pyarrow as pa

    table = pa.Table.from_pandas(run.to_frame(), preserve_index=False)
    meta = {
        b"prsm_health.units": json.dumps({k: UNITS[k] for k in table.column_names}).encode(),
        b"prsm_health.sample_rate": repr(float(run.sample_rate)).encode(),
        b"prsm_health.labels": dumps(run.labels).encode(),
        b"prsm_health.scenario": dumps(run.scenario).encode(),
    }
    return table.replace_schema_metadata({**(table.schema.metadata or {}), **meta})


def contract_channels(path: Path, columns: Iterable[str], column: Callable) -> dict:
    """Every column named like a measured contract channel, as float arrays (SI); none is an
    error (``truth_*`` columns are simulator truth, never channels)."""
    columns = list(columns)
    channels = {c: np.asarray(column(c), dtype=float) for c in CHANNEL_NAMES if c in columns}
    if not channels:
        truth = any(str(c).startswith(TRUTH_PREFIX) for c in columns)
        raise PRSMHealthError(
            f"{path}: no usable channels (expected contract names such as nut_axial_accel; "
            f"found {', '.join(map(str, columns[:8]))})"
            + ("; truth_* columns are simulator truth, not measurements" if truth else "")
        )
    return channels


def truth_columns(columns: Iterable[str], column: Callable) -> dict:
    """The ``truth_<name>`` columns of the contract's truth signals, keyed by ``name``."""
    columns = set(columns)
    return {
        name: np.asarray(column(truth_column(name)), dtype=float)
        for name in TRUTH_NAMES
        if truth_column(name) in columns
    }


def rate_from_time(path: Path, time: np.ndarray) -> float:
    """Sample rate [Hz] of a uniformly sampled, strictly increasing time axis [s]."""
    if len(time) < 2 or not np.all(np.diff(time) > 0):
        raise PRSMHealthError(f"{path}: 'time' must increase strictly (and hold 2 samples or more)")
    return 1.0 / float(np.median(np.diff(time)))
