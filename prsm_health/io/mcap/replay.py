"""Streaming replay of a recording as fixed-length windows (:func:`iter_windows`), and the
classic indicators of a window (:func:`window_statistics`).

The replay never holds the whole file: it decodes one chunk at a time, in log-time order
(through the summary's chunk index when the file has one, else by scanning the records), and
keeps only the unfinished window. Window boundaries follow
:func:`~prsm_health.core.run.window_span`, as :meth:`Run.windows <prsm_health.core.run.Run.windows>`
cuts a run in memory (here in nanoseconds of log time, there in samples), from
:func:`window_origin_ns`; a window is complete once a sample reaches
:func:`window_reached_ns` — the log-time rules the live view (:mod:`prsm_health.apps.live`)
also cuts a run in memory by.
"""

from __future__ import annotations

import math
import os
import time as _time
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np

from prsm_health.core.channels import TOPIC_FIELDS
from prsm_health.core.errors import PRSMHealthError, TruncatedRecordingWarning
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import lookup_channel, window_span

from ._samples import _align, _Batch, _merge_topic, _require_positive, _sample_rate, _start_ns
from ._scan import _chunk_batches, _Damaged, _Source, _unchunked_batches

__all__ = [
    "Window",
    "WindowStream",
    "iter_windows",
    "window_origin_ns",
    "window_reached_ns",
    "window_statistics",
]


def window_origin_ns(run_start_ns: int, first_sample_ns: int) -> int:
    """Log time [ns] at which window 0 starts: the run start, or the first sample when one
    comes before it (windows are then :func:`~prsm_health.core.run.window_span` from there)."""
    return min(int(run_start_ns), int(first_sample_ns))


def window_reached_ns(end_ns: int, sample_rate: float | None) -> float:
    """Log time [ns] a window ending at ``end_ns`` is complete from: its last sample lies at most
    one sample period (+1 ns of log-time rounding) before its end. ``sample_rate`` [Hz] None or
    0: unknown, the end itself (−1 ns)."""
    period = 1e9 / sample_rate if sample_rate else 0.0
    return end_ns - period - 1


@dataclass(frozen=True, eq=False)
class Window:
    """A fixed-length stretch of a recording, as replayed by :func:`iter_windows`.

    Attributes
    ----------
    index : int
        Window number, from 0.
    start, end : float [s]
        Window span from the run start, ``[start, end)``.
    start_ns, end_ns : int [ns]
        The same span in log time (for messages written about this window).
    time : ndarray [s]
        Sample times from the run start.
    channels : dict of name → ndarray
        Measured contract channels, SI; NaN where a topic has no sample at a time another has.
    labels : dict
        Run labels of the recording.
    operating : OperatingPoint
        The recording's design, reduction and nominal conditions.
    sample_rate : float [Hz]
    truth : dict of name → ndarray
        Truth signals of ``/prsm/truth``, when replayed (simulated recordings); never an input
        of the diagnosis.
    """

    index: int
    start: float
    end: float
    start_ns: int
    end_ns: int
    time: np.ndarray
    channels: dict[str, np.ndarray]
    labels: dict = field(default_factory=dict)
    operating: OperatingPoint = field(default_factory=OperatingPoint)
    sample_rate: float = 0.0
    truth: dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.time)

    def __getitem__(self, name: str) -> np.ndarray:
        return lookup_channel(self.time, self.channels, name)


