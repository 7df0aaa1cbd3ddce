"""What the column-table formats (CSV, Parquet, Arrow IPC) share: a run as one Arrow table
with its metadata, picking the measured channels and the truth columns, and the sample rate
from the time axis."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from prsm_health.core.channels import (
    CHANNEL_NAMES,
    CHECK_METADATA,
    CHECK_PHASE,
    TRUTH_NAMES,
    TRUTH_PREFIX,
    UNITS,
    truth_column,
)
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps


def run_table(run):
    """``run`` as a pyarrow Table (``time``, channels, ``check_phase``, ``truth_<name>``) whose
    schema carries the units and sample rate (:func:`with_units`), the labels, the scenario and
    a health check's phases (what the Parquet and Arrow writers store)."""
    import pyarrow as pa

    table = with_units(pa.Table.from_pandas(run.to_frame(), preserve_index=False), run.sample_rate)
    meta = {
        b"prsm_health.labels": dumps(run.labels).encode(),
        b"prsm_health.scenario": dumps(run.scenario).encode(),
    }
    if run.check:
        meta[CHECK_KEY] = dumps(run.check).encode()
    return table.replace_schema_metadata({**table.schema.metadata, **meta})


def units_schema(schema, sample_rate: float):
    """``schema`` with the unit of every contract column (``time``, channels, ``truth_*``;
    other columns such as ``run_id`` have none) and the sample rate [Hz] where each reader
    looks for them — one place for every file of signals the package writes:

    - ``prsm_health.units`` (JSON: column → unit) and ``prsm_health.sample_rate`` in the schema
      metadata (the contract, docs/formats.md; polars ``read_parquet_metadata``, duckdb
      ``parquet_kv_metadata``);
    - the field metadata ``unit`` of each column (pyarrow ``schema.field(name).metadata``);
    - pandas ``DataFrame.attrs``: ``{"units": {column: unit}, "sample_rate": Hz}`` after
      ``pandas.read_parquet`` (pandas ≥ 2.1 restores ``attrs`` from the "pandas" metadata).
    """
    import pyarrow as pa

    units = {name: UNITS[name] for name in schema.names if name in UNITS}
    fields = [
        f.with_metadata({**(f.metadata or {}), b"unit": units[f.name].encode()})
        if f.name in units
        else f
        for f in schema
    ]
    meta = dict(schema.metadata or {})
    if b"pandas" in meta:
        pandas_meta = json.loads(meta[b"pandas"])
    else:  # a table built from arrays: the pandas metadata of its (empty) frame
        empty = schema.empty_table().to_pandas()
        pandas_meta = json.loads(
            pa.Schema.from_pandas(empty, preserve_index=False).metadata[b"pandas"]
        )
    pandas_meta["attributes"] = {
        **pandas_meta.get("attributes", {}),
        "units": units,
        "sample_rate": float(sample_rate),
    }
    meta.update(
        {
            b"pandas": json.dumps(pandas_meta).encode(),
            b"prsm_health.units": json.dumps(units).encode(),
            b"prsm_health.sample_rate": repr(float(sample_rate)).encode(),
        }
    )
    return pa.schema(fields, metadata=meta)


def with_units(table, sample_rate: float):
    """``table`` with :func:`units_schema` (the data are not copied)."""
    import pyarrow as pa

    return pa.Table.from_arrays(table.columns, schema=units_schema(table.schema, sample_rate))


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


#: Schema-metadata key of a health check's name and phase boundaries (JSON).
CHECK_KEY = f"prsm_health.{CHECK_METADATA}".encode()


def check_columns(table) -> dict:
    """``check_phase`` (int16) and ``check`` (name, boundaries) of a run table, as ``Run``
    keywords: none when the table is no check recording (docs/formats.md)."""
    if CHECK_PHASE not in table.column_names:
        return {}
    meta = table.schema.metadata or {}
    try:
        check = json.loads(meta.get(CHECK_KEY, b"{}"))
    except ValueError as exc:
        raise PRSMHealthError(f"unreadable {CHECK_KEY.decode()} metadata ({exc})") from None
    phase = table.column(CHECK_PHASE).to_numpy().astype(np.int16)
    return {"check_phase": phase, "check": check if isinstance(check, dict) else {}}
