"""The compiled loops of prsm_health.signals.kernels compute what the numpy/scipy code they
replace computed: bitwise where the operations are the same, to rounding where a sum's order
changed."""

import numpy as np
import pytest
from scipy import signal

from prsm_health.signals.envelope_analysis import (
    KURTOGRAM_WINDOWS,
    lines_and_ratios,
    spectral_kurtosis,
)
from prsm_health.signals.kernels import (
    frame_power_sums,
    hysteresis_crossings,
    interp_rows,
    moment_sums,
    screw_power_sums,
    sosfiltfilt_rows,
    step_polynomial_normal_equations,
    subtract_polynomial,
)
from prsm_health.signals.spectra import _bandpass, _bandpass_sos, hann, hilbert_envelope

RATE = 20_000.0
rng = np.random.default_rng(11)


@pytest.mark.parametrize("order", [2, 4, 6])
def test_sosfiltfilt_rows_is_scipys(order):
    x = rng.standard_normal((3, 3_000))
    bands = [(1000.0, 3000.0), (200.0, 400.0), (5000.0, 8000.0)]
    designs = [_bandpass(order, lo, hi, RATE) for lo, hi in bands]
    out = np.empty_like(x)
    sosfiltfilt_rows(x, *(np.array([d[k] for d in designs]) for k in range(3)), out)
    for row, band, got in zip(x, bands, out):
        # bitwise equal to scipy today (same operations in the same order); a tolerance, so a
        # scipy release that reorders its arithmetic does not fail a correct kernel
        expected = signal.sosfiltfilt(_bandpass_sos(order, *band, RATE), row)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-14 * np.abs(expected).max())


@pytest.mark.parametrize("n", [4_000, 4_001])
def test_hilbert_envelope_is_abs_of_scipys_analytic_signal(n):
    x = rng.standard_normal((2, n))
    expected = np.abs(signal.hilbert(x))
    np.testing.assert_allclose(hilbert_envelope(x), expected, rtol=1e-12, atol=1e-13)
    spectrum = np.fft.rfft(x, axis=-1)
    np.testing.assert_allclose(hilbert_envelope(x, spectrum), expected, rtol=1e-12, atol=1e-13)


def test_frame_power_sums_of_zero_padded_frames_equal_numpy():
    x = rng.standard_normal(1_000)
    n_w, step, frames = 64, 16, 66
    padded = np.concatenate([np.zeros(32), x, np.zeros(64)])
    z = np.fft.rfft(
        np.lib.stride_tricks.sliding_window_view(padded, n_w)[::step][:frames] * hann(n_w),
        axis=-1,
    )
    power = z.real**2 + z.imag**2
    s2, s4 = frame_power_sums(x, hann(n_w), step, -32, frames, detrend=False, fourth=True)
    np.testing.assert_allclose(s2, power.sum(axis=0), rtol=1e-13)
    np.testing.assert_allclose(s4, (power**2).sum(axis=0), rtol=1e-13)
    assert frame_power_sums(x, hann(n_w), step, 0, 3, detrend=False)[1].size == 0


def test_detrended_frames_must_lie_inside_the_signal():
    with pytest.raises(ValueError, match="inside"):
        frame_power_sums(np.ones(100), hann(64), 16, 0, 4, detrend=True)


def test_spectral_kurtosis_is_that_of_scipys_stft():
    x = rng.standard_normal((2, 5_000))
    x[1, ::101] += 6.0
    levels = spectral_kurtosis(x, RATE)
    assert set(levels) == set(KURTOGRAM_WINDOWS)
    for n_w, (f, sk, frames) in levels.items():
        freq, _, z = signal.stft(
            x - x.mean(axis=-1, keepdims=True), RATE, "hann", n_w, 3 * n_w // 4, axis=-1
        )
        power = np.abs(z) ** 2  # (rows, bins, frames)
        expected = (power**2).mean(axis=-1) / power.mean(axis=-1) ** 2 - 2.0
        assert frames == power.shape[-1]
        np.testing.assert_allclose(f, freq)
        np.testing.assert_allclose(sk, expected, rtol=1e-10, atol=1e-12)


