"""Your own rig's recordings as a dataset: CSV, Parquet or MCAP files plus a labels table.

``prsm-health import RECORDINGS… --labels LABELS.csv --map MAP.toml --out DIR`` (docs/import.md)
writes the dataset layout of :mod:`prsm_health.datasets` — one Parquet shard per recording, the
labels table ``runs.parquet``, ``manifest.json`` — so ``train`` and ``evaluate`` work on it as on
a generated dataset.

* **MAP.toml** — ``[columns]`` maps contract channel names (:mod:`prsm_health.core.channels`, plus
  ``time`` and the alias ``motor_current``) to the files' column names; ``[units]`` gives each
  mapped file column's unit (:data:`UNITS`), converted to SI; ``sample_rate`` [Hz] instead of a
  time column; optional ``design`` (a preset or design name; absent for a rig that is not a
  PRSM: design-dependent indicators are then NaN), ``lead`` [m per revolution of
  ``screw_angle``] for such a rig (lost motion needs it), ``torque_constant`` [N·m/A] to turn a
  ``motor_current`` into ``drive_torque``.
* **LABELS.csv** — a ``recording`` column (the file's name) and label columns: ``fault_class``,
  ``clearance`` [m] (both sides), any other; ``split`` (train/test) optional, else a
  deterministic stratified split.
* MCAP recordings in this project's layout carry contract channels in SI already; the map's
  columns and units apply to table files (CSV, Parquet).

Everything is checked before anything is written, and the dataset is assembled in a temporary
sibling directory renamed at the end: a failed import leaves nothing behind.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.channels import UNITS as CHANNEL_UNITS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps
from prsm_health.core.run import MIN_SAMPLES, Run
from prsm_health.core.tomlfile import read_toml

#: Lowest sample rate an import accepts [Hz].
MIN_RATE = 10.0
#: Quantity of each contract channel (and of ``time``, ``motor_current``).
QUANTITY = {
    "time": "time",
    "screw_angle": "angle",
    "screw_speed": "angular speed",
    "nut_position": "length",
    "nut_axial_accel": "acceleration",
    "nut_tangential_accel": "acceleration",
    "nut_radial_x_accel": "acceleration",
    "nut_radial_y_accel": "acceleration",
    "drive_torque": "torque",
    "axial_load": "force",
    "motor_current": "current",
}
_G = 9.80665
#: Unit spelling → (quantity, factor to SI). Declared once; docs/import.md prints it.
UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0),
    "ms": ("time", 1e-3),
    "us": ("time", 1e-6),
    "m": ("length", 1.0),
    "mm": ("length", 1e-3),
    "um": ("length", 1e-6),
    "µm": ("length", 1e-6),
    "in": ("length", 0.0254),
    "rad": ("angle", 1.0),
    "deg": ("angle", math.pi / 180),
    "rev": ("angle", 2 * math.pi),
    "rad/s": ("angular speed", 1.0),
    "deg/s": ("angular speed", math.pi / 180),
    "rpm": ("angular speed", 2 * math.pi / 60),
    "N*m": ("torque", 1.0),
    "N·m": ("torque", 1.0),
    "Nm": ("torque", 1.0),
    "N*mm": ("torque", 1e-3),
    "N·mm": ("torque", 1e-3),
    "Nmm": ("torque", 1e-3),
    "A": ("current", 1.0),
    "mA": ("current", 1e-3),
    "N": ("force", 1.0),
    "kN": ("force", 1e3),
    "kgf": ("force", _G),
    "lbf": ("force", 4.4482216152605),
    "m/s^2": ("acceleration", 1.0),
    "m/s²": ("acceleration", 1.0),
    "mm/s^2": ("acceleration", 1e-3),
    "mm/s²": ("acceleration", 1e-3),
    "g": ("acceleration", _G),
}
MAP_KEYS = ("columns", "units", "sample_rate", "design", "lead", "torque_constant")
TABLE_SUFFIXES = (".csv", ".parquet")


@dataclass(frozen=True)
class ImportMap:
    """A parsed, checked MAP.toml."""

    columns: dict[str, str]
    units: dict[str, str] = field(default_factory=dict)
    sample_rate: float | None = None
    design: str | None = None
    lead: float | None = None
    torque_constant: float | None = None
    source: dict = field(default_factory=dict)


def load_map(path: str | Path) -> ImportMap:
    """Parse and check a MAP.toml; errors name the file and the key."""
    path = Path(path)
    data = read_toml(path, "column map")
    unknown = sorted(set(data) - set(MAP_KEYS))
    if unknown:
        raise PRSMHealthError(
            f"{path}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(MAP_KEYS)}"
        )
    columns = data.get("columns")
    if not isinstance(columns, dict) or not columns:
        raise PRSMHealthError(
            f"{path}: [columns] must map channel names to your files' column names"
        )
    for name, column in columns.items():
        if name not in QUANTITY:
            raise PRSMHealthError(
                f"{path}: [columns] {name!r} is not a channel; use time, motor_current or one of "
                f"{', '.join(CHANNEL_NAMES)}"
            )
        if not isinstance(column, str) or not column:
            raise PRSMHealthError(f"{path}: [columns] {name} = {column!r} must be a column name")
    units = data.get("units", {})
    if not isinstance(units, dict):
        raise PRSMHealthError(f"{path}: [units] must map column names to units")
    for name, column in columns.items():
        unit = units.get(column, "s" if name == "time" else None)
        if unit is None:
            raise PRSMHealthError(f"{path}: [units] gives no unit for column {column!r} ({name})")
        if unit not in UNITS:
            raise PRSMHealthError(
                f"{path}: unit {unit!r} of column {column!r} is not understood; accepted: "
                f"{', '.join(UNITS)}"
            )
        if UNITS[unit][0] != QUANTITY[name]:
            accepted = [u for u, (q, _) in UNITS.items() if q == QUANTITY[name]]
            raise PRSMHealthError(
                f"{path}: column {column!r} ({name}) is a {QUANTITY[name]}, but its unit {unit!r} "
                f"is a {UNITS[unit][0]}; use one of {', '.join(accepted)}"
            )
    stray = sorted(set(units) - set(columns.values()))
    if stray:
        raise PRSMHealthError(
            f"{path}: [units] names column(s) {', '.join(stray)} that [columns] does not map"
        )
    rate = data.get("sample_rate")
    if ("time" in columns) == (rate is not None):
        raise PRSMHealthError(
            f"{path}: give either a time column ([columns] time = …) or sample_rate [Hz], not both or neither"
        )
    if rate is not None and not (isinstance(rate, (int, float)) and rate >= MIN_RATE):
        raise PRSMHealthError(f"{path}: sample_rate = {rate!r} must be a number ≥ {MIN_RATE:g} Hz")
    for key in ("lead", "torque_constant"):
        value = data.get(key)
        if value is not None and not (isinstance(value, (int, float)) and value > 0):
            raise PRSMHealthError(f"{path}: {key} = {value!r} must be a positive number")
    if "motor_current" in columns:
        if data.get("torque_constant") is None:
            raise PRSMHealthError(
                f"{path}: motor_current needs torque_constant [N·m/A] to become drive_torque"
            )
        if "drive_torque" in columns:
            raise PRSMHealthError(f"{path}: map motor_current or drive_torque, not both")
    design = data.get("design")
    if design is not None:
        from prsm_health.actuator.design import PRESETS

        if design not in PRESETS:
            raise PRSMHealthError(
                f"{path}: design = {design!r} must be a preset ({', '.join(sorted(PRESETS))}); "
                "leave it out for a rig that is not one of them (design-dependent indicators NaN)"
            )
    return ImportMap(
        columns=dict(columns),
        units=dict(units),
        sample_rate=None if rate is None else float(rate),
        design=design,
        lead=data.get("lead"),
        torque_constant=data.get("torque_constant"),
        source=data,
    )


def read_table(path: Path, spec: ImportMap) -> Run:
    """One CSV or Parquet recording through the map, in SI."""
    import pandas as pd

    try:
        frame = pd.read_csv(path) if path.suffix.lower() == ".csv" else pd.read_parquet(path)
    except Exception as exc:  # truncated or not a table
        raise PRSMHealthError(
            f"{path}: unreadable or truncated ({type(exc).__name__}: {exc})"
        ) from None
    missing = [c for c in spec.columns.values() if c not in frame.columns]
    if missing:
        raise PRSMHealthError(
            f"{path}: no column(s) {', '.join(map(repr, missing))} (the map's [columns]); the file "
            f"has {', '.join(map(str, list(frame.columns)[:10]))}"
        )
    values = {}
    for name, column in spec.columns.items():
        unit = spec.units.get(column, "s")
        try:
            x = frame[column].to_numpy(float) * UNITS[unit][1]
        except (TypeError, ValueError):
            raise PRSMHealthError(f"{path}: column {column!r} is not numeric") from None
        if not np.all(np.isfinite(x)):
            raise PRSMHealthError(f"{path}: column {column!r} has empty or non-finite values")
        values[name] = x
    n = len(frame)
    if "time" in values:
        time = values.pop("time")
        steps = np.diff(time)
        if n < 2 or not np.all(steps > 0):
            raise PRSMHealthError(f"{path}: time must increase strictly")
        rate = 1.0 / float(np.median(steps))
        if np.max(np.abs(steps - 1 / rate)) > 0.01 / rate:
            raise PRSMHealthError(f"{path}: time is not uniformly sampled (steps vary by > 1 %)")
        time = time - time[0]
    else:
        rate = spec.sample_rate
        time = np.arange(n) / rate
    if "motor_current" in values:
        values["drive_torque"] = values.pop("motor_current") * spec.torque_constant
    return Run(time, values, rate)


def _read(path: Path, spec: ImportMap) -> tuple[Run, list[str]]:
    if not path.exists():
        raise PRSMHealthError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix in TABLE_SUFFIXES:
        run = read_table(path, spec)
    elif suffix == ".mcap":
        from prsm_health.io.mcap import read_mcap

        run = read_mcap(path)
        run = Run(run.time - run.time[0], dict(run.channels), run.sample_rate)
    else:
        raise PRSMHealthError(f"{path}: unsupported file type {suffix!r} (.csv, .parquet, .mcap)")
    derived = []
    if "screw_speed" not in run.channels and "screw_angle" in run.channels:
        # the drive speed from the angle, as a drive's own estimate would (docs/import.md)
        run.channels["screw_speed"] = np.gradient(run.channels["screw_angle"], run.time)
        derived.append("screw_speed")
    if run.sample_rate < MIN_RATE:
        raise PRSMHealthError(
            f"{path}: sample rate {run.sample_rate:.3g} Hz is below {MIN_RATE:g} Hz"
        )
    if len(run) < MIN_SAMPLES:
        raise PRSMHealthError(
            f"{path}: {len(run)} samples; the indicators need at least {MIN_SAMPLES} "
            f"({MIN_SAMPLES / run.sample_rate:.3g} s at {run.sample_rate:g} Hz)"
        )
    return run.validate(what=str(path)), derived


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
    stray = sorted(set(table["recording"]) - set(names))
    if stray:
        raise PRSMHealthError(f"{path}: labels for recording(s) not given: {', '.join(stray)}")
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

    from prsm_health import __version__
    from prsm_health.actuator.faults import FAULT_CLASSES

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
    spec = load_map(map_path)
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
                "design": spec.design,
                "lead": spec.lead,
                **row,
                "n_samples": len(run),
            }
            columns = {
                "run_id": pa.array(np.full(len(run), run_id, np.int32)),
                "time": pa.array(run.time),
            }
            for c in channels:
                columns[c] = pa.array(run.channels[c])
            shard = tmp / "signals" / f"part-{run_id:05d}.parquet"
            metadata = {
                b"prsm_health.units": json.dumps(
                    {"time": "s", **{c: CHANNEL_UNITS[c] for c in channels}}
                ).encode(),
                b"prsm_health.sample_rate": repr(float(run.sample_rate)).encode(),
                b"prsm_health.labels": dumps([label]).encode(),
            }
            table_ = pa.table(columns)
            pq.write_table(table_.replace_schema_metadata(metadata), shard, compression="zstd")
            rows.append(dict(label, shard=f"signals/{shard.name}", row_group=0))
        frame = pd.DataFrame(rows)
        pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), tmp / "runs.parquet")
        classes = sorted(set(frame["fault_class"].astype(str))) if "fault_class" in frame else []
        manifest = {
            "name": name or out.name,
            "recipe": {
                "name": name or out.name,
                "imported": True,
                "design": spec.design,
                "instrumentation": None,
                "map": spec.source,
                "labels": str(labels),
            },
            "package": {"name": "prsm_health", "version": __version__},
            "sample_rate": runs[0].sample_rate,
            "duration": min(r.duration for r in runs),
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
    }


def _plain(value):
    """A label cell as a plain Python value (numpy scalars out, NaN as None)."""
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