class _TopicBuffer:
    """Buffered samples of one topic, consumed from the front."""

    def __init__(self, topic: str):
        self.topic = topic
        self.log_time = np.zeros(0, dtype=np.int64)
        self.fields: list[str] = []
        self.values = np.zeros((0, 0))

    def __len__(self) -> int:
        return len(self.log_time)

    def append(self, batch: _Batch) -> None:
        """Add samples, keeping the buffer in log-time order."""
        if not len(self):
            self.log_time, self.fields, self.values = batch.log_time, batch.fields, batch.values
            return
        if batch.fields != self.fields or batch.log_time[0] < self.log_time[-1]:
            merged = _merge_topic([self.as_batch(), batch])
            self.log_time, self.fields, self.values = merged.log_time, merged.fields, merged.values
            return
        self.log_time = np.concatenate([self.log_time, batch.log_time])
        self.values = np.concatenate([self.values, batch.values], axis=1)

    def as_batch(self) -> _Batch:
        return _Batch(self.topic, self.log_time, list(self.fields), self.values)

    def take(self, start: int, end: int, drop_before: int) -> _Batch:
        """Samples in ``[start, end)``; forget those before ``drop_before``."""
        a, b = np.searchsorted(self.log_time, [start, end])
        out = _Batch(self.topic, self.log_time[a:b], list(self.fields), self.values[:, a:b])
        keep = int(np.searchsorted(self.log_time, drop_before))
        self.log_time = self.log_time[keep:]
        self.values = self.values[:, keep:]
        return out


