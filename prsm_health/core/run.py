"""A simulated or recorded run: time, measured channels, truth, operating point, labels.

Channel names and units follow the signal-channel contract (:mod:`prsm_health.core.channels`):
:attr:`Run.channels` holds the measured channels a recording has, :attr:`Run.truth` the
simulator's truth signals (empty for a recording from hardware); the two never mix. A run as a
table (:meth:`Run.to_frame`, the single-run Parquet file of :mod:`prsm_health.io.parquet`) has
the columns ``time``, the measured channels, then ``truth_<name>`` for each truth signal.
What the run is of and how it ran travels typed: :attr:`Run.operating` (design, reduction,
nominal conditions) and :attr:`Run.check` (a health check's phases); :attr:`Run.labels` is
ground truth (a simulated or dataset run's clearances, fault class, seed, …), never read by the
diagnosis.
:meth:`Run.validate` is the one place that decides whether a recording can be processed,
:meth:`Run.windows` the one place recordings are cut into windows.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .channels import CHANNEL_NAMES, CHECK_PHASE, TRUTH_NAMES, truth_column
from .check_phases import CheckPhases
from .errors import PRSMHealthError, RecordingError, RecordingTooLongError
from .operating_point import OperatingPoint

#: Fewest samples a recording or window needs: below it the spectra have too few bins for the
#: indicators (a 256-point Welch segment).
MIN_SAMPLES = 256
#: A tail of this many samples or fewer (a recording that ends one sample past its last
#: window) is not worth a note about what was not diagnosed.
_TAIL_WORTH_A_NOTE = 5


@dataclass
class Run:
    """Sampled channels of one run.

    Attributes
    ----------
    time : ndarray [s]
    channels : dict of name → ndarray
        Measured contract channels (:data:`~prsm_health.core.channels.CHANNEL_NAMES`), SI: what the
        sensors gave. A recording may lack some.
    sample_rate : float [Hz]
    labels : dict
        Ground truth (the run-label contract, docs/formats.md): clearances [m], fault class,
        seed, … of a simulated or dataset run; empty for a recording. Never read by the
        diagnosis.
    scenario : dict
        Everything needed to re-run it (design, health, profile, sensors, options).
    energy : dict
        Energy book of the simulation [J] (drive, load, dissipated, friction) — empty for
        recordings.
    truth : dict of name → ndarray
        Truth signals of a simulated run (:data:`~prsm_health.core.channels.TRUTH_NAMES`, without
        the ``truth_`` prefix), SI, on the same time axis, free of sensor errors — empty for
        recordings. Never an input of the diagnosis.
    check_phase : ndarray of int or None
        Health-check phase of every sample (a phase's ``index`` in ``check``, −1 outside any
        phase), None when the run is no check. Known to the controller (it commands the
        phases), so a recording from hardware may have it too.
    check : CheckPhases or None
        The check's name and its phases (span [s] and commanded condition); None when the run
        is no check.
    operating : OperatingPoint
        The design the run is of, the reduction, the nominal conditions: what the diagnosis
        reads about a recording beside its samples (every field may be unknown).
    """

    time: np.ndarray
    channels: dict[str, np.ndarray]
    sample_rate: float
    labels: dict = field(default_factory=dict)
    scenario: dict = field(default_factory=dict)
    energy: dict = field(default_factory=dict)
    truth: dict[str, np.ndarray] = field(default_factory=dict)
    check_phase: np.ndarray | None = None
    check: CheckPhases | None = None
    operating: OperatingPoint = field(default_factory=OperatingPoint)

    def __getitem__(self, name: str) -> np.ndarray:
        if name in self.truth and name not in self.channels:
            raise PRSMHealthError(
                f"{name!r} is not a measured channel of this run; its truth is run.truth[{name!r}]"
            )
        return lookup_channel(self.time, self.channels, name)

    def __len__(self) -> int:
        return len(self.time)

    @property
    def duration(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.time[-1] - self.time[0]) if len(self.time) else 0.0

    def validate(
        self,
        *,
        min_samples: int = MIN_SAMPLES,
        max_samples: int | None = None,
        max_abs: float | None = None,
        max_time: float | None = None,
        what: str = "recording",
    ) -> Run:
        """Check that the recording can be processed; returns self.

        Parameters
        ----------
        min_samples, max_samples : int
            Accepted length [samples].
        max_abs : float or None
            Largest accepted magnitude of a sample (SI); beyond it the indicators overflow.
            None: no bound.
        max_time : float or None [s]
            Largest accepted magnitude of the time axis. None: no bound.
        what : str
            How the messages name the recording.

        Raises
        ------
        RecordingError
            Too short, no channel, non-finite or non-increasing time, a channel or truth
            signal of another length, non-finite samples, out-of-range channel samples.
        RecordingTooLongError
            More than ``max_samples`` samples.
        """
        n, rate = len(self), float(self.sample_rate)
        if not (np.isfinite(rate) and rate > 0):
            raise RecordingError(f"{what}: sample rate {rate:g} Hz must be finite and > 0")
        if not self.channels:
            raise RecordingError(f"{what}: no contract channel ({', '.join(CHANNEL_NAMES)})")
        if n < min_samples:
            raise RecordingError(
                f"{what} too short: {n} samples, need at least {min_samples} "
                f"({min_samples / rate:.3g} s at {rate:g} Hz){ms_hint(rate)}"
            )
        if max_samples is not None and n > max_samples:
            raise RecordingTooLongError(
                f"{what} too long: {n} samples ({n / rate:.6g} s at {rate:g} Hz); "
                f"at most {max_samples} samples accepted here"
            )
        time = np.asarray(self.time, dtype=float)
        if not (np.all(np.isfinite(time)) and np.all(np.diff(time) > 0)):
            raise RecordingError(f"{what}: time must be finite and strictly increasing")
        if max_time is not None and float(np.max(np.abs(time))) > max_time:
            raise RecordingError(
                f"{what}: time beyond ±{max_time:g} s (use time from the recording start)"
            )
        for name, values in self.channels.items():
            values = np.asarray(values, dtype=float)
            if len(values) != n:
                raise RecordingError(
                    f"{what}: channel {name} has {len(values)} samples, time has {n}"
                )
            if not np.all(np.isfinite(values)):
                raise RecordingError(f"{what}: channel {name} contains NaN or infinite values")
            if max_abs is not None and values.size and float(np.max(np.abs(values))) > max_abs:
                raise RecordingError(
                    f"{what}: channel {name} has samples beyond ±{max_abs:g} "
                    "(SI units expected: m, rad, N, N·m, m/s²)"
                )
        for name, values in self.truth.items():
            values = np.asarray(values, dtype=float)
            if len(values) != n:
                raise RecordingError(
                    f"{what}: truth {name} has {len(values)} samples, time has {n}"
                )
            if not np.all(np.isfinite(values)):
                raise RecordingError(f"{what}: truth {name} contains NaN or infinite values")
        if self.check_phase is not None and len(self.check_phase) != n:
            raise RecordingError(
                f"{what}: {CHECK_PHASE} has {len(self.check_phase)} samples, time has {n}"
            )
        return self

    def without_truth(self) -> Run:
        """The same recording with the measured channels only (arrays shared, not copied)."""
        return replace(self, truth={})

    def slice(self, start: int, stop: int) -> Run:
        """Samples ``[start, stop)`` as a run (views): channels, truth, check phase, with the
        labels, scenario, check and operating point; no energy book (it is the whole run's)."""
        sl = slice(start, stop)
        return replace(
            self,
            time=self.time[sl],
            channels={k: v[sl] for k, v in self.channels.items()},
            truth={k: v[sl] for k, v in self.truth.items()},
            check_phase=None if self.check_phase is None else self.check_phase[sl],
            energy={},
        )

    def windows(
        self, length: float, *, hop: float | None = None, min_tail: float | None = None
    ) -> tuple[list[Run], list[str]]:
        """The run cut into windows of ``length`` seconds (views), and notes on what is not in
        one: the one place windows are cut (features, diagnosis, service).

        Window ``k`` holds the samples ``[k·step, k·step + n)`` (:func:`window_span`), ``n``
        and ``step`` being ``length`` and ``hop`` in samples.

        Parameters
        ----------
        length : float [s]
            Window length; at least :data:`MIN_SAMPLES` samples.
        hop : float or None [s]
            Hop between window starts; default ``length`` (contiguous windows).
        min_tail : float or None
            None: complete windows only (a run shorter than one window gives none), no notes.
            A fraction of a window: a run shorter than one window is one short window; the
            samples after the last complete window are a last, shorter window when they are
            at least ``min_tail`` of a window (and :data:`MIN_SAMPLES`), else left out; the
            notes say which.

        Raises
        ------
        PRSMHealthError
            A window or hop shorter than the indicators' minimum or than one sample.
        """
        rate = float(self.sample_rate)
        n = int(round(length * rate)) if np.isfinite(length) else 0
        step = n if hop is None else (int(round(hop * rate)) if np.isfinite(hop) else 0)
        if n < MIN_SAMPLES:
            raise PRSMHealthError(
                f"window length {length:g} s gives {n} samples, need at least {MIN_SAMPLES}"
                f"{ms_hint(rate)}"
            )
        if step < 1:
            raise PRSMHealthError(f"hop {hop:g} s is shorter than one sample at {rate:g} Hz")
        total = len(self)
        if min_tail is not None and total < n:
            return [self], [
                f"recording ({self.duration:.2g} s) is shorter than the window ({length:g} s): "
                "diagnosed as one short window"
            ]
        count = complete_windows(total, n, step)
        parts = [self.slice(*window_span(k, n, step)) for k in range(count)]
        if min_tail is None:
            return parts, []
        end = window_span(count - 1, n, step)[1]
        tail = total - end
        notes = []
        if tail >= max(MIN_SAMPLES, min_tail * n):
            parts.append(self.slice(end, total))
            notes.append(f"last window is {tail / rate:.2g} s, shorter than {length:g} s")
        elif tail > max(_TAIL_WORTH_A_NOTE, 0.01 * n):  # the closing sample or so: no news
            fraction = "half a window" if min_tail == 0.5 else f"{min_tail:g} of a window"
            notes.append(
                f"last {tail / rate:.2g} s not diagnosed: shorter than {fraction} "
                f"({min_tail * length:.2g} s)"
            )
        return parts, notes

    def phases(self) -> dict[str, Run]:
        """The samples of each health-check phase as a run (views), by phase name, in check
        order (the ramps between phases, ``check_phase`` −1, are in none); empty when the run
        is no check. A phase is one contiguous span of samples (:meth:`slice`)."""
        if self.check_phase is None:
            return {}
        phase = np.asarray(self.check_phase)
        names = self.check.names() if self.check is not None else {}
        out = {}
        for index in np.unique(phase[phase >= 0]):
            where = np.flatnonzero(phase == index)
            out[names.get(int(index), str(int(index)))] = self.slice(where[0], where[-1] + 1)
        return out

    def columns(self) -> dict[str, np.ndarray]:
        """The run as file columns (contract): ``time``, the measured channels, ``check_phase``
        (int16, when the run is a check), then ``truth_<name>`` for each truth signal, in
        contract order."""
        data = {"time": self.time}
        data.update({name: self.channels[name] for name in CHANNEL_NAMES if name in self.channels})
        if self.check_phase is not None:
            data[CHECK_PHASE] = np.asarray(self.check_phase, dtype=np.int16)
        data.update({truth_column(n): self.truth[n] for n in TRUTH_NAMES if n in self.truth})
        return data

    def to_frame(self):
        """pandas DataFrame of :meth:`columns`."""
        import pandas as pd

        return pd.DataFrame(self.columns())


def window_span(
    index: int, length: int, step: int | None = None, origin: int = 0
) -> tuple[int, int]:
    """``[start, end)`` of window ``index`` when windows of ``length`` start every ``step``
    (default ``length``) from ``origin``: the boundary arithmetic of every windowing, in any
    integer unit (samples for :meth:`Run.windows`, nanoseconds of log time for the MCAP
    replay)."""
    start = origin + index * (length if step is None else step)
    return start, start + length


def complete_windows(total: int, length: int, step: int | None = None) -> int:
    """How many windows of :func:`window_span` fit completely in ``total`` units from 0."""
    step = length if step is None else step
    return 0 if total < length else (total - length) // step + 1


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


def ms_hint(rate: float) -> str:
    """'; is time in ms?' when a sample rate is implausibly low for a vibration recording but
    plausible × 1000 (20 kHz sampled, time written in ms, reads as 20 Hz)."""
    if 1.0 <= rate < 100.0:
        return (
            f" — the time axis gives {rate:g} Hz; if time is in milliseconds, convert it to "
            f"seconds ({1000 * rate:g} Hz)"
        )
    return ""
