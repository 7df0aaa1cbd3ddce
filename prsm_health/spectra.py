"""Spectral estimates shared by plots, validation and (later) the feature extractor.

Windows and scalings are explicit: Hann windows, amplitude spectra corrected for the window's
coherent gain, Welch PSDs in units²/Hz.
"""

from __future__ import annotations

import numpy as np
from scipy import signal


def amplitude_spectrum(x: np.ndarray, sample_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum of the mean-removed signal, Hann window.

    Scaled so a sinusoid of amplitude A reads A at its bin (coherent gain corrected).

    Parameters
    ----------
    x : ndarray
    sample_rate : float [Hz]

    Returns
    -------
    (frequency [Hz], amplitude [unit of x])
    """
    x = np.asarray(x, float) - np.mean(x)
    window = signal.windows.hann(len(x), sym=False)
    spectrum = np.abs(np.fft.rfft(x * window)) * 2.0 / np.sum(window)
    return np.fft.rfftfreq(len(x), 1.0 / sample_rate), spectrum


def dominant_frequency(
    x: np.ndarray,
    sample_rate: float,
    band: tuple[float, float] = (150.0, 1500.0),
    nperseg: int = 512,
) -> float:
    """Frequency of the largest Welch PSD peak inside ``band`` [Hz], with parabolic sub-bin interpolation.

    Welch: Hann window, ``nperseg`` samples, 75 % overlap, density scaling. Interpolating the
    log-PSD of the peak and its two neighbours locates a windowed peak to a fraction of a bin.
    """
    x = np.asarray(x, float)
    nperseg = min(nperseg, len(x))
    f, p = signal.welch(
        x - x.mean(), fs=sample_rate, window="hann", nperseg=nperseg, noverlap=3 * nperseg // 4
    )
    inside = np.flatnonzero((f > band[0]) & (f < band[1]))
    k = inside[np.argmax(p[inside])]
    if 0 < k < len(p) - 1 and np.all(p[k - 1 : k + 2] > 0):
        a, b, c = np.log(p[k - 1 : k + 2])
        denom = a - 2 * b + c
        offset = 0.5 * (a - c) / denom if denom != 0 else 0.0
        return float(f[k] + np.clip(offset, -0.5, 0.5) * (f[1] - f[0]))
    return float(f[k])