def test_moment_sums():
    x = rng.standard_normal((3, 1_001))
    out = np.empty((3, 5))
    moment_sums(x, out)
    expected = np.stack(
        [np.sum(x**2, -1), np.sum(x**3, -1), np.sum(x**4, -1), x.max(-1), x.min(-1)], axis=-1
    )
    np.testing.assert_allclose(out, expected, rtol=1e-12, atol=1e-12)


def test_interp_rows_is_numpys():
    xp = np.cumsum(rng.random(500) + 0.01)
    fp = rng.standard_normal((2, 500))
    x = np.sort(np.concatenate([np.linspace(xp[0] - 1, xp[-1] + 1, 800), xp[10:20], xp[-1:]]))
    out = np.empty((2, len(x)))
    interp_rows(x, xp, fp, out)
    # bitwise equal to numpy today; a tolerance for a numpy release with another formula
    np.testing.assert_allclose(out, [np.interp(x, xp, row) for row in fp], rtol=1e-14, atol=1e-15)


def test_hysteresis_crossings():
    x = np.array([0.0, 2.0, 0.5, -2.0, 0.1, -3.0, 5.0, 0.0, 0.0, -1.5])
    # the state after each sample that leaves the band [-1, 1]: +, −, −, +, − → 3 changes
    state = np.where(x > 1, 1, np.where(x < -1, -1, 0))
    state = state[state != 0]
    assert hysteresis_crossings(x, -1.0, 1.0) == np.count_nonzero(np.diff(state)) == 3


def test_screw_power_sums_use_numpys_gradient():
    n = 2_000
    time = np.cumsum(5e-5 * (1 + 0.01 * rng.random(n)))
    torque, speed, load, position = rng.standard_normal((4, n))
    through, loss = screw_power_sums(torque, speed, load, position, time)
    p_out = load * np.gradient(position, time)
    np.testing.assert_allclose(through, np.sum(np.abs(p_out)), rtol=1e-12)
    np.testing.assert_allclose(loss, np.sum(torque * speed - p_out), rtol=1e-10)


def test_step_polynomial_fit_equals_the_chebyshev_basis_solution():
    n = 3_000
    position = np.cumsum(rng.standard_normal(n))
    side = np.sign(rng.standard_normal(n))
    residual = 1e-3 * position**2 + 0.2 * side + rng.standard_normal(n)
    lo, hi = position.min(), position.max()
    basis = np.polynomial.chebyshev.chebvander((2 * position - lo - hi) / (hi - lo), 7)
    design = np.column_stack([basis, side])
    gram, rhs = np.empty((9, 9)), np.empty(9)
    step_polynomial_normal_equations(position, side, residual, lo, hi, 7, gram, rhs)
    np.testing.assert_allclose(gram, design.T @ design, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(rhs, design.T @ residual, rtol=1e-12, atol=1e-9)
    coef = np.linalg.solve(gram, rhs)
    out = np.empty(n)
    subtract_polynomial(position, residual, lo, hi, coef[:8], out)
    np.testing.assert_allclose(out, residual - basis @ coef[:8], rtol=1e-12, atol=1e-12)


def test_lines_and_ratios_median_floor():
    freq = np.arange(0.0, 200.0)
    amp = np.abs(rng.standard_normal((2, 200))) + 0.1
    amp[0, 100] = 9.0
    targets = np.array([[100.0, 40.0, np.nan], [60.0, 250.0, 0.0]])
    lines, ratios = lines_and_ratios(freq, amp, targets, np.array([180.0, 180.0]))
    # target 100 Hz: the line ±2 bins, the floor the median of 50…150 Hz without those bins
    floor = np.median(np.concatenate([amp[0, 50:98], amp[0, 103:151]]))
    assert lines[0, 0] == 9.0 and ratios[0, 0] == 9.0 / floor
    floor = np.median(np.concatenate([amp[1, 30:58], amp[1, 63:91]]))
    assert lines[1, 0] == amp[1, 58:63].max() and ratios[1, 0] == lines[1, 0] / floor
    assert np.isnan(lines[0, 2]) and np.isnan(lines[1, 1]) and np.isnan(ratios[1, 2])
