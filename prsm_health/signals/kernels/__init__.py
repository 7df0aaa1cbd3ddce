"""Compiled loops of the indicators (numba, :mod:`._kernels`): framing, windowing and power
sums around the FFTs of Welch spectra and kurtograms, the zero-phase Butterworth band-pass,
one-pass moments, linear interpolation of several signals on one angle grid, the line-to-floor
medians of envelope spectra, the normal equations of the lost-motion fit, the screw's power
balance and the torque's hysteresis crossings.

The FFTs stay numpy's; the kernels replace the passes numpy made around them, each over
arrays larger than the cache (a frame matrix, its windowed copy, |X|², |X|⁴, a basis matrix,
…), and scipy's filter loop. Each computes the estimator it replaces (tests/
test_signal_kernels.py): the band-pass, the interpolation, the medians and the crossings
bitwise, the sums to rounding (docs/performance.md, section Diagnosis).
"""

from __future__ import annotations

import numpy as np

from ._kernels import (
    add_power_sums,
    hysteresis_crossings,
    interp_rows,
    line_floors,
    moment_sums,
    screw_power_sums,
    sosfiltfilt_rows,
    step_polynomial_normal_equations,
    subtract_polynomial,
    windowed_frames,
)

__all__ = [
    "frame_power_sums",
    "hysteresis_crossings",
    "interp_rows",
    "line_floors",
    "moment_sums",
    "screw_power_sums",
    "sosfiltfilt_rows",
    "step_polynomial_normal_equations",
    "subtract_polynomial",
]

#: Most samples of frames transformed per FFT call (1 MB, this machine's L2 cache): a second's
#: frames of one signal (≤ 80,000 samples at 75 % overlap) in one call, a longer signal's in
#: blocks, so its frames never fill the memory (measured: 2 % slower at 32,768, 25 % at 8,192).
BLOCK_SAMPLES = 131072


def frame_power_sums(
    x: np.ndarray,
    window: np.ndarray,
    step: int,
    start: int,
    frames: int,
    *,
    detrend: bool,
    fourth: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """(Σ_j |rfft(w · frame_j)|², Σ_j |rfft(w · frame_j)|⁴) over ``frames`` frames of the 1-D
    signal ``x``, frame j its ``len(window)`` samples from ``start + j·step`` (zero outside
    ``x``), its mean removed first when ``detrend``. The fourth powers only when ``fourth``
    (else an empty array)."""
    n_w = len(window)
    if detrend and (start < 0 or start + (frames - 1) * step + n_w > len(x)):
        raise ValueError("detrended frames must lie inside x")
    bins = n_w // 2 + 1
    s2 = np.zeros(bins)
    s4 = np.zeros(bins if fourth else 0)
    block = min(frames, max(1, BLOCK_SAMPLES // n_w))
    buffer = np.empty((block, n_w))
    for j in range(0, frames, block):
        part = buffer[: min(block, frames - j)]
        windowed_frames(x, start + j * step, step, window, detrend, part)
        add_power_sums(np.fft.rfft(part, axis=-1), s2, s4, fourth)
    return s2, s4