class WindowStream(Iterator[Window]):
    """Iterator of :class:`Window` over an MCAP recording (see :func:`iter_windows`).

    Attributes
    ----------
    peak_buffered : int
        Largest number of samples of one topic held at once: the unfinished window plus the
        chunk just decoded — not the file.
    late_samples : int
        Samples dropped because they arrived after their window was emitted (only possible
        in files without a summary whose messages are out of log-time order).
    """

    def __init__(self, path, window, *, step=None, rate=None, topics=None, partial=False):
        _require_positive("window", window, "[s]")
        step = window if step is None else step
        _require_positive("step", step, "[s]")
        if rate is not None:
            _require_positive("rate", rate, "(or None)")
        topics = tuple(
            TOPIC_FIELDS if topics is None else ([topics] if isinstance(topics, str) else topics)
        )
        unknown = [t for t in topics if t not in TOPIC_FIELDS]
        if unknown or not topics:
            raise PRSMHealthError(
                f"cannot replay topics {unknown or list(topics)}; signal topics are "
                f"{', '.join(TOPIC_FIELDS)}"
            )
        self.window_ns = int(round(window * 1e9))
        self.step_ns = int(round(step * 1e9))
        if self.window_ns < 1 or self.step_ns < 1:
            raise PRSMHealthError("window and step must be at least 1 ns")
        self.rate = rate
        self.partial = partial
        self.peak_buffered = 0
        self.late_samples = 0
        self._source = _Source(path, topics)
        self._buffers = {t: _TopicBuffer(t) for t in topics}
        self._index = 0
        self._origin: int | None = None  # log time of the run start
        self._first: int | None = None  # log time of window 0
        self._emitted_until: int | None = None
        self._wall0 = 0.0
        self._rate_hz: float | None = None
        self._windows = self._generate()

    def __next__(self) -> Window:
        return next(self._windows)

    def close(self) -> None:
        """Stop early and release the file."""
        self._windows.close()
        self._source.close()

    # ------------------------------------------------------------------ batches in time order
    def _batches(self) -> Iterator[list[_Batch]]:
        source = self._source
        summary = source.summary()
        if summary is not None and summary.chunk_indexes:
            source.read_indexed(summary)
            if not source.wanted:
                raise source.no_topics_error()
            yield from self._indexed_batches(summary)
        else:
            loose: list = []
            for kind, *rest in source.scan():
                if kind == "chunk":
                    yield [b.sorted() for b in _chunk_batches(source, rest[1])]
                elif kind == "message":
                    loose.append(rest[0])
                    if len(loose) >= 4096:
                        yield [b.sorted() for b in _unchunked_batches(source, loose)]
                        loose = []
            if loose:
                yield [b.sorted() for b in _unchunked_batches(source, loose)]
            if not source.wanted:
                raise source.no_topics_error()
        if source.damage:
            warnings.warn(
                f"{source.path}: {source.damage}; replay stopped there",
                TruncatedRecordingWarning,
                stacklevel=3,
            )

    def _indexed_batches(self, summary) -> Iterator[list[_Batch]]:
        """Chunks in start-time order; messages released once no later chunk can precede them.

        The same rule as mcap's log-time-order reader, applied to whole decoded chunks, so
        overlapping chunks (e.g. a diagnosis appended after the signals) stay in order.
        """
        source = self._source
        wanted = set(source.wanted)
        chunks = [
            ci
            for ci in summary.chunk_indexes
            if not ci.message_index_offsets or wanted.intersection(ci.message_index_offsets)
        ]
        chunks.sort(key=lambda ci: (ci.message_start_time, ci.chunk_start_offset))
        pending: dict[str, list[_Batch]] = {}
        for k, chunk_index in enumerate(chunks):
            try:
                walked = source.read_chunk(chunk_index)
            except (_Damaged, *source.errors) as exc:
                source.damage = f"damaged chunk at byte {chunk_index.chunk_start_offset}: {exc}"
                break
            for batch in _chunk_batches(source, walked):
                pending.setdefault(batch.topic, []).append(batch)
            bound = chunks[k + 1].message_start_time if k + 1 < len(chunks) else None
            ready = []
            for topic, batches in pending.items():
                merged = _merge_topic(batches)
                if bound is None:
                    cut = len(merged.log_time)
                else:
                    cut = int(np.searchsorted(merged.log_time, bound))
                ready.append(
                    _Batch(topic, merged.log_time[:cut], merged.fields, merged.values[:, :cut])
                )
                pending[topic] = [
                    _Batch(topic, merged.log_time[cut:], merged.fields, merged.values[:, cut:])
                ]
            yield ready
        else:
            return
        # Damage: release what was read so far.
        yield [_merge_topic(b) for b in pending.values() if b]

    # ------------------------------------------------------------------ windows
    def _generate(self) -> Iterator[Window]:
        try:
            for batches in self._batches():
                for batch in batches:
                    if not len(batch.log_time) or not batch.fields:
                        continue
                    self._start(batch)
                    buffer = self._buffers[batch.topic]
                    if self._emitted_until is not None:
                        late = batch.log_time < self._emitted_until
                        if late.any():
                            self.late_samples += int(late.sum())
                            batch = _Batch(
                                batch.topic,
                                batch.log_time[~late],
                                batch.fields,
                                batch.values[:, ~late],
                            )
                    buffer.append(batch)
                self._note_buffered()
                yield from self._ready(final=False)
            yield from self._ready(final=True)
            if self._first is None and not any(len(b) for b in self._buffers.values()):
                where = f": {self._source.damage}" if self._source.damage else ""
                raise PRSMHealthError(f"{self._source.path}: no samples could be read{where}")
        finally:
            self._source.close()
        if self.late_samples:
            warnings.warn(
                f"{self._source.path}: {self.late_samples} samples arrived after their window "
                "(messages out of log-time order in a file without a summary) and were dropped",
                UserWarning,
                stacklevel=2,
            )

    def _start(self, batch: _Batch) -> None:
        if self._first is not None:
            return
        info = self._source.info()
        self._origin = _start_ns(info, batch.log_time)
        self._first = window_origin_ns(self._origin, batch.log_time[0])
        try:
            self._rate_hz = _sample_rate(info, batch.log_time, self._source.path)
        except PRSMHealthError:
            self._rate_hz = None
        self._wall0 = _time.monotonic()

    def _note_buffered(self) -> None:
        held = max(len(b) for b in self._buffers.values())
        self.peak_buffered = max(self.peak_buffered, held)

    def _ready(self, *, final: bool) -> Iterator[Window]:
        if self._first is None:
            return
        declared = set(self._source.wanted.values()) & set(self._buffers)
        while True:
            start, end = window_span(self._index, self.window_ns, self.step_ns, self._first)
            newest = {t: int(b.log_time[-1]) for t, b in self._buffers.items() if len(b)}
            if not newest:
                return
            latest = max(newest.values())
            if latest < start:
                return
            reached = window_reached_ns(end, self._rate_hz)  # complete once a sample is there
            if final:
                if latest < reached and not self.partial:
                    return
            elif any(newest.get(t, -1) < reached for t in declared):
                # A topic that stopped must not make the others pile up: wait at most one
                # window beyond the end.
                if latest < end + self.window_ns:
                    return
            parts = {
                t: b.take(start, end, start + self.step_ns)
                for t, b in self._buffers.items()
                if len(b)
            }
            self._emitted_until = start + self.step_ns
            self._index += 1
            parts = {t: p for t, p in parts.items() if len(p.log_time)}
            if not parts:
                continue
            grid, channels, truth = _align(parts, trim=False)
            rate = self._rate_hz
            if rate is None:
                rate = 1e9 / float(np.median(np.diff(grid))) if len(grid) > 1 else 0.0
            self._pace(end)
            yield Window(
                index=self._index - 1,
                start=(start - self._origin) / 1e9,
                end=(end - self._origin) / 1e9,
                start_ns=start,
                end_ns=end,
                time=(grid - self._origin) / 1e9,
                channels=channels,
                labels=self._source.labels(),
                operating=self._source.operating(),
                sample_rate=rate,
                truth=truth,
            )

    def _pace(self, end_ns: int) -> None:
        if self.rate is None:
            return
        due = self._wall0 + (end_ns - self._first) / 1e9 / self.rate
        now = _time.monotonic()
        if due > now:
            _time.sleep(due - now)


