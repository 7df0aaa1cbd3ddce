"""Your own rig's recordings as a dataset: CSV, Parquet or MCAP files plus a labels table.

``prsm-health import RECORDINGS… --labels LABELS.csv --map MAP.toml --out DIR`` (docs/import.md)
writes the dataset layout of :mod:`prsm_health.datasets` — one Parquet shard per recording, the
labels table ``runs.parquet``, ``manifest.json`` — so ``train`` and ``evaluate`` work on it as on
a generated dataset.

* **MAP.toml** — ``[columns]`` maps contract channel names (:mod:`prsm_health.core.channels`, plus
  ``time`` and the alias ``motor_current``) to the files' column names; ``[units]`` gives each
  mapped file column's unit (:data:`prsm_health.io.column_map.UNITS`), converted to SI;
  ``sample_rate`` [Hz] instead of a time column; optional ``design`` (a preset, a design TOML
  file relative to the map, or an inline ``[design]`` table; absent for a rig that is not a
  PRSM: design-dependent indicators are then NaN),
  ``lead`` [m per revolution of ``screw_angle``] for such a rig (lost motion needs it),
  ``torque_constant`` [N·m/A] to turn a ``motor_current`` into ``drive_torque``.
* **LABELS.csv** — a ``recording`` column (the file's name) and label columns: ``fault_class``,
  ``clearance`` [m] (both sides), any other; ``split`` (train/test) optional, else a
  deterministic stratified split.
* MCAP recordings in this project's layout carry contract channels in SI already; the map's
  columns and units apply to table files (CSV, Parquet).

The map is :class:`prsm_health.io.ColumnMap` and every file is read by
:func:`prsm_health.io.read_with_warnings` — the reader ``prsm-health diagnose`` and the service
use — so a recording and its map read the same on import and at diagnosis (derived channels
included). What is import's own: time from 0, labels from the labels table, one sample rate.
The design travels as a generated dataset's does: the manifest's ``recipe.design`` (a preset
name or the full dict form), its ``design`` entry (name and fingerprint) and every run's
``design`` and ``design_fingerprint`` labels, so :attr:`Dataset.design` and the indicators find
it.

Everything is checked before anything is written, and the dataset is assembled in a temporary
sibling directory renamed at the end: a failed import leaves nothing behind.
"""

from __future__ import annotations

import math
import os
import shutil
import warnings
from pathlib import Path

import numpy as np

from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.channels import UNITS as CHANNEL_UNITS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps
from prsm_health.core.run import MIN_SAMPLES, Run
from prsm_health.io import ColumnMap, load_column_map, read_with_warnings
from prsm_health.io.column_map import MIN_RATE as COLUMN_MAP_MIN_RATE
from prsm_health.io.columns import run_columns, units_schema
from prsm_health.signals.indicator_table import usable_groups

#: Lowest sample rate an import accepts [Hz] (a map's ``sample_rate`` is held to it too).
MIN_RATE = COLUMN_MAP_MIN_RATE


def _read(path: Path, spec: ColumnMap) -> tuple[Run, tuple[str, ...]]:
    """One recording as the dataset stores it (time from 0, channels only) and the channels
    the reader derived; through :func:`prsm_health.io.read_with_warnings`, the reader
    ``diagnose`` and the service use, so a file reads the same everywhere."""
    recording = read_with_warnings(path, column_map=spec)
    recording.warn(stacklevel=3)
    run = recording.run
    # An MCAP recording keeps its own clock, labels and truth; the dataset stores its signals
    # from 0 and the labels table's labels (a mapped table starts at 0 already).
    run = Run(run.time - run.time[0], dict(run.channels), run.sample_rate)
    if run.sample_rate < MIN_RATE:
        raise PRSMHealthError(
            f"{path}: sample rate {run.sample_rate:.3g} Hz is below {MIN_RATE:g} Hz"
        )
    if len(run) < MIN_SAMPLES:
        raise PRSMHealthError(
            f"{path}: {len(run)} samples; the indicators need at least {MIN_SAMPLES} "
            f"({MIN_SAMPLES / run.sample_rate:.3g} s at {run.sample_rate:g} Hz)"
        )
    return run.validate(what=str(path)), recording.derived


