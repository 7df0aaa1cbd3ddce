"""The logger's anti-alias decimation (the sensors themselves: test_instrumentation.py)."""

import numpy as np
import pytest

from prsm_health.simulation.decimation import decimate

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
