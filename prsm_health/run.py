"""A simulated or recorded run: time, contract channels, labels, and its single-file Parquet form.

Channel names and units follow the signal-channel contract of ../shared/DESIGN.md. A single run
written to ``.parquet`` has the columns ``time`` and every channel, with the units, sample rate,
labels and scenario in the Parquet schema metadata, so pandas/pyarrow/duckdb read it as is.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .dynamics.layout import CHANNELS
from .errors import PRSMHealthError

#: SI unit of every channel (contract).
UNITS = {
    "time": "s",
    "screw_angle": "rad",
    "screw_speed": "rad/s",
    "carrier_speed": "rad/s",
    "nut_position": "m",
    "nut_axial_accel": "m/s^2",
    "nut_tangential_accel": "m/s^2",
    "nut_radial_x_accel": "m/s^2",
    "nut_radial_y_accel": "m/s^2",
    "drive_torque": "N*m",
    "friction_torque": "N*m",
    "axial_load": "N",
}


@dataclass
class Run:
    """Sampled channels of one run.

    Attributes
    ----------
    time : ndarray [s]
    channels : dict of name → ndarray
        Contract channels (see :data:`UNITS`), SI.
    sample_rate : float [Hz]
    labels : dict
        Run labels (contract): clearances [m], nominal speed [rad/s] and load [N], seed, …
    scenario : dict
        Everything needed to re-run it (design, health, profile, sensors, options).
    energy : dict
        Energy book of the simulation [J] (drive, load, dissipated, friction) — empty for
        recordings.
    """

    time: np.ndarray
    channels: dict[str, np.ndarray]
    sample_rate: float
    labels: dict = field(default_factory=dict)
    scenario: dict = field(default_factory=dict)
    energy: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return lookup_channel(self.time, self.channels, name)

    def __len__(self) -> int:
        return len(self.time)

    def to_frame(self):
        """pandas DataFrame with ``time`` and the channels in contract order."""
        import pandas as pd

        data = {"time": self.time}
        data.update({name: self.channels[name] for name in CHANNELS if name in self.channels})
        return pd.DataFrame(data)

    def to_parquet(self, path: str | Path) -> Path:
        """Write the run as one Parquet file (atomic: temp file, then rename)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        path = Path(path)
        table = pa.Table.from_pandas(self.to_frame(), preserve_index=False)
        meta = {
            b"prsm_health.units": json.dumps({k: UNITS[k] for k in table.column_names}).encode(),
            b"prsm_health.sample_rate": repr(float(self.sample_rate)).encode(),
            b"prsm_health.labels": json.dumps(self.labels, default=json_default).encode(),
            b"prsm_health.scenario": json.dumps(self.scenario, default=json_default).encode(),
        }
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), **meta})
        tmp = path.with_name(path.name + ".partial")
        pq.write_table(table, tmp, compression="zstd")
        tmp.replace(path)
        return path

    @classmethod
    def from_parquet(cls, path: str | Path) -> Run:
        """Read a run written by :meth:`to_parquet` (or any Parquet file with contract columns)."""
        import pyarrow.parquet as pq

        path = Path(path)
        try:
            table = pq.read_table(path)
        except FileNotFoundError:
            raise PRSMHealthError(f"{path}: no such file") from None
        except Exception as exc:  # pyarrow raises several types for damaged files
            raise PRSMHealthError(f"{path}: not a readable Parquet file ({exc})") from None
        meta = table.schema.metadata or {}
        if "time" not in table.column_names:
            raise PRSMHealthError(f"{path}: no 'time' column")
        channels = {
            name: table.column(name).to_numpy().astype(float)
            for name in CHANNELS
            if name in table.column_names
        }
        if not channels:
            raise PRSMHealthError(f"{path}: none of the contract channels is present")
        time = table.column("time").to_numpy().astype(float)
        if b"prsm_health.sample_rate" in meta:
            rate = float(meta[b"prsm_health.sample_rate"])
        elif len(time) > 1:
            rate = 1.0 / float(np.median(np.diff(time)))
        else:
            raise PRSMHealthError(f"{path}: cannot tell the sample rate from one sample")
        labels = json.loads(meta.get(b"prsm_health.labels", b"{}"))
        scenario = json.loads(meta.get(b"prsm_health.scenario", b"{}"))
        return cls(time, channels, rate, labels, scenario)


def lookup_channel(time: np.ndarray, channels: dict[str, np.ndarray], name: str) -> np.ndarray:
    """``time`` or a named channel; an unknown name is a user error listing the available ones."""
    if name == "time":
        return time
    try:
        return channels[name]
    except KeyError:
        raise PRSMHealthError(
            f"unknown channel {name!r}; available: time, {', '.join(channels)}"
        ) from None


def json_default(value):
    """``json.dumps`` fallback for numpy arrays and scalars, and paths."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
