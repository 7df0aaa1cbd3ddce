"""A simulated or recorded run: time, contract channels, labels, and its single-file Parquet form.

Channel names and units follow the signal-channel contract (:mod:`prsm_health.channels`). A
single run written to ``.parquet`` has the columns ``time`` and every channel, with the units,
sample rate, labels and scenario in the Parquet schema metadata, so pandas/pyarrow/duckdb read it
as is. :meth:`Run.validate` is the one place that decides whether a recording can be processed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .channels import CHANNEL_NAMES
from .errors import PRSMHealthError, RecordingError, RecordingTooLongError

#: Fewest samples a recording or window needs: below it the spectra have too few bins for the
#: indicators (a 256-point Welch segment).
MIN_SAMPLES = 256


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
            Too short, no channel, non-finite or non-increasing time, a channel of another
            length, non-finite or out-of-range samples.
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
        return self

    def to_frame(self):
        """pandas DataFrame with ``time`` and the channels in contract order."""
        import pandas as pd

        data = {"time": self.time}
        data.update({name: self.channels[name] for name in CHANNEL_NAMES if name in self.channels})
        return pd.DataFrame(data)


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