def _labels(path: Path, names: list[str]):
    import pandas as pd

    try:
        table = pd.read_csv(path)
    except FileNotFoundError:
        raise PRSMHealthError(f"{path}: no such labels file") from None
    except Exception as exc:
        raise PRSMHealthError(f"{path}: unreadable labels table ({exc})") from None
    if "recording" not in table.columns:
        raise PRSMHealthError(f"{path}: no 'recording' column (the recordings' file names)")
    table["recording"] = table["recording"].astype(str)
    duplicated = sorted(set(table["recording"][table["recording"].duplicated()]))
    if duplicated:
        raise PRSMHealthError(f"{path}: recording(s) labelled twice: {', '.join(duplicated)}")
    extra = ~table["recording"].isin(names)
    if extra.any():  # a labels table of the whole campaign, some recordings imported: fine
        rows = [
            f"data row {i + 1} ({name})"
            for i, name in zip(np.flatnonzero(extra), table["recording"][extra])
        ]
        warnings.warn(
            f"{path}: {len(rows)} label row(s) for recordings not given, ignored: "
            f"{', '.join(rows)}",
            stacklevel=3,
        )
        table = table[~extra].reset_index(drop=True)
    unlabelled = sorted(set(names) - set(table["recording"]))
    if unlabelled:
        raise PRSMHealthError(f"{path}: no labels for recording(s) {', '.join(unlabelled)}")
    if "split" in table.columns and not set(table["split"]) <= {"train", "test"}:
        raise PRSMHealthError(f"{path}: split must be 'train' or 'test'")
    if "clearance" in table.columns:
        clearance = pd.to_numeric(table["clearance"], errors="coerce")
        if clearance.isna().any() or (clearance < 0).any() or (clearance > 1e-3).any():
            raise PRSMHealthError(f"{path}: clearance must be a number in [0, 1e-3] m (SI metres)")
    return table.set_index("recording")


def _split(labels, test_fraction: float, seed: int) -> list[str]:
    """A deterministic test split, stratified by fault_class when there is one."""
    rng = np.random.default_rng(seed)
    split = ["train"] * len(labels)
    groups = labels["fault_class"].astype(str) if "fault_class" in labels else ["all"] * len(labels)
    positions: dict[str, list[int]] = {}
    for i, g in enumerate(groups):
        positions.setdefault(g, []).append(i)
    for members in positions.values():
        k = int(round(test_fraction * len(members)))
        if test_fraction > 0 and len(members) >= 2:
            k = max(k, 1)  # every class with two recordings or more is tested
        for i in rng.permutation(members)[:k]:
            split[int(i)] = "test"
    return split


