"""The kernel's cheap stand-ins for library functions against the functions they replace."""

import math

import numpy as np

from prsm_health.simulation.dynamics import _kernels
from prsm_health.simulation.dynamics import layout as L


def test_rational_tanh_is_tanh_to_its_stated_error():
    x = np.linspace(-8.0, 8.0, 16001)
    approx = np.array([_kernels._tanh(v) for v in x])
    error = np.abs(approx - np.tanh(x))
    assert error[np.abs(x) <= 3.0].max() <= 1e-6  # the comment's bounds
    assert error.max() <= 1e-4
    assert np.all(np.diff(approx) >= 0.0)  # monotone: a smoothed sign never turns back
    assert all(_kernels._tanh(-v) == -_kernels._tanh(v) for v in x[::97])  # odd
    assert _kernels._tanh(5.0) == 1.0 and _kernels._tanh(-5.0) == -1.0


def test_table_lookup_reads_the_reciprocal_period():
    # A cosine tabulated over a period P, column 0 holding 1/P: value and slope at any u.
    n, period = L.N_ERROR_POINTS, 0.37
    table = np.zeros((1, n + 1))
    table[0, 0] = 1.0 / period
    table[0, 1:] = np.cos(2.0 * math.pi * np.arange(n) / n)
    for u in (-1.234, 0.0, 0.1, 5.55, 123.4):
        value, slope = _kernels._wave(table, 0, u)
        phase = 2.0 * math.pi * u / period
        # linear interpolation on n points: value to (2π/n)²/8, slope to 2π/n of its scale
        assert abs(value - math.cos(phase)) <= (2.0 * math.pi / n) ** 2
        scale = 2.0 * math.pi / period
        assert abs(slope + scale * math.sin(phase)) <= 2.0 * math.pi / n * scale


def test_mesh_lookup_interpolates_periodically_at_any_phase():
    # The kernel wraps the index by a bit mask: right only for a table of a power of two
    # points (layout.MESH_POINTS), at negative and many-cycle phases alike.
    n = L.MESH_POINTS
    table = 1e9 + 1e8 * np.sin(2.0 * math.pi * np.arange(n) / n) ** 3
    grid = np.arange(n + 1) / n
    for phase in (-7.3, -0.001, 0.0, 0.25, 0.9999, 41.5, 12345.678):
        expected = np.interp(phase % 1.0, grid, np.append(table, table[0]))
        assert abs(_kernels._mesh_stiffness(table, phase) - expected) <= 1e-6 * 1e9


def test_knot_segment_is_the_last_knot_not_after_t():
    # Bisection gives the scan's segment, duplicate knot times included.
    times = np.array([0.0, 0.1, 0.1, 0.25, 0.4, 0.4, 0.4, 0.9, 1.0])
    knots = np.vstack([times, np.arange(times.size)])
    for t in np.linspace(0.0, 0.999, 200):
        assert _kernels._segment(knots, t) == np.searchsorted(times, t, side="right") - 1
