"""The batched indicators (several windows and channels per FFT call) equal the one-window path."""

import math

import numpy as np
import pytest
from scipy import signal

from prsm_health.signals.envelope_analysis import defect_lines, defect_lines_batch
from prsm_health.signals.features import extract_features, extract_features_batch, windows
from prsm_health.signals.gear_indicators import (
    gear_indicators,
    synchronous_averages,
    tsa_indicators,
)
from prsm_health.signals.spectra import _bandpass_sos, amplitude_spectrum, band_envelope

RATE = 20_000.0


def same(a: dict, b: dict) -> bool:
    """Equal indicator dicts, NaN equal to NaN. Bitwise equal here today; the tolerance is for
    FFT libraries that transform a batch of rows with other SIMD paths than one row (numpy's
    pocketfft may), which changes the last bits only."""
    return list(a) == list(b) and all(
        (math.isnan(a[k]) and math.isnan(b[k])) or math.isclose(a[k], b[k], rel_tol=1e-12)
        for k in a
    )


def test_batch_equals_window_by_window(reversing_run):
    run = reversing_run(20e-6, duration=0.4)
    parts = list(windows(run, 0.1))
    # a shorter last window and a window without the load cell: their own groups
    parts.append(run.slice(0, 1500))
    stripped = run.slice(0, 2000)
    stripped.channels.pop("axial_load", None)
    parts.append(stripped)
    batched = extract_features_batch(parts)
    assert len(batched) == len(parts)
    for part, row in zip(parts, batched):
        assert same(row, extract_features(part))


def test_defect_lines_batch_equals_one_row_at_a_time():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((3, 20_000))
    x[1, ::97] += 8.0  # impacts: an impulsive band
    frequencies = [{"a": 97.0, "b": 141.3}, {"a": 206.2, "zero": 0.0}, {"c": 55.5}]
    for row, freq, result in zip(x, frequencies, defect_lines_batch(x, RATE, frequencies)):
        np.testing.assert_equal(result, defect_lines(row, RATE, freq))
    bands = [(2000.0, 4000.0), (3000.0, 6000.0), (2000.0, 4000.0)]
    results = defect_lines_batch(x, RATE, frequencies, bands)
    for row, freq, band, result in zip(x, frequencies, bands, results):
        np.testing.assert_equal(result, defect_lines(row, RATE, freq, band=band))


def test_tsa_indicators_of_rows_equal_gear_indicators():
    rng = np.random.default_rng(4)
    angle = np.linspace(0.0, 12 * np.pi, 12_000)
    x = np.sin(20 * angle) * (1 + 0.3 * np.cos(angle)) + 0.1 * rng.standard_normal((2, 12_000))
    [(tsa, n_periods)] = synchronous_averages(x, angle, [2 * np.pi])
    rows = tsa_indicators(tsa, n_periods, 20)
    for k in range(2):
        one = gear_indicators(x[k], angle, 2 * np.pi, 20)
        assert same({name: float(v[k]) for name, v in rows.items()}, one)


def test_band_envelope_is_scipys_filtfilt_and_hilbert():
    x = np.random.default_rng(5).standard_normal((3, 5_000)) + 2.0
    bands = [(2000.0, 4000.0), (500.0, 900.0), (2000.0, 4000.0)]
    envelope = band_envelope(x, RATE, bands)
    for row, band, got in zip(x, bands, envelope):
        sos = _bandpass_sos(4, *band, RATE)
        expected = np.abs(signal.hilbert(signal.sosfiltfilt(sos, row - row.mean())))
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * expected.max())


def test_amplitude_spectrum_batches_leading_axes():
    x = np.random.default_rng(6).standard_normal((2, 3, 1000))
    _, batched = amplitude_spectrum(x, RATE)
    for i in range(2):
        for j in range(3):
            # rows of one FFT call vs one at a time: equal up to the FFT's rounding
            np.testing.assert_allclose(
                batched[i, j], amplitude_spectrum(x[i, j], RATE)[1], rtol=1e-12, atol=1e-15
            )


@pytest.mark.parametrize("n", [20_000, 777])
def test_batched_amplitude_spectrum_keeps_its_frequencies(n):
    f, a = amplitude_spectrum(np.ones((2, n)), RATE)
    np.testing.assert_array_equal(f, np.fft.rfftfreq(n, 1 / RATE))
    assert a.shape == (2, len(f))
