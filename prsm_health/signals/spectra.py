"""Spectral estimates shared by plots, validation and the feature extractor.

Windows and scalings are explicit: Hann windows, amplitude spectra corrected for the window's
coherent gain, Welch PSDs in units²/Hz.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal

from .kernels import frame_power_sums, sosfiltfilt_rows


@lru_cache(maxsize=64)
def hann(n: int) -> np.ndarray:
    """Periodic Hann window of ``n`` samples (``scipy.signal.windows.hann(n, sym=False)``),
    made once per length: the indicators ask for the same few lengths on every window."""
    window = signal.windows.hann(n, sym=False)
    window.flags.writeable = False
    return window


@lru_cache(maxsize=256)
def _bandpass_sos(order: int, low: float, high: float, sample_rate: float) -> np.ndarray:
    # designed once per band: scipy's design costs more than filtering a second of signal
    return signal.butter(order, (low, high), btype="bandpass", fs=sample_rate, output="sos")


def amplitude_spectrum(x: np.ndarray, sample_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum of the mean-removed signal, Hann window.

    Scaled so a sinusoid of amplitude A reads A at its bin (coherent gain corrected). ``x`` may
    hold several signals of equal length on its leading axes: they share one FFT call.

    Parameters
    ----------
    x : ndarray (..., n)
    sample_rate : float [Hz]

    Returns
    -------
    (frequency [Hz], amplitude [unit of x] of shape (..., n // 2 + 1))
    """
    x = np.asarray(x, float)
    x = x - np.mean(x, axis=-1, keepdims=True)
    window = hann(x.shape[-1])
    spectrum = np.abs(np.fft.rfft(x * window, axis=-1)) * 2.0 / np.sum(window)
    return np.fft.rfftfreq(x.shape[-1], 1.0 / sample_rate), spectrum


def band_envelope(
    x: np.ndarray, sample_rate: float, bands: list[tuple[float, float]], order: int = 4
) -> np.ndarray:
    """Envelope of each row of ``x`` in its frequency band: the magnitude of the analytic
    signal (Hilbert) of the mean-removed row, band-passed by a zero-phase Butterworth
    (:func:`bandpass_rows`); the envelope is ``abs(scipy.signal.hilbert(row))`` from one real
    FFT pair (:func:`hilbert_envelope`, equal to rounding).

    Parameters
    ----------
    x : ndarray (rows, n)
    sample_rate : float [Hz]
    bands : list of (low, high) [Hz], one per row
    order : int
        Butterworth order of the band-pass.

    Returns
    -------
    ndarray (rows, n)
    """
    return hilbert_envelope(bandpass_rows(x, sample_rate, bands, order))


def bandpass_rows(
    x: np.ndarray, sample_rate: float, bands: list[tuple[float, float]], order: int = 4
) -> np.ndarray:
    """Each row of ``x`` with its mean removed, band-passed in its band by a zero-phase
    Butterworth of ``order``: ``scipy.signal.sosfiltfilt(butter(order, band, "bandpass",
    output="sos"), row)`` (odd extension of 3·(2·sections + 1) samples, steady-state initial
    conditions), equal bitwise, by a compiled kernel
    (:func:`prsm_health.signals.kernels.sosfiltfilt_rows`) with each band's filter and initial
    conditions designed once.

    Parameters
    ----------
    x : ndarray (rows, n)
    sample_rate : float [Hz]
    bands : list of (low, high) [Hz], one per row
    order : int

    Returns
    -------
    ndarray (rows, n)
    """
    x = np.asarray(x, float)
    x = x - np.mean(x, axis=-1, keepdims=True)
    if not len(bands):
        return np.empty_like(x)
    designs = [_bandpass(order, float(lo), float(hi), float(sample_rate)) for lo, hi in bands]
    sos, zi, edge = (np.array([d[k] for d in designs]) for k in range(3))
    if x.shape[-1] <= (padlen := int(edge.max())):
        raise ValueError(
            f"The length of the input vector x must be greater than padlen, which is {padlen}."
        )
    filtered = np.empty_like(x)
    sosfiltfilt_rows(x, sos, zi, edge, filtered)
    return filtered


