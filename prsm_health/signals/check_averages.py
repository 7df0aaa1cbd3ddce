"""The synchronous averages of a health check's high-load stroke, as waveforms: what the
high-load indicators of :mod:`prsm_health.signals.check_indicators` are the SNRs of, for a
reader to see (the CLI's check figure, :mod:`prsm_health.apps.check_plot`).

The same chain as those indicators — their own :func:`~prsm_health.signals.check_indicators.impact_residual`: the nut axial acceleration band-passed to the impact band
(:func:`~prsm_health.signals.check_indicators.impact_band`), the reduction's orders removed on
the screw angle, then averaged over each period of
:data:`~prsm_health.signals.check_indicators.SNR_PERIODS` (a test keeps each average's SNR
equal to the diagnosis's indicator).
"""

from __future__ import annotations

import numpy as np

from prsm_health.core.run import Run

from .angle_domain import SynchronousAverage, prsm_periods, synchronous_average_periods
from .check_indicators import SNR_PERIODS, impact_residual


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
