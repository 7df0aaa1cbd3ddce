"""Gear condition indicators against signals built to give a known textbook value."""

import math

import numpy as np
import pytest

from prsm_health.core.errors import PRSMHealthError
from prsm_health.signals.gear_indicators import (
    GEAR_INDICATORS,
    angle_resample,
    ensemble_ratio,
    fm0,
    fm4,
    gear_indicators,
    m6a,
    m8a,
    sideband_amplitudes,
    split_signals,
    sum_of_squares,
    time_synchronous_average,
)

N = 1024


def _period_signal(*components):
    """One period of N samples: sum of (order, amplitude, phase) cosines."""
    theta = 2 * np.pi * np.arange(N) / N
    return sum(a * np.cos(k * theta + p) for k, a, p in components)


def test_moment_ratios_of_a_sinusoid_and_an_impulse():
    sine = np.sin(2 * np.pi * 5 * np.arange(N) / N)
    # mean sin⁴ / (mean sin²)² = (3/8)/(1/4) = 1.5; sin⁶: (5/16)/(1/8) = 2.5; sin⁸: (35/128)/(1/16)
    assert fm4(sine) == pytest.approx(1.5, rel=1e-12)
    assert m6a(sine) == pytest.approx(2.5, rel=1e-12)
    assert m8a(sine) == pytest.approx(35 / 8, rel=1e-12)
    # one impulse in N samples: FM4 = N (about, the mean removed: (N−1)² + … exact below)
    impulse = np.zeros(N)
    impulse[7] = 1.0
    d = impulse - impulse.mean()
    exact = N * np.sum(d**4) / np.sum(d**2) ** 2
    assert fm4(impulse) == pytest.approx(exact, rel=1e-12) and fm4(impulse) > 0.99 * N
    assert math.isnan(fm4(np.zeros(N)))


def test_fm4_of_gaussian_noise_is_three():
    # Sample kurtosis of N Gaussian samples: 3 with standard error √(24/N) ≈ 0.034 for 20 480
    # samples; 5 standard errors.
    x = np.random.default_rng(0).standard_normal(20 * N)
    assert fm4(x) == pytest.approx(3.0, abs=5 * math.sqrt(24 / len(x)))


def test_fm0_of_a_mesh_tone_and_its_harmonics():
    # One mesh tone of amplitude A: PP = 2A, Σ harmonics = A → FM0 = 2.
    tsa = _period_signal((20, 0.7, 0.0))
    assert fm0(tsa, 20) == pytest.approx(2.0, rel=1e-9)
    # cos 20θ + 0.5 cos 40θ = c² + c − 0.5 with c = cos 20θ: max 1.5 (c = 1), min −0.75
    # (c = −0.5); PP = 2.25 over Σ = 1.5 → FM0 = 1.5. The minimum falls between samples (51
    # per mesh cycle): PP is short by ≲ (π/51)²·0.75 ≈ 3e-3 relative at worst; 1e-4 here.
    two = _period_signal((20, 1.0, 0.0), (40, 0.5, 0.0))
    assert fm0(two, 20) == pytest.approx(1.5, rel=1e-4)
    # A sharp local fault raises PP, not the mesh lines: FM0 grows.
    faulty = _period_signal((20, 1.0, 0.0))
    faulty[100] += 3.0
    assert fm0(faulty, 20) > 3.0


def test_signals_split_and_energy_ratio():
    shaft = (1, 0.3, 0.2)
    mesh = (20, 1.0, 0.0)
    sidebands = [(19, 0.2, 0.1), (21, 0.15, -0.3)]
    other = (7, 0.05, 0.4)  # neither shaft, mesh nor sideband: a fault's order
    tsa = _period_signal(shaft, mesh, *sidebands, other)
    parts = split_signals(tsa, 20)
    assert np.allclose(parts["difference"], _period_signal(other), atol=1e-12)
    assert np.allclose(parts["residual"], _period_signal(*sidebands, other), atol=1e-12)
    assert np.allclose(parts["regular"], _period_signal(shaft, mesh, *sidebands), atol=1e-12)
    # ER = RMS(d)/RMS(regular) = (0.05/√2)/√((0.3² + 1 + 0.2² + 0.15²)/2)
    out = gear_indicators(np.tile(tsa, 4), np.arange(4 * N) * 2 * np.pi / N, 2 * np.pi, 20)
    expected = 0.05 / math.sqrt(0.3**2 + 1.0 + 0.2**2 + 0.15**2)
    assert out["energy_ratio"] == pytest.approx(expected, rel=1e-6)


def test_sideband_index_and_level_factor():
    tsa = _period_signal((20, 1.0, 0.0), (19, 0.2, 0.0), (21, 0.1, 0.0))
    assert sideband_amplitudes(tsa, 20) == pytest.approx((0.2, 0.1), rel=1e-9)
    out = gear_indicators(np.tile(tsa, 3), np.arange(3 * N) * 2 * np.pi / N, 2 * np.pi, 20)
    assert out["sideband_index"] == pytest.approx(0.15, rel=1e-6)
    sigma = math.sqrt((1.0 + 0.04 + 0.01) / 2)
    assert out["sideband_level_factor"] == pytest.approx(0.3 / sigma, rel=1e-6)


