"""Reading a Parquet dataset back: runs table, labels and each run's signals (docs/formats.md).
pandas, polars, pyarrow and duckdb read the same files with no custom code; :class:`Dataset` adds
the contract's names and checks.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.design_files import load_design
from prsm_health.core.channels import CHANNEL_NAMES, CHECK_PHASE, TRUTH_PREFIX
from prsm_health.core.check_phases import CheckPhases
from prsm_health.core.errors import (
    PRSMHealthError,
    StorageError,
)
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run

from .store import DatasetStore


class Dataset:
    """A generated dataset directory: labels table and per-run signals.

    Parameters
    ----------
    path : path or str
        A local directory or an fsspec URL (``s3://bucket/prefix`` …), as for :func:`generate`.
    """

    def __init__(self, path: str | Path):
        import pandas as pd

        self._store = DatasetStore(path)
        #: A Path for a local dataset, the URL (str) for an object-store one.
        self.path = self._store.location
        if not self._store.exists("manifest.json"):
            raise PRSMHealthError(f"{self.path}: not a dataset directory (no manifest.json)")
        try:
            self.manifest = json.loads(self._store.read_text("manifest.json"))
            # a file object, not filesystem=: pandas < 2.1 has no such argument
            with self._store.open("runs.parquet") as file:
                self.runs = pd.read_parquet(file)
        except StorageError:
            raise
        except Exception as exc:  # damaged files
            raise PRSMHealthError(f"{self.path}: unreadable dataset ({exc})") from None

    @property
    def design(self) -> PRSMDesign | None:
        """The design the dataset's runs are of: the preset a recipe named, or the full design
        it was generated with (a design file's, stored in the manifest); None for an imported
        rig that is not a PRSM. Its fingerprint is every run's ``design_fingerprint`` label."""
        ref = self.manifest.get("recipe", {}).get("design")
        if ref is None:
            return None
        try:
            return load_design(ref)
        except PRSMHealthError as exc:  # a manifest edited by hand, or of another version
            raise PRSMHealthError(f"{self.path}: manifest.json recipe design: {exc}") from None

    @property
    def sample_rate(self) -> float:
        return float(self.manifest["sample_rate"])

    @property
    def channels(self) -> tuple[str, ...]:
        """The measured channels the dataset's runs have, in contract order."""
        return tuple(c for c in CHANNEL_NAMES if c in self.manifest["channels"])

    @property
    def indicator_groups(self) -> dict[str, str]:
        """Each indicator group → ``"usable"`` with this dataset's channels and sample rate, or
        why not (:func:`~prsm_health.signals.indicator_table.usable_groups`)."""
        from prsm_health.signals.indicator_table import usable_groups

        return usable_groups(self.channels, self.sample_rate)

    def __len__(self) -> int:
        return len(self.runs)

    def run(self, run_id: int, *, truth: bool = True) -> Run:
        """The signals of one run as a :class:`~prsm_health.core.run.Run` (one row group read):
        the measured channels, and the truth signals in ``Run.truth`` unless ``truth`` is
        False (then their columns are not read)."""
        import pyarrow.parquet as pq

        from prsm_health.io.columns import contract_channels, truth_columns

        rows = self.runs[self.runs["run_id"] == run_id]
        if rows.empty:
            raise PRSMHealthError(f"run_id {run_id} is not in {self.path}")
        row = rows.iloc[0]
        store = self._store
        with (
            store._io("read", row["shard"]),
            # a local shard read by pyarrow itself: through fsspec it took 1.5× as long
            pq.ParquetFile(
                store.path(row["shard"]), filesystem=None if store.local else store.fs
            ) as shard,
        ):
            names = shard.schema_arrow.names
            if not truth:
                names = [c for c in names if not c.startswith(TRUTH_PREFIX)]
            table = shard.read_row_group(int(row["row_group"]), columns=names)
        channels = contract_channels(
            store.name(row["shard"]), names, lambda c: table.column(c).to_numpy()
        )
        signals = truth_columns(names, lambda c: table.column(c).to_numpy())
        labels = {
            k: (v.item() if hasattr(v, "item") else v)
            for k, v in row.items()
            if k not in ("shard", "row_group")
        }
        phase, check = None, None
        if CHECK_PHASE in names:  # a health-check run: its phases, as the generator stored them
            phase = table.column(CHECK_PHASE).to_numpy().astype(np.int16)
            check = CheckPhases.from_record(json.loads(labels.get("check_phases") or "{}"))
        return Run(
            table.column("time").to_numpy(),
            channels,
            self.sample_rate,
            labels,
            # the design as a simulated run's scenario holds it (a preset name or the dict)
            {"recipe": self.manifest["recipe"], "design": self.manifest["recipe"].get("design")},
            truth=signals,
            check_phase=phase,
            check=check,
            # the design, reduction and nominal conditions are columns of runs.parquet
            operating=OperatingPoint.from_labels(labels),
        )

    def iter_runs(self, run_ids: Iterable[int] | None = None):
        for run_id in run_ids if run_ids is not None else self.runs["run_id"]:
            yield self.run(int(run_id))
