"""Envelope analysis and spectral kurtosis against signals with a known answer."""

import math

import numpy as np
import pytest

from prsm_health.core.errors import PRSMHealthError
from prsm_health.signals.envelope_analysis import (
    defect_lines,
    envelope_amplitude_spectrum,
    kurtogram,
    line_and_ratio,
)

RATE = 20_000.0
T = np.arange(int(RATE)) / RATE  # 1 s


def test_am_signal_gives_its_modulation_depth():
    # x = (1 + m cos 2π f_m t) cos 2π f_c t: envelope 1 + m cos 2π f_m t, line m at f_m. The
    # Butterworth passband is flat to < 1 % well inside the band, f_m falls on a bin (1 s, 1 Hz
    # bins) so the Hann scalloping is 0; 2 % covers the filter's edge effects over 1 s.
    m, f_m, f_c = 0.4, 97.0, 5000.0
    x = (1 + m * np.cos(2 * np.pi * f_m * T)) * np.cos(2 * np.pi * f_c * T)
    freq, amp = envelope_amplitude_spectrum(x, RATE, (4000.0, 6000.0))
    line, ratio = line_and_ratio(freq, amp, f_m, 1000.0)
    assert line == pytest.approx(m, rel=0.02)
    assert ratio > 100  # nothing else in the envelope
    lines = defect_lines(x, RATE, {"a": f_m, "b": 2 * f_m, "zero": 0.0}, band=(4000.0, 6000.0))
    assert lines["lines"]["a"]["amplitude"] == pytest.approx(m, rel=0.02)
    assert math.isnan(lines["lines"]["zero"]["ratio"])
    # a line above half the band width is not carried by the envelope: NaN
    narrow = defect_lines(x, RATE, {"a": f_m}, band=(4950.0, 5050.0))
    assert math.isnan(narrow["lines"]["a"]["amplitude"])


def _impacts(rng, rate_hz=97.0, resonance=6000.0, snr=1.0):
    """Decaying resonance bursts at rate_hz in Gaussian noise."""
    x = np.zeros_like(T)
    tail = np.arange(int(0.004 * RATE)) / RATE
    burst = np.exp(-tail / 0.0005) * np.sin(2 * np.pi * resonance * tail)
    for t0 in np.arange(0.001, 1.0 - 0.005, 1 / rate_hz):
        i = int(t0 * RATE)
        x[i : i + len(burst)] += burst
    return snr * x / np.std(x) + rng.standard_normal(len(T))


def test_kurtogram_finds_the_impact_band_and_the_line_stands_out():
    rng = np.random.default_rng(0)
    x = _impacts(rng)
    k = kurtogram(x, RATE, low=1000.0)
    assert k["impulsive"] and k["band"][0] < 6000.0 < k["band"][1]
    result = defect_lines(x, RATE, {"defect": 97.0, "other": 141.3})
    assert result["impulsive"]
    assert result["lines"]["defect"]["ratio"] > 5.0
    # An unrelated frequency: the envelope spectrum of noise has a Rayleigh-like floor; its max
    # over ±2 bins over the median stays below ≈ 3 with high probability.
    assert result["lines"]["other"]["ratio"] < 3.0


def test_gaussian_noise_is_not_impulsive():
    rng = np.random.default_rng(1)
    x = rng.standard_normal(len(T))
    k = kurtogram(x, RATE, low=1000.0)
    # SK of Gaussian noise: ≈ 0 ± 2/√K; the largest bin stays under 5 standard deviations.
    assert not k["impulsive"] and k["sk"] < k["threshold"]
    lines = defect_lines(x, RATE, {"a": 97.0})["lines"]["a"]
    assert lines["ratio"] < 3.0


def test_bad_input():
    with pytest.raises(PRSMHealthError, match="rate"):
        kurtogram(np.ones(1000), 0.0)
    with pytest.raises(PRSMHealthError, match="finite"):
        kurtogram(np.full(1000, np.nan), RATE)
    with pytest.raises(PRSMHealthError, match="band"):
        envelope_amplitude_spectrum(np.ones(1000), RATE, (1000.0, 15000.0))
    with pytest.raises(PRSMHealthError, match="no kurtogram band"):
        kurtogram(np.ones(1000), RATE, low=9500.0)
