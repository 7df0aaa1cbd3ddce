"""Samples on the MCAP log-time clock (private): the ns conversion of sample times, batches of
one topic's samples, their merge and alignment on a common grid, and the sample rate and run
start recovered from the ``prsm_health`` metadata or from the log times.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from prsm_health.core.channels import CHANNEL_NAMES, TOPIC_FIELDS, TOPIC_TRUTH, TRUTH_NAMES
from prsm_health.core.errors import PRSMHealthError


def _require_positive(name: str, value, unit: str) -> None:
    """A user error unless ``value`` is a finite real number > 0 (not a bool)."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not (ok and 0 < value < math.inf):
        raise PRSMHealthError(f"{name} = {value!r} must be a finite number > 0 {unit}")


def _to_ns(seconds: np.ndarray) -> np.ndarray:
    """Times [s] as log-time offsets [ns], rounded to the nearest ns."""
    return np.round(seconds * 1e9).astype(np.int64)


@dataclass
class _Batch:
    """Samples of one topic: log times [ns] and one row per field."""

    topic: str
    log_time: np.ndarray  # int64
    fields: list[str]
    values: np.ndarray  # (len(fields), n) float64

    def sorted(self) -> _Batch:
        if len(self.log_time) > 1 and np.any(np.diff(self.log_time) < 0):
            order = np.argsort(self.log_time, kind="stable")
            return _Batch(self.topic, self.log_time[order], self.fields, self.values[:, order])
        return self


def _merge_topic(batches: list[_Batch]) -> _Batch:
    """Batches of one topic as one, in log-time order (NaN where a batch lacks a field)."""
    fields = []
    for batch in batches:
        fields += [f for f in batch.fields if f not in fields]
    log_time = np.concatenate([b.log_time for b in batches])
    values = np.full((len(fields), len(log_time)), np.nan)
    at = 0
    for batch in batches:
        rows = [fields.index(f) for f in batch.fields]
        values[rows, at : at + len(batch.log_time)] = batch.values
        at += len(batch.log_time)
    return _Batch(batches[0].topic, log_time, fields, values).sorted()


def _align(
    batches: dict[str, _Batch], *, trim: bool
) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Common log-time grid of several topics, and on it each measured contract channel and
    each truth signal (of :data:`TOPIC_TRUTH`), NaN where a topic has no sample.

    With ``trim``, the grid stops at the last time every topic reached (a truncated tail is
    incomplete).
    """
    grids = [b.log_time for b in batches.values()]
    same = all(np.array_equal(grids[0], g) for g in grids[1:])
    grid = grids[0] if same else np.unique(np.concatenate(grids))
    if trim and not same:
        grid = grid[grid <= min(g[-1] for g in grids if len(g))]
    channels, truth = {}, {}
    for topic, batch in batches.items():
        into = truth if topic == TOPIC_TRUTH else channels
        names = dict(TOPIC_FIELDS[topic])
        if same:
            placed = batch.values
        else:
            placed = np.full((len(batch.fields), len(grid)), np.nan)
            keep = batch.log_time <= grid[-1] if len(grid) else np.zeros(0, bool)
            placed[:, np.searchsorted(grid, batch.log_time[keep])] = batch.values[:, keep]
        for row, name in enumerate(batch.fields):
            into[names[name]] = np.ascontiguousarray(placed[row])
    ordered = {name: channels[name] for name in CHANNEL_NAMES if name in channels}
    return grid, ordered, {name: truth[name] for name in TRUTH_NAMES if name in truth}


def _sample_rate(info: dict, grid: np.ndarray, path: Path) -> float:
    try:
        rate = float(info["sample_rate"])
        if rate > 0 and math.isfinite(rate):
            return rate
    except (KeyError, ValueError):
        pass
    if len(grid) > 1:
        step = float(np.median(np.diff(grid)))
        if step > 0:
            return 1e9 / step
    raise PRSMHealthError(f"{path}: cannot tell the sample rate from {len(grid)} sample(s)")


def _start_ns(info: dict, grid: np.ndarray) -> int:
    try:
        return int(info["start_time_ns"])
    except (KeyError, ValueError):
        return int(grid[0]) if len(grid) else 0


def _times(grid: np.ndarray, start_ns: int, rate: float, exact_grid: bool) -> np.ndarray:
    """Sample times [s]; exactly ``arange(n) / rate`` when the log times are that grid."""
    relative = grid - start_ns
    if exact_grid:
        regular = np.arange(len(grid)) / rate
        if np.array_equal(_to_ns(regular), relative):
            return regular
    return relative / 1e9
