"""What one request may ask of the service: :class:`ServiceLimits`."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from prsm_health.core.errors import PRSMHealthError, RecordingError

#: Largest magnitude accepted for any sample (SI units): far above any physical
#: reading, far below where squares and fourth powers of a window overflow float64 in the
#: indicators.
MAX_ABS_VALUE = 1e12
#: Largest accepted time [s] of a recording's samples: time runs from the recording start.
MAX_TIME = 1e7
#: Largest accepted operating hours [h] of an asset (over a thousand years: a typing error).
MAX_OPERATING_HOURS = 1e7


def _longest_built_in_check() -> float:
    """Duration [s] of the longest built-in health check (prsm_health.actuator.health_check)."""
    from prsm_health.actuator.health_check import BUILT_IN

    return max(check.duration for check in BUILT_IN.values())


#: Default longest recording of ``POST /v1/diagnose`` [s]: 2 s of in-service signal, or the
#: longest built-in health check rounded up to the half second when that is longer (2.62 s →
#: 3 s) — a check is one recording, read phase by phase, and must fit in one request.
DEFAULT_MAX_WINDOW_SECONDS = max(2.0, math.ceil(2.0 * _longest_built_in_check()) / 2.0)


@dataclass(frozen=True)
class ServiceLimits:
    """Bounds on what one request may ask of the service.

    Attributes
    ----------
    max_body_bytes : int [bytes]
        Largest body of ``POST /v1/diagnose`` (JSON, Arrow IPC, Parquet or MCAP).
    max_body_decoded_bytes : int [bytes]
        Most bytes a binary body of ``POST /v1/diagnose`` may decompress to (Arrow IPC
        buffers, Parquet row groups, MCAP chunks), checked from what the body declares
        before it is decoded.
    max_upload_bytes : int [bytes]
        Largest multipart body of ``POST /v1/diagnose/file``.
    max_small_body_bytes : int [bytes]
        Largest body on every other endpoint.
    max_window_seconds : float [s]
        Longest recording ``POST /v1/diagnose`` accepts: ``max_window_seconds · sample_rate``
        samples (default :data:`DEFAULT_MAX_WINDOW_SECONDS`: the longest built-in health check
        fits).
    max_upload_samples : int
        Most samples an uploaded recording may hold (checked from the file's metadata before
        it is decoded, when the file has it, and again after).
    max_upload_decoded_bytes : int [bytes]
        Most bytes an uploaded file may decompress to (MCAP chunks, Parquet row groups).
    min_sample_rate, max_sample_rate : float [Hz]
        Accepted sample rates.
    workers : int
        Diagnoses (parse + diagnose) running at once in worker threads when ``processes`` is
        0; more requests wait their turn. Default: half the CPUs. A diagnosis holds the GIL
        much of the time, so threads add little: on 2 CPUs, 40 in-process diagnoses of 1 s
        recordings ran at 22 per s on one thread and 19 per s on two, and the service with one
        worker gave as much throughput as with two, a lower p99 latency and half the
        /v1/health p99 (docs/service.md).
    processes : int
        Diagnosis processes (each loads the model once and diagnoses one request at a time);
        0: diagnose in worker threads of the server process (``workers``). Processes use the
        cores in parallel (docs/service.md has the measured throughput).
    max_pending : int
        Diagnose requests admitted at once (receiving, waiting for a worker or running);
        beyond, ``503`` with ``Retry-After``. Bounds the memory held by request bodies.
    max_history : int
        Largest ``limit`` of the history endpoint.
    """

    max_body_bytes: int = 16 * 2**20
    max_body_decoded_bytes: int = 64 * 2**20
    max_upload_bytes: int = 128 * 2**20
    max_small_body_bytes: int = 64 * 2**10
    max_window_seconds: float = DEFAULT_MAX_WINDOW_SECONDS
    max_upload_samples: int = 1_200_000
    max_upload_decoded_bytes: int = 2**30
    min_sample_rate: float = 1.0
    max_sample_rate: float = 200e3
    workers: int = max(1, (os.cpu_count() or 1) // 2)
    processes: int = 0
    max_pending: int = 16
    max_history: int = 10_000

    def __post_init__(self):
        for name in (
            "max_body_bytes",
            "max_body_decoded_bytes",
            "max_upload_bytes",
            "max_small_body_bytes",
            "max_upload_samples",
            "max_upload_decoded_bytes",
            "workers",
            "max_pending",
            "max_history",
        ):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 1):
                raise PRSMHealthError(f"ServiceLimits.{name} = {value!r} must be an integer >= 1")
        if not (isinstance(self.processes, int) and 0 <= self.processes <= 64):
            raise PRSMHealthError(
                f"ServiceLimits.processes = {self.processes!r} must be an integer in [0, 64]"
            )
        if not (math.isfinite(self.max_window_seconds) and self.max_window_seconds > 0):
            raise PRSMHealthError(
                "ServiceLimits.max_window_seconds must be a finite number > 0 [s]"
            )
        if not (0 < self.min_sample_rate <= self.max_sample_rate < math.inf):
            raise PRSMHealthError(
                "ServiceLimits: need 0 < min_sample_rate <= max_sample_rate < inf [Hz]"
            )

    def check_sample_rate(self, rate: float, what: str = "") -> None:
        """Raise :class:`~prsm_health.core.errors.RecordingError` (a 422 answer) unless ``rate``
        [Hz] lies in ``[min_sample_rate, max_sample_rate]``; ``what`` names the recording."""
        rate = float(rate)
        if not (math.isfinite(rate) and self.min_sample_rate <= rate <= self.max_sample_rate):
            where = f"{what}: " if what else ""
            raise RecordingError(
                f"{where}sample_rate = {rate:g} Hz is outside the accepted range "
                f"[{self.min_sample_rate:g}, {self.max_sample_rate:g}] Hz"
            )

    def max_json_samples(self, rate: float) -> int:
        """Most samples ``POST /v1/diagnose`` accepts at ``rate`` [Hz]."""
        return int(self.max_window_seconds * rate)

    @property
    def max_body_samples(self) -> int:
        """Most samples any ``POST /v1/diagnose`` body may hold (at ``max_sample_rate``):
        the bound a binary body's declared row count is checked against before decoding."""
        return self.max_json_samples(self.max_sample_rate)