def hilbert_envelope(x: np.ndarray, spectrum: np.ndarray | None = None) -> np.ndarray:
    """``abs(scipy.signal.hilbert(x, axis=-1))`` with one real FFT pair: the analytic signal
    is x + i·H(x), H(x) the inverse real FFT of −i·X without DC and Nyquist, so the envelope
    is √(x² + H(x)²) — without hilbert's complex inverse FFT, three times a real one.
    ``spectrum``: ``np.fft.rfft(x, axis=-1)`` when the caller has it."""
    n = x.shape[-1]
    quadrature = -1j * (np.fft.rfft(x, axis=-1) if spectrum is None else spectrum)
    quadrature[..., 0] = 0.0
    if n % 2 == 0:
        quadrature[..., -1] = 0.0
    h = np.fft.irfft(quadrature, n, axis=-1)
    # not np.hypot: its overflow-safe scaling costs six times the arithmetic here
    return np.sqrt(x * x + h * h)


@lru_cache(maxsize=256)
def _bandpass(order: int, low: float, high: float, sample_rate: float):
    """(sos, steady-state initial conditions, edge) of ``sosfiltfilt`` for a band, read-only;
    sos and zi padded with identity sections to a multiple of four (the kernel's groups)."""
    sos = _bandpass_sos(order, low, high, sample_rate)
    ntaps = 2 * len(sos) + 1 - min(np.sum(sos[:, 2] == 0), np.sum(sos[:, 5] == 0))
    sections = -(-len(sos) // 4) * 4
    padded = np.zeros((sections, 6))
    padded[:, [0, 3]] = 1.0  # identity: y = x, states stay 0
    padded[: len(sos)] = sos
    zi = np.zeros((sections, 2))
    zi[: len(sos)] = signal.sosfilt_zi(sos)
    padded.flags.writeable = False
    zi.flags.writeable = False
    return padded, zi, 3 * int(ntaps)


def welch_psd(
    x: np.ndarray, sample_rate: float, nperseg: int, noverlap: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density, a signal's segments in one FFT call [units²/Hz].

    The estimate of ``scipy.signal.welch(x, fs, window="hann", nperseg, noverlap)`` (periodic
    Hann window, each segment's mean removed, density scaling, one-sided, mean of the segments,
    no padding): the segments detrended and windowed, and their power summed, by compiled
    loops around one FFT call (:func:`prsm_health.signals.kernels.frame_power_sums`); scipy
    ≥ 1.12 detrends and transforms segment by segment in Python, which made the Welch spectra
    half the time of the indicators (docs/performance.md). ``x`` may hold several signals of
    equal length on its leading axes (channels, windows).

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
    window = hann(nperseg)
    step = nperseg - noverlap
    frames = (x.shape[-1] - nperseg) // step + 1
    rows = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
    psd = np.empty((len(rows), nperseg // 2 + 1))
    # signal by signal: one signal's segments fit the cache, a batch's do not (twice slower)
    for row, out in zip(rows, psd):
        out[:] = frame_power_sums(row, window, step, 0, frames, detrend=True)[0] / frames
    psd /= sample_rate * np.sum(window**2)
    # one-sided: every bin but DC (and Nyquist for an even length) carries both signs' power
    psd[..., 1 : None if nperseg % 2 else -1] *= 2.0
    psd = psd.reshape(x.shape[:-1] + psd.shape[-1:])
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
    high = min(band[1], 0.45 * sample_rate)
    envelope = band_envelope(np.asarray(x, float)[None], sample_rate, [(band[0], high)])[0]
    return welch_psd(envelope - envelope.mean(), sample_rate, nperseg)
