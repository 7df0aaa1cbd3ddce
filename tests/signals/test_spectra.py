"""The shared spectral estimates against scipy's reference implementations."""

import numpy as np
import pytest
from scipy import signal

from prsm_health.signals.spectra import dominant_frequency, welch_psd


@pytest.mark.parametrize(
    ("n", "nperseg", "noverlap"),
    [(20000, 1024, 768), (20000, 512, 384), (1000, 8192, None), (777, 64, None), (20001, 513, 100)],
)
def test_welch_psd_is_scipys_welch(n, nperseg, noverlap):
    # the same estimator (Hann, constant detrend, density, one-sided, mean): equal to rounding
    x = np.random.default_rng(n).standard_normal(n) + 3.0
    f_ref, p_ref = signal.welch(
        x, fs=2e4, window="hann", nperseg=min(nperseg, n), noverlap=noverlap
    )
    f, p = welch_psd(x, 2e4, nperseg, noverlap)
    np.testing.assert_array_equal(f, f_ref)
    np.testing.assert_allclose(p, p_ref, rtol=1e-10, atol=1e-14 * p_ref.max())


def test_welch_psd_batches_leading_axes():
    x = np.random.default_rng(1).standard_normal((3, 2, 4096))
    _, batched = welch_psd(x, 1e4, 256, 192)
    for i in range(3):
        for j in range(2):
            np.testing.assert_allclose(batched[i, j], welch_psd(x[i, j], 1e4, 256, 192)[1])


def test_dominant_frequency_finds_a_tone_between_bins():
    rate = 20000.0
    t = np.arange(20000) / rate
    x = np.sin(2 * np.pi * 437.3 * t) + 0.01 * np.random.default_rng(2).standard_normal(len(t))
    # 512-sample segments: 39 Hz bins; parabolic interpolation of the log-PSD lands within a
    # tenth of a bin of a Hann-windowed tone
    assert dominant_frequency(x, rate) == pytest.approx(437.3, abs=4.0)
