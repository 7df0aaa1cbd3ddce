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


@pytest.mark.parametrize("n", [2, 7, 300, 5_003])
def test_columns_together_equal_scipy_one_at_a_time(n):
    # The numba kernel (all columns of a record at once) is resample_poly's filter and edges:
    # equal to round-off (1e-12 of the signal: a 201-tap sum in another order), also for
    # records shorter than the filter, where both ends use the line through the end samples.
    from scipy import signal

    from prsm_health.simulation import _kernels
    from prsm_health.simulation.decimation import _taps

    rng = np.random.default_rng(n)
    x = np.cumsum(rng.standard_normal((n, 5)), axis=0) + np.linspace(0.0, 50.0, n)[:, None]
    expected = signal.resample_poly(x, 1, FACTOR, axis=0, window=("kaiser", 5.0), padtype="line")
    scale = np.max(np.abs(expected))
    assert np.max(np.abs(decimate(x, FACTOR) - expected)) < 1e-12 * scale
    # the kernel's Python source (NUMBA_DISABLE_JIT's path), on the short ones
    if n <= 300:
        out = np.empty_like(expected)
        kernel = _kernels.fir_decimate_columns
        getattr(kernel, "py_func", kernel)(x, _taps(FACTOR), FACTOR, out)
        assert np.max(np.abs(out - expected)) < 1e-12 * scale
