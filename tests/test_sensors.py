"""Sensor model: anti-alias decimation, noise, quantisation."""

import numpy as np
import pytest

from prsm_health.errors import ParameterError
from prsm_health.sensors import SensorModel, decimate, measure

RATE_IN, FACTOR = 200_000.0, 10
RATE_OUT = RATE_IN / FACTOR


def tone(freq, n=40_000):
    t = np.arange(n) / RATE_IN
    return np.sin(2 * np.pi * freq * t)


def test_passband_tone_kept():
    # A tone at 0.4 × the output Nyquist frequency passes with its amplitude (within 1 %:
    # passband ripple of the Kaiser β = 5 FIR), away from the edges.
    y = decimate(tone(0.4 * RATE_OUT / 2), FACTOR)
    assert np.sqrt(2) * np.std(y[200:-200]) == pytest.approx(1.0, rel=1e-2)


def test_alias_suppressed():
    # A tone at 1.6 × the output Nyquist would alias to 0.4 × Nyquist; the anti-alias filter
    # must remove it (residual below 1 %, i.e. better than 40 dB).
    y = decimate(tone(1.6 * RATE_OUT / 2), FACTOR)
    assert np.max(np.abs(y[200:-200])) < 1e-2


def test_ramps_have_no_edge_transient():
    # Angles and positions are ramps; padtype="line" keeps the ends exact (1e-9 of the span).
    ramp = np.linspace(0.0, 10.0, 40_000)
    y = decimate(ramp, FACTOR)
    assert np.max(np.abs(y - ramp[::FACTOR])) < 1e-9 * 10.0


def test_noise_and_quantisation_seeded():
    raw = {
        "nut_axial_accel": np.zeros(40_000),
        "screw_angle": np.linspace(0, 1, 40_000),
        "nut_position": np.linspace(0, 1e-3, 40_000),
    }
    sensors = SensorModel(
        sample_rate=RATE_OUT, accel_noise=0.5, encoder_counts=4096, linear_encoder_resolution=1e-6
    )
    a = measure(raw, RATE_IN, sensors, np.random.default_rng(3))
    b = measure(raw, RATE_IN, sensors, np.random.default_rng(3))
    assert np.array_equal(a["nut_axial_accel"], b["nut_axial_accel"])
    # 4000 samples: the sample std is within ~2 % of 0.5 at 3σ.
    assert np.std(a["nut_axial_accel"]) == pytest.approx(0.5, rel=0.05)
    step = 2 * np.pi / 4096
    assert np.allclose(a["screw_angle"] / step, np.round(a["screw_angle"] / step))
    assert np.allclose(a["nut_position"] / 1e-6, np.round(a["nut_position"] / 1e-6))


def test_accelerometer_bandwidth_attenuates():
    raw = {"nut_axial_accel": tone(4000.0)}
    flat = measure(raw, RATE_IN, SensorModel(sample_rate=RATE_OUT), np.random.default_rng(0))
    limited = measure(
        raw,
        RATE_IN,
        SensorModel(sample_rate=RATE_OUT, accel_bandwidth=1000.0),
        np.random.default_rng(0),
    )
    # 2nd-order Butterworth applied forward and backward: |H|² at 4× the corner = 1/(1 + 4⁴) ≈ 0.004.
    ratio = np.std(limited["nut_axial_accel"][200:-200]) / np.std(flat["nut_axial_accel"][200:-200])
    assert ratio == pytest.approx(1 / (1 + 4**4), rel=0.1)


def test_bad_sensor_settings():
    with pytest.raises(ParameterError, match="sensors.sample_rate"):
        SensorModel(sample_rate=-1.0)
    with pytest.raises(ParameterError, match="sensors.sample_rate"):
        measure(
            {"nut_axial_accel": np.zeros(10)},
            RATE_IN,
            SensorModel(sample_rate=30_000.0),
            np.random.default_rng(0),
        )
