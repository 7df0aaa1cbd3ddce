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


def envelope_spectrum(
    x: np.ndarray,
    sample_rate: float,
    band: tuple[float, float],
    nperseg: int = 8192,
) -> tuple[np.ndarray, np.ndarray]:
    """Welch PSD of the envelope of ``x`` in the frequency ``band`` [Hz] (Randall & Antoni 2011, §3):
    4th-order Butterworth band-pass (zero phase), magnitude of the analytic signal (Hilbert),
    mean removed, Welch with Hann windows of ``nperseg`` samples and 50 % overlap.

    Impacts repeating at a defect frequency excite resonances in the band; their envelope
    carries the repetition rate, so the defect frequency and its harmonics stand out here.

    Returns
    -------
    (frequency [Hz], PSD [unit²/Hz])
    """
    x = np.asarray(x, float)
    high = min(band[1], 0.45 * sample_rate)
    sos = signal.butter(4, (band[0], high), btype="bandpass", fs=sample_rate, output="sos")
    envelope = np.abs(signal.hilbert(signal.sosfiltfilt(sos, x - np.mean(x))))
    nperseg = min(nperseg, len(x))
    return signal.welch(envelope - envelope.mean(), fs=sample_rate, nperseg=nperseg)
