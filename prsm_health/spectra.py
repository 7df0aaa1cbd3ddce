"""Spectral estimates shared by plots, validation and the feature extractor.

Windows and scalings are explicit: Hann windows, amplitude spectra corrected for the window's
coherent gain, Welch PSDs in units²/Hz.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal


@lru_cache(maxsize=64)
def hann(n: int) -> np.ndarray:
    """Periodic Hann window of ``n`` samples (``scipy.signal.windows.hann(n, sym=False)``),
    made once per length: the indicators ask for the same few lengths on every window."""
    window = signal.windows.hann(n, sym=False)
    window.flags.writeable = False
    return window


def bandpass_sos(order: int, low: float, high: float, sample_rate: float) -> np.ndarray:
    """Butterworth band-pass in second-order sections, designed once per band (scipy's design
    costs milliseconds, more than filtering a second of signal); a copy, as scipy's filters
    want a writable array."""
    return _bandpass_sos(order, low, high, sample_rate).copy()


@lru_cache(maxsize=256)
def _bandpass_sos(order: int, low: float, high: float, sample_rate: float) -> np.ndarray:
    return signal.butter(order, (low, high), btype="bandpass", fs=sample_rate, output="sos")


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
    window = hann(len(x))
    spectrum = np.abs(np.fft.rfft(x * window)) * 2.0 / np.sum(window)
    return np.fft.rfftfreq(len(x), 1.0 / sample_rate), spectrum


def welch_psd(
    x: np.ndarray, sample_rate: float, nperseg: int, noverlap: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density, every segment in one FFT call [units²/Hz].

    The estimate of ``scipy.signal.welch(x, fs, window="hann", nperseg, noverlap)`` (periodic
    Hann window, each segment's mean removed, density scaling, one-sided, mean of the segments,
    no padding) computed on a strided view of all segments at once: scipy ≥ 1.12 detrends and
    transforms segment by segment in Python, which made the Welch spectra half the time of
    the indicators (docs/performance.md). ``x`` may hold several signals of equal length on its
    leading axes (channels, windows): they share the call.

    Parameters
    ----------
    x : ndarray (..., n)
    sample_rate : float [Hz]
    nperseg : int
        Segment length [samples], reduced to ``n`` if longer.
    noverlap : int or None
        Overlap [samples]; None: half a segment.

    Returns
    -------
    (frequency [Hz], PSD of shape (..., nperseg // 2 + 1))

    References
    ----------
    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra",
    IEEE Trans. Audio Electroacoust. 15 (1967) 70–73.
    """
    x = np.asarray(x, float)
    nperseg = min(int(nperseg), x.shape[-1])
    noverlap = nperseg // 2 if noverlap is None else int(noverlap)
    frames = np.lib.stride_tricks.sliding_window_view(x, nperseg, axis=-1)
    frames = frames[..., :: nperseg - noverlap, :]
    window = hann(nperseg)
    spectrum = np.fft.rfft((frames - frames.mean(axis=-1, keepdims=True)) * window, axis=-1)
    psd = np.mean(spectrum.real**2 + spectrum.imag**2, axis=-2)
    psd /= sample_rate * np.sum(window**2)
    # one-sided: every bin but DC (and Nyquist for an even length) carries both signs' power
    psd[..., 1 : None if nperseg % 2 else -1] *= 2.0
    return np.fft.rfftfreq(nperseg, 1.0 / sample_rate), psd


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
    f, p = welch_psd(x - x.mean(), sample_rate, nperseg, 3 * nperseg // 4)
    return peak_frequency(f, p, band)


def peak_frequency(f: np.ndarray, p: np.ndarray, band: tuple[float, float]) -> float:
    """Frequency of the largest PSD peak inside ``band`` [Hz], parabolic interpolation of the
    log-PSD around it (:func:`dominant_frequency`)."""
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
    sos = bandpass_sos(4, float(band[0]), float(high), float(sample_rate))
    envelope = np.abs(signal.hilbert(signal.sosfiltfilt(sos, x - np.mean(x))))
    return welch_psd(envelope - envelope.mean(), sample_rate, nperseg)