def iter_windows(
    path: str | os.PathLike,
    window: float,
    *,
    step: float | None = None,
    rate: float | None = None,
    topics: Iterable[str] | None = None,
    partial: bool = False,
) -> WindowStream:
    """Replay a recording as fixed-length windows, streaming (never the whole file in memory).

    Parameters
    ----------
    path : str or path-like
        MCAP recording (with or without summary; a damaged tail ends the replay with a
        :class:`TruncatedRecordingWarning`).
    window : float [s]
        Window length; window ``k`` spans ``[t0 + k·step, t0 + k·step + window)`` in log time,
        ``t0`` the run start.
    step : float [s], optional
        Hop between window starts (default ``window``: contiguous, no overlap).
    rate : float, optional
        Real-time factor: windows are released as log time advances ``rate`` times faster than
        wall time (``1`` = real time). None: as fast as possible.
    topics : iterable of str, optional
        Signal topics to replay: default all of them, the measured :data:`TOPIC_NUT_ACCEL` and
        :data:`TOPIC_DRIVE` and, in a simulated recording, :data:`TOPIC_TRUTH`
        (:data:`~prsm_health.core.channels.MEASURED_TOPICS` replays the measurements only).
    partial : bool
        Also yield the last, incomplete window.

    Returns
    -------
    WindowStream
        Iterator of :class:`Window` in log-time order; its ``peak_buffered`` attribute reports
        the most samples held at once.

    Raises
    ------
    PRSMHealthError
        Bad parameters or a file that is missing or not MCAP (at the call); none of the
        topics or no sample in the file (when iteration starts).
    """
    return WindowStream(path, window, step=step, rate=rate, topics=topics, partial=partial)


def window_statistics(window: Window) -> dict[str, dict[str, float]]:
    """Classic indicators of each channel of a window, NaN samples ignored.

    Parameters
    ----------
    window : Window

    Returns
    -------
    dict
        Channel → ``{"mean", "rms", "peak", "crest_factor"}`` in the channel's unit (crest
        factor dimensionless): mean, root mean square and largest absolute value of the raw
        signal (mean included), and peak / rms (NaN when rms is 0 or no sample is finite).
    """
    out = {}
    for name, values in window.channels.items():
        x = np.asarray(values, dtype=np.float64)
        x = x[np.isfinite(x)]
        if len(x) == 0:
            out[name] = dict.fromkeys(("mean", "rms", "peak", "crest_factor"), math.nan)
            continue
        rms = float(np.sqrt(np.mean(x * x)))
        peak = float(np.max(np.abs(x)))
        out[name] = {
            "mean": float(np.mean(x)),
            "rms": rms,
            "peak": peak,
            "crest_factor": peak / rms if rms > 0 else math.nan,
        }
    return out
