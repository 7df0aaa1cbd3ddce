"""The synchronous averages of a health check's high-load stroke, as waveforms: what the
high-load indicators of :mod:`prsm_health.signals.check_indicators` are the SNRs of, for a
reader to see (the CLI's check figure, :mod:`prsm_health.apps.check_plot`).

The same chain as those indicators: the nut axial acceleration band-passed to the impact band
(:func:`~prsm_health.signals.check_indicators.impact_band`), the reduction's orders removed on
the screw angle, then averaged over each period of
:data:`~prsm_health.signals.check_indicators.SNR_PERIODS` (a test keeps each average's SNR
equal to the diagnosis's indicator).
"""

from __future__ import annotations

import numpy as np

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run

from .angle_domain import (
    SynchronousAverage,
    prsm_periods,
    subtract_synchronous,
    synchronous_average_periods,
)
from .check_indicators import IMPACT_BAND, SNR_PERIODS, impact_band
from .spectra import bandpass_rows


def impact_residual(phase: Run, design, gear_ratio: float) -> np.ndarray:
    """The phase's nut axial acceleration in the impact band, the motor's orders removed
    (``gear_ratio`` > 1) [m/s²].

    Raises
    ------
    PRSMHealthError
        The sampling rate leaves no impact band; the angle stops or turns back.
    """
    band = impact_band(phase.sample_rate)
    if band is None:
        raise PRSMHealthError(
            f"sample rate {phase.sample_rate:g} Hz too low for the {IMPACT_BAND} Hz band"
        )
    x = np.asarray(phase.channels["nut_axial_accel"], float)
    angle = np.asarray(phase.channels["screw_angle"], float)
    # band first, then the reduction's orders (check_indicators: less leakage of the mesh line)
    y = bandpass_rows(x[None], phase.sample_rate, [band])[0]
    if gear_ratio > 1:
        y, _ = subtract_synchronous(y, angle, prsm_periods(design, gear_ratio)["motor"])
    return y


def high_load_averages(phase: Run, design, gear_ratio: float) -> dict[str, SynchronousAverage]:
    """Period name (:data:`SNR_PERIODS`) → synchronous average of :func:`impact_residual`
    over it (``n_periods`` 0 and a NaN average when the phase spans less than one).

    Raises
    ------
    PRSMHealthError
        As :func:`impact_residual`.
    """
    y = impact_residual(phase, design, gear_ratio)
    periods = prsm_periods(design, gear_ratio)
    angle = np.asarray(phase.channels["screw_angle"], float)
    return synchronous_average_periods(y, angle, {k: periods[k] for k in SNR_PERIODS})