def test_na4_nb4_run_ensemble():
    rng = np.random.default_rng(1)
    healthy = _period_signal((20, 1.0, 0.0)) + 0.05 * rng.standard_normal(N)
    # M = 1: NA4 is the residual's kurtosis (the record's own variance)
    r = split_signals(healthy, 20)["residual"]
    assert ensemble_ratio(r) == pytest.approx(fm4(r), rel=1e-12)
    # A baseline of the same variance leaves it; damage growing over the run raises NA4 above
    # FM4-like normalisation by its own variance: residual energy × 4 against a baseline of 1 →
    # NA4 = kurtosis × 16 / ((16 + 1)/2)²·… computed exactly:
    earlier = [sum_of_squares(r)]
    grown = 2.0 * r
    expected = (
        N * np.sum((grown - grown.mean()) ** 4) / np.mean([sum_of_squares(grown), *earlier]) ** 2
    )
    assert ensemble_ratio(grown, earlier) == pytest.approx(expected, rel=1e-12)
    assert ensemble_ratio(grown, earlier) > ensemble_ratio(grown)
    # NB4: a local burst of mesh amplitude (amplitude modulation) makes the envelope peaky
    theta = 2 * np.pi * np.arange(N) / N
    burst = 1.0 + 4.0 * np.exp(-(((theta - 2.0) / 0.05) ** 2))
    modulated = burst * np.cos(20 * theta)
    steady = np.cos(20 * theta) + 0.01 * rng.standard_normal(N)
    angle = np.arange(3 * N) * 2 * np.pi / N
    # The envelope of a steady tone in noise fluctuates like the noise (kurtosis ≈ 3); a burst
    # of width 0.05 rad in 2π is a spike in the envelope: kurtosis of order 2π/0.05/√(2π)… ≫ 3.
    peaky = gear_indicators(np.tile(modulated, 3), angle, 2 * np.pi, 20)["nb4"]
    flat = gear_indicators(np.tile(steady, 3), angle, 2 * np.pi, 20)["nb4"]
    assert peaky > 10.0 and flat < 4.0


def test_tsa_with_a_non_integer_period_and_either_direction():
    # Carrier of paper 01: 0.375 of the screw; its period is 2π/0.375 screw radians (16.76 rad,
    # not a whole number of screw turns). Sampled in time at 20 kHz, the screw at 100 rad/s.
    rate, omega, ratio = 20_000.0, 100.0, 0.375
    t = np.arange(int(2.0 * rate)) / rate
    screw = omega * t + 0.3
    carrier = ratio * screw
    synchronous = np.cos(12 * carrier) + 0.5 * np.cos(3 * carrier + 1.0)
    asynchronous = np.cos(2 * np.pi * 57.3 * t)  # not locked to the carrier
    period = 2 * np.pi / ratio
    tsa, periods = time_synchronous_average(synchronous + asynchronous, screw, period, N)
    theta = 2 * np.pi * np.arange(N) / N + 0.3 * ratio  # the grid starts at the first angle
    expected = np.cos(12 * theta) + 0.5 * np.cos(3 * theta + 1.0)
    n = len(periods)
    assert n == int((screw[-1] - screw[0]) // period)
    # The synchronous part is kept (linear interpolation error < 1e-3 at ≥ 300 samples/cycle);
    # the asynchronous tone averages down: its residue is bounded by 1/n for a tone whose
    # phase advances evenly per period (a geometric sum), well below 1/√n.
    assert np.max(np.abs(tsa - expected)) < 2.0 / n + 1e-3
    # Reversed rotation: the same averaged waveform, mirrored angle
    tsa_back, _ = time_synchronous_average(synchronous[::-1], screw[::-1], period, N)
    assert np.max(np.abs(tsa_back - tsa_back.mean())) > 0.5


def test_short_or_stopped_windows_give_nan_and_bad_input_errors():
    angle = np.linspace(0.0, 1.5 * 2 * np.pi, 3000)
    x = np.cos(20 * angle)
    out = gear_indicators(x, angle, 2 * np.pi, 20)  # 1 period < MIN_PERIODS
    assert list(out) == list(GEAR_INDICATORS) and math.isnan(out["fm4"]) and out["periods"] == 1
    stopped = np.concatenate([angle, np.full(100, angle[-1])])
    assert math.isnan(gear_indicators(np.append(x, np.zeros(100)), stopped, 2 * np.pi, 20)["fm4"])
    with pytest.raises(PRSMHealthError, match="one length"):
        angle_resample(x, angle[:-1], 2 * np.pi, N)
    with pytest.raises(PRSMHealthError, match="period"):
        angle_resample(x, angle, -1.0, N)
    with pytest.raises(PRSMHealthError, match="samples_per_period"):
        angle_resample(x, angle, 2 * np.pi, 4)
    with pytest.raises(PRSMHealthError, match="finite"):
        gear_indicators(np.full_like(x, np.nan), angle, 2 * np.pi, 20)
