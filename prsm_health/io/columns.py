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
from prsm_health.core.check_phases import CheckPhases
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps
from prsm_health.core.operating_point import OPERATING_METADATA, OperatingPoint
from prsm_health.core.run import Run

#: Schema-metadata key of a health check's name and phases (JSON, CheckPhases.as_record).
CHECK_KEY = f"prsm_health.{CHECK_METADATA}".encode()
#: Schema-metadata key of the operating point (JSON, OperatingPoint.as_dict).
OPERATING_KEY = f"prsm_health.{OPERATING_METADATA}".encode()
LABELS_KEY = b"prsm_health.labels"
SCENARIO_KEY = b"prsm_health.scenario"


def run_table(run: Run):
    """``run`` as a pyarrow Table (:func:`run_columns`: ``time``, channels, ``check_phase``,
    ``truth_<name>``) whose schema carries the units and sample rate (:func:`with_units`), the
    labels, the scenario, the operating point and a health check's phases (:func:`run_metadata`):
    what the Parquet and Arrow writers store. A dataset's shard holds the same columns and units
    for each of its runs, the labels of all in its footer (:mod:`prsm_health.datasets`)."""
    import pyarrow as pa

    table = with_units(pa.table(run_columns(run)), run.sample_rate)
    return table.replace_schema_metadata({**table.schema.metadata, **run_metadata(run)})


def run_columns(run: Run, dtype=None) -> dict[str, np.ndarray]:
    """The run's file columns (:meth:`Run.columns <prsm_health.core.run.Run.columns>`), the
    channel and truth columns stored as ``dtype`` (default: as the run holds them); ``time``
    stays float64 (float32 would round the sample times), ``check_phase`` int16. A dataset's
    shard stores each of its runs so, its schema made by :func:`units_schema`."""
    return {
        name: values if dtype is None or name in ("time", CHECK_PHASE) else values.astype(dtype)
        for name, values in run.columns().items()
    }


def run_metadata(run: Run) -> dict[bytes, bytes]:
    """The schema metadata of a run beside its units: labels, scenario, operating point and,
    for a health check, its phases (:func:`read_run_metadata` reads them back)."""
    meta = {
        LABELS_KEY: dumps(run.labels).encode(),
        SCENARIO_KEY: dumps(run.scenario).encode(),
        OPERATING_KEY: dumps(run.operating.as_dict()).encode(),
    }
    if run.check is not None:
        meta[CHECK_KEY] = dumps(run.check.as_record()).encode()
    return meta


def read_run_metadata(meta: dict, name: str | Path) -> dict:
    """``labels``, ``scenario``, ``operating`` and ``check`` of a run's schema metadata
    (:func:`run_metadata`), as :class:`~prsm_health.core.run.Run` keywords. A file written
    before the operating record has its operating point read from its labels, which carried
    the same keys; a file without the check record has no check.

    Raises
    ------
    PRSMHealthError
        Metadata that is not JSON, or not of the shape written, naming ``name``.
    """
    try:
        labels = json.loads(meta.get(LABELS_KEY, b"{}"))
        scenario = json.loads(meta.get(SCENARIO_KEY, b"{}"))
        operating = json.loads(meta[OPERATING_KEY]) if OPERATING_KEY in meta else labels
        check = CheckPhases.from_record(json.loads(meta.get(CHECK_KEY, b"{}")))
    except (ValueError, TypeError, KeyError) as exc:
        raise PRSMHealthError(f"{name}: unreadable prsm_health schema metadata ({exc})") from None
    if not all(isinstance(x, dict) for x in (labels, scenario, operating)):
        raise PRSMHealthError(
            f"{name}: prsm_health.labels, .scenario and .operating must be JSON objects"
        )
    return {
        "labels": labels,
        "scenario": scenario,
        "operating": OperatingPoint.from_labels(operating),
        "check": check,
    }


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


def check_column(table) -> np.ndarray | None:
    """The ``check_phase`` column (int16) of a run table; None when the table has none."""
    if CHECK_PHASE not in table.column_names:
        return None
    return table.column(CHECK_PHASE).to_numpy().astype(np.int16)


def run_from_table(table, name: str | Path) -> Run:
    """A run from a table of :func:`run_table`'s layout, or any table with a ``time`` column
    [s] and measured channel columns (the Parquet and Arrow readers): ``truth_<name>``
    columns go to ``Run.truth``; the sample rate is the ``prsm_health.sample_rate`` schema
    metadata, else 1/(median time step); labels, scenario, operating point and check from the
    metadata (:func:`read_run_metadata`; the check only with its ``check_phase`` column).
    ``name`` names the file in messages."""
    import pyarrow as pa

    meta = table.schema.metadata or {}
    if "time" not in table.column_names:
        raise PRSMHealthError(f"{name}: no 'time' column")
    numeric = {"time", *[c for c in table.column_names if c in UNITS]}
    for column in numeric:
        kind = table.schema.field(column).type
        if not (pa.types.is_floating(kind) or pa.types.is_integer(kind)):
            raise PRSMHealthError(f"{name}: column {column!r} has type {kind}; numbers expected")

    def values(column):
        return table.column(column).to_numpy()

    channels = contract_channels(name, table.column_names, values)
    truth = truth_columns(table.column_names, values)
    time = values("time").astype(float)
    try:
        rate = (
            float(meta[b"prsm_health.sample_rate"])
            if b"prsm_health.sample_rate" in meta
            else rate_from_time(name, time)
        )
    except ValueError as exc:
        raise PRSMHealthError(f"{name}: unreadable prsm_health schema metadata ({exc})") from None
    keywords = read_run_metadata(meta, name)
    phase = check_column(table)
    if phase is None:
        keywords["check"] = None
    return Run(time, channels, rate, truth=truth, check_phase=phase, **keywords)