def import_recordings(
    recordings: list[str | Path],
    labels: str | Path,
    map_path: str | Path,
    out: str | Path,
    *,
    test_fraction: float = 0.25,
    seed: int = 0,
    overwrite: bool = False,
    name: str | None = None,
) -> dict:
    """Import recordings into a dataset directory; returns a summary.

    Raises
    ------
    PRSMHealthError
        Anything wrong with the map, the labels or a recording (one sentence naming the file
        and what is wrong), or an existing non-empty ``out`` without ``overwrite`` — before
        anything is written.
    """
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    from prsm_health.actuator.faults import FAULT_CLASSES
    from prsm_health.core.version import __version__

    from .store import dataset_counts

    out = Path(out)
    if not (0 <= test_fraction < 1):
        raise PRSMHealthError(f"test_fraction = {test_fraction!r} must lie in [0, 1)")
    if out.exists() and any(out.iterdir()) and not overwrite:
        raise PRSMHealthError(f"{out}: exists and is not empty (use --overwrite to replace it)")
    if not out.parent.exists():
        raise PRSMHealthError(f"{out}: directory {out.parent} does not exist")
    if not recordings:
        raise PRSMHealthError("no recordings given")
    spec = load_column_map(map_path)
    paths = [Path(p) for p in recordings]
    names = [p.name for p in paths]
    if len(set(names)) < len(names):
        raise PRSMHealthError(
            "two recordings share a file name; the labels table cannot tell them apart"
        )
    table = _labels(Path(labels), names)
    read = [_read(p, spec) for p in paths]
    runs = [run for run, _ in read]
    derived = sorted({name for _, names in read for name in names})
    rates = {p.name: r.sample_rate for p, r in zip(paths, runs)}
    first = next(iter(rates))
    for other, rate in rates.items():
        if abs(rate - rates[first]) > 1e-6 * rates[first]:
            raise PRSMHealthError(
                f"{other} is sampled at {rate:.6g} Hz, {first} at {rates[first]:.6g} Hz: one import "
                "needs one sample rate (resample first)"
            )
    channel_sets = {tuple(sorted(r.channels)) for r in runs}
    if len(channel_sets) > 1:
        raise PRSMHealthError("the recordings do not all have the same channels")
    given = list(table["split"]) if "split" in table.columns else _split(table, test_fraction, seed)
    split_of = dict(zip(table.index, given))

    tmp = out.with_name(f".{out.name}.importing-{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    (tmp / "signals").mkdir(parents=True)
    try:
        rows = []
        channels = [c for c in CHANNEL_NAMES if c in runs[0].channels]
        operating = spec.operating()
        for run_id, (path, run) in enumerate(zip(paths, runs)):
            row = {k: _plain(v) for k, v in table.loc[path.name].items() if k != "split"}
            if "clearance" in row:
                clearance = float(row.pop("clearance"))
                row["clearance_screw"] = row["clearance_nut"] = clearance
            label = {
                "run_id": run_id,
                "split": split_of[path.name],
                "recording": path.name,
                "source": str(path),
                # None for a rig that is not a PRSM; else the map's design name, fingerprint
                "design": operating.design,
                "design_fingerprint": operating.design_fingerprint,
                "lead": spec.lead,
                **row,
                "n_samples": len(run),
            }
            # the columns and units of a single-run file, as a generated dataset's shard
            table_ = pa.table({"run_id": np.full(len(run), run_id, np.int32), **run_columns(run)})
            schema = units_schema(table_.schema, run.sample_rate)
            schema = schema.with_metadata(
                {**schema.metadata, b"prsm_health.labels": dumps([label]).encode()}
            )
            shard = tmp / "signals" / f"part-{run_id:05d}.parquet"
            pq.write_table(table_.cast(schema), shard, compression="zstd")
            rows.append(dict(label, shard=f"signals/{shard.name}", row_group=0))
        frame = pd.DataFrame(rows)
        pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), tmp / "runs.parquet")
        classes = sorted(set(frame["fault_class"].astype(str))) if "fault_class" in frame else []
        manifest = {
            "name": name or out.name,
            "recipe": {
                "name": name or out.name,
                "imported": True,
                # a preset name or the design's full dict form, as a generated dataset's recipe
                "design": spec.design,
                "instrumentation": None,
                "map": spec.source,
                "labels": str(labels),
            },
            "design": (
                {"name": operating.design, "fingerprint": operating.design_fingerprint}
                if spec.design is not None
                else None
            ),
            "package": {"name": "prsm_health", "version": __version__},
            "sample_rate": runs[0].sample_rate,
            # the training window: n samples span n sample periods (a window of the first to the
            # last sample's time would cut the last sample off every recording in `diagnose`)
            "duration": min(len(r) / r.sample_rate for r in runs),
            "channels": {"time": "s", **{c: CHANNEL_UNITS[c] for c in channels}},
            "truth": {},
            "derived_channels": derived,
            "dtype": "float64",
            "formats": "parquet",
            "fault_taxonomy": {
                "classes": classes,
                "known_classes": [c for c in classes if c in FAULT_CLASSES],
                "thresholds": None,
                "rule": "labels given by the user (imported)",
            },
            "counts": dataset_counts(frame),
        }
        (tmp / "manifest.json").write_text(dumps(manifest, indent=2))
        if out.exists():
            shutil.rmtree(out)
        tmp.replace(out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {
        "out": str(out),
        "runs": len(rows),
        "channels": channels,
        "sample_rate": runs[0].sample_rate,
        "classes": classes,
        "train": manifest["counts"]["train"],
        "test": manifest["counts"]["test"],
        "indicator_groups": usable_groups(channels, runs[0].sample_rate),
    }


def _plain(value):
    """A label cell as a plain Python value (numpy scalars out, NaN as None)."""
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
