"""Angle-domain processing against synthetic signals with a known answer: order tracking on an
accelerating shaft, the periodic SNR's expected value, the removal of the reduction's orders,
a burst fixed in stroke position, the PRSM's periods."""

import math

import numpy as np
import pytest
from scipy import signal

from prsm_health.actuator.design import preset
from prsm_health.core.errors import PRSMHealthError
from prsm_health.signals import angle_domain, gear_indicators
from prsm_health.signals.angle_domain import (
    angle_resample,
    evaluate_periodic,
    periodic_snr,
    position_profile,
    prsm_periods,
    subtract_synchronous,
    synchronous_average,
)

RATE = 20_000.0


def _accelerating(duration: float, start: float, end: float) -> np.ndarray:
    """Shaft angle [rad] of a constant acceleration from ``start`` to ``end`` rad/s."""
    t = np.arange(int(duration * RATE)) / RATE
    return start * t + 0.5 * (end - start) / duration * t**2


def test_gear_indicators_names_are_the_angle_domain_functions():
    # one implementation, two public homes
    assert gear_indicators.angle_resample is angle_domain.angle_resample
    assert gear_indicators.time_synchronous_average is angle_domain.time_synchronous_average


def test_plain_resampling_is_linear_interpolation_bitwise():
    # the gear indicators' processing (antialias off, no up-sampling) is np.interp on the grid
    angle = _accelerating(0.2, 50.0, 80.0)
    x = np.sin(3 * angle) + np.cos(50 * angle)
    out, n = angle_resample(x, angle, 2 * np.pi, 256)
    grid = angle[0] + np.arange(n * 256) * (2 * np.pi / 256)
    assert n == int((angle[-1] - angle[0]) // (2 * np.pi))
    assert np.array_equal(out, np.interp(grid, angle, x))


def test_order_tracking_on_an_accelerating_shaft_keeps_the_order_and_stops_aliasing():
    # 40 → 80 rad/s over 1 s: 9 whole turns. 512 grid points per turn (Nyquist order 256) are
    # coarser than the time samples everywhere (1571–3142 per turn), so order 400 — a 2–5 kHz
    # line, well sampled in time — folds onto order 512 − 400 = 112 of a plain
    # interpolation, synchronously: it stays in the average at full amplitude.
    angle = _accelerating(1.0, 40.0, 80.0)
    x = np.sin(20 * angle) + 0.5 * np.sin(400 * angle)
    grid = angle[0] + np.arange(512) * (2 * np.pi / 512)
    wanted = np.sin(20 * grid)
    plain = synchronous_average(x, angle, 2 * np.pi, 512, antialias=False, upsampling=1)
    tracked = synchronous_average(x, angle, 2 * np.pi, 512)
    assert plain.n_periods == tracked.n_periods == 9
    assert np.max(np.abs(plain.average - wanted)) > 0.4  # the folded line
    # The anti-alias FIR passes order 20 (0.08 of Nyquist) within 0.3 % and stops order 400
    # (1.56 Nyquist) below 0.05 %: 4e-3 away from the ends. The FIR's first and last ~10
    # points meet the record's ends (padding), once in 9 turns: 0.02 there.
    error = np.abs(tracked.average - wanted)
    assert np.max(error[10:-10]) < 4e-3 and np.max(error) < 0.02


def test_periodic_snr_expected_value_and_its_bias_correction():
    # Rows s + e_j, e white Gaussian: E[SNR] = (P/σ²)·ν/(ν − 2) + 2(N − 1)/(N n (ν − 2)),
    # ν = N(n − 1) (periodic_snr docstring); the uncorrected ratio is higher by ≈ (N − 1)/(N n).
    # 400 draws: the mean is within 4 standard errors of its expectation.
    rng = np.random.default_rng(7)
    n, size, draws = 20, 64, 400
    theta = 2 * np.pi * np.arange(size) / size
    nu = size * (n - 1)
    for amplitude in (0.0, 1.0):
        power = amplitude**2 / 2
        rows = amplitude * np.sin(3 * theta + 0.2) + rng.standard_normal((draws, n, size))
        snr = periodic_snr(rows)
        raw = periodic_snr(rows, debias=False)
        expected = power * nu / (nu - 2) + 2 * (size - 1) / (size * n * (nu - 2))
        assert snr.shape == (draws,)
        assert abs(np.mean(snr) - expected) < 4 * np.std(snr) / math.sqrt(draws)
        bias = np.mean(raw - snr)
        assert bias == pytest.approx((size - 1) / (size * n), rel=1e-12)
    # degenerate cases
    assert math.isnan(periodic_snr(np.ones((1, 8))))
    assert periodic_snr(np.tile(np.sin(theta), (4, 1))) == math.inf
    assert math.isnan(periodic_snr(np.zeros((4, 8))))


def test_snr_through_order_tracking_on_an_accelerating_shaft():
    # A sine of amplitude 1 at order 7 of the shaft, plus noise of unit variance band-limited
    # to 3 kHz (below the grid's Nyquist even at the slowest speed: 628 orders × 50 rad/s =
    # 5 kHz, and inside the anti-alias passband), 50 → 150 rad/s over 2 s (31 turns): the
    # resampling keeps the noise's variance, periods are independent (correlation ≪ a turn),
    # so E[SNR] = (1/2)/1. Spread of one draw: N_eff ≈ 2·3 kHz·63 ms ≈ 380 independent
    # samples per turn, sd(SNR) ≈ √(4·0.5/(31·380) + 2·0.25/(30·380)) ≈ 0.015: ± 0.06 is 4 sd.
    angle = _accelerating(2.0, 50.0, 150.0)
    sos = signal.butter(8, 3000.0, fs=RATE, output="sos")
    noise = signal.sosfiltfilt(sos, np.random.default_rng(3).standard_normal(len(angle)))
    noise /= np.std(noise)
    found = synchronous_average(np.sin(7 * angle + 0.4) + noise, angle, 2 * np.pi)
    assert found.n_periods == 31
    assert found.snr == pytest.approx(0.5, abs=0.06)
    assert found.residual.shape == found.periods.shape


def test_motor_orders_removed_carrier_period_line_survives():
    # Flight-EMA drive: a ratio-3 reduction, its mesh at 16 per motor turn (48 per screw turn)
    # and a harmonic at 6.9 kHz (order 144 of the motor at 100 rad/s of the screw); a carrier
    # line at order 7 of the carrier (ratio 0.375: 2.625 per screw turn, 0.875 per motor turn,
    # so not a motor order). The record spans 48 motor turns = 6 carrier turns + a little, so
    # the carrier line's residue in the motor average, Σ_j e^{i2π·0.875j}/48, is exactly 0.
    ratio, carrier = 3.0, 0.375
    motor_period = 2 * np.pi / ratio
    t = np.arange(int(1.0055 * RATE)) / RATE
    # 100 rad/s with a slow ±2 % speed ripple and the resolver's quantisation (2π/2¹⁶ of the
    # motor): the measured angle the resampling reads
    angle = 100.0 * t + 0.03 * np.sin(2 * np.pi * 3.0 * t)
    measured = np.round(angle * ratio / (2 * np.pi / 2**16)) * (2 * np.pi / 2**16) / ratio
    motor = 2.0 * np.sin(16 * ratio * angle) + 0.2 * np.sin(144 * ratio * angle + 1.0)
    line = 0.3 * np.sin(7 * carrier * angle + 0.5)
    residual, average = subtract_synchronous(motor + line, measured, motor_period)
    assert average.n_periods == 48
    # what is left of the reduction's lines: 2e-3 of their RMS at 764 Hz, ≤ 3 % at 6.9 kHz
    # (the anti-alias passband edge and the interpolation between up-sampled points); with
    # the line: ≤ 0.01 in all against 1.4 RMS
    assert np.std(residual - line) < 0.01
    # the carrier line is kept whole: its synchronous average is the line, SNR very high
    found = synchronous_average(residual, measured, 2 * np.pi / carrier)
    assert found.n_periods == 6
    grid = found.average.shape[-1]
    theta = measured[0] * carrier + 2 * np.pi * np.arange(grid) / grid
    assert np.max(np.abs(found.average - 0.3 * np.sin(7 * theta + 0.5))) < 0.01
    assert found.snr > 100


def test_subtract_needs_two_periods_and_evaluation_is_periodic():
    angle = np.linspace(0.0, 1.5 * 2 * np.pi, 3000)
    with pytest.raises(PRSMHealthError, match="at least 2"):
        subtract_synchronous(np.sin(angle), angle, 2 * np.pi)
    # One period of cos 3θ in 64 points, evaluated on an increasing and on a decreasing angle
    # (the period runs from the first angle in the direction of travel). Fourier up-sampling
    # to 512 points is exact for order 3; linear interpolation between them errs by at most
    # h²/8·max|f''| = (2π/512)²/8·9 ≈ 1.7e-4.
    size = 64
    wave = np.cos(3 * 2 * np.pi * np.arange(size) / size)
    forward = np.linspace(0.0, 4 * np.pi, 500)
    back = forward[::-1] + 1.0
    tolerance = (2 * np.pi / 512) ** 2 / 8 * 9
    assert np.max(np.abs(evaluate_periodic(wave, forward, 2 * np.pi) - np.cos(3 * forward))) < (
        tolerance
    )
    mirrored = evaluate_periodic(wave, back, 2 * np.pi) - np.cos(3 * (back[0] - back))
    assert np.max(np.abs(mirrored)) < tolerance


def test_position_profile_finds_a_burst_at_its_position():
    # Three strokes over ±40 mm at different speeds; a defect at +12 mm adds bursts while
    # the nut is within ±3 mm of it. 5 mm bins: its bin is 10–15 mm.
    rng = np.random.default_rng(11)
    legs = [np.linspace(-0.04, 0.04, 6000), np.linspace(0.04, -0.04, 3000)]
    position = np.concatenate([*legs, np.linspace(-0.04, 0.04, 9000)])
    noise = rng.standard_normal(len(position))
    near = np.abs(position - 0.012) < 0.003
    burst = np.where(near, 4.0 * np.sin(0.7 * np.arange(len(position))), 0.0)
    found = position_profile(noise + burst, position, 0.005)
    assert found.peak_position == pytest.approx(0.0125, abs=1e-12)
    assert found.contrast > 2.0 and found.snr > 5.0
    # without the defect the level does not depend on position: SNR about 0 — the replicas
    # are independent, the profile's noise is taken out; its sd ≈ √(2/15)/4 ≈ 0.09 for 16
    # bins × 4 replicas: ± 0.4 is > 4 sd
    flat = position_profile(noise, position, 0.005)
    assert abs(flat.snr) < 0.4 and flat.contrast < 1.2
    assert len(flat.centres) == 16 and np.all(flat.counts >= 0.5 * flat.counts.max())
    # mean |x| as the level: the same position
    assert position_profile(noise + burst, position, 0.005, statistic="mean_abs").peak_position == (
        pytest.approx(0.0125, abs=1e-12)
    )
    with pytest.raises(PRSMHealthError, match="bin_width"):
        position_profile(noise, position, 0.0)
    with pytest.raises(PRSMHealthError, match="statistic"):
        position_profile(noise, position, 0.005, statistic="max")
    with pytest.raises(PRSMHealthError, match="splits"):
        position_profile(noise, position, 0.005, splits=1)
    with pytest.raises(PRSMHealthError, match="one length"):
        position_profile(noise[:-1], position, 0.005)


def test_prsm_periods_of_paper01_with_the_flight_ema_reduction():
    # paper 01 §3.1: carrier/screw 0.375; 7 rollers; roller spin relative to the carrier
    # −1.875 of the screw (paper 03 eqs. 26–27 with r_s/r_r = 3)
    periods = prsm_periods(preset("paper01"), 3.0)
    assert list(periods) == list(angle_domain.PERIODS)
    assert periods["carrier"] == pytest.approx(2 * np.pi / 0.375, rel=1e-12)
    assert periods["nut_pass"] == pytest.approx(2 * np.pi / 0.375 / 7, rel=1e-12)
    assert periods["roller_spin"] == pytest.approx(2 * np.pi / 1.875, rel=1e-12)
    assert periods["screw"] == 2 * np.pi and periods["motor"] == pytest.approx(2 * np.pi / 3)
    # 8 motor turns per carrier turn: why the reduction's orders are removed first
    assert periods["carrier"] / periods["motor"] == pytest.approx(8.0, rel=1e-12)
    assert prsm_periods(preset("paper01"))["motor"] == 2 * np.pi
    with pytest.raises(PRSMHealthError, match="gear_ratio"):
        prsm_periods(preset("paper01"), -1.0)


def test_bad_resampling_arguments():
    angle = np.linspace(0.0, 4 * np.pi, 1000)
    with pytest.raises(PRSMHealthError, match="upsampling"):
        angle_resample(np.sin(angle), angle, 2 * np.pi, 64, upsampling=0)
    with pytest.raises(PRSMHealthError, match="monotonic"):
        synchronous_average(np.sin(angle), np.sin(angle), 2 * np.pi)
    short = synchronous_average(np.sin(angle[:100]), angle[:100], 2 * np.pi, 64)
    assert short.n_periods == 0 and np.all(np.isnan(short.average)) and math.isnan(short.snr)
