"""numba kernels of the out-of-distribution guard (:class:`prsm_health.diagnostics.estimators.
DistributionGuard`): the mean distance of each row to its nearest training rows in one pass,
instead of numpy's seven arrays of (rows × training rows × indicators) per chunk of rows; and
each training row's nearest one at another level of an operating factor (the guard's
interpolation).

numpy's arithmetic is kept: float32 differences, their squares summed in float32 one indicator
after the other (the order numpy's broadcast arrays took for the shipped model's guard, whose
scores are equal bitwise: docs/performance.md), the rest in float64. numpy's order depended on
the memory layout its iterator chose for the broadcast arrays, pairwise for some shapes, so
other guards agree with the former code to the rounding of a float32 sum (≈ 1e-7 relative;
tests/diagnostics/test_estimators.py)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def row_distance(z, i, reference, j, penalty2):
    """The distance of row z[i] to row reference[j] (float32, NaN where missing): the RMS over
    the indicators either row has of their differences, √``penalty2`` for one that only one
    row has; float32 squares summed one indicator after the other, the rest in float64."""
    one = 0
    used = 0
    squares = np.float32(0.0)
    for f in range(z.shape[1]):
        a = z[i, f]
        b = reference[j, f]
        a_ok = np.isfinite(a)
        b_ok = np.isfinite(b)
        if a_ok and b_ok:
            d = a - b
            squares += d * d
        if a_ok != b_ok:
            one += 1
        if a_ok or b_ok:
            used += 1
    total = np.float64(squares) + penalty2 * one
    return np.sqrt(total / max(used, 1))


@njit(cache=True)
def nearest_across(z, values, gaps, penalty2, out):
    """out[i, k] = the index of the row of z nearest to z[i] (:func:`row_distance`) among those
    whose factor k (``values[:, k]``) differs from row i's by more than ``gaps[k]`` — the
    nearest window at another level of that operating factor; −1 where there is none. Each
    pair's distance is computed once for all the factors."""
    factors = values.shape[1]
    best = np.empty(factors)
    for i in range(z.shape[0]):
        for k in range(factors):
            best[k] = np.inf
            out[i, k] = -1
        for j in range(z.shape[0]):
            distance = -1.0  # not computed yet
            for k in range(factors):
                if not abs(values[j, k] - values[i, k]) > gaps[k]:  # NaN: never a level apart
                    continue
                if distance < 0.0:
                    distance = row_distance(z, i, z, j, penalty2)
                if distance < best[k]:
                    best[k] = distance
                    out[i, k] = j


@njit(cache=True)
def neighbour_distances(z, reference, penalty2, neighbours, leave_out_offset, out):
    """out[i] = the mean of the ``neighbours`` smallest distances of row z[i] to the rows of
    ``reference`` (float32, NaN where an indicator is missing): the RMS over the indicators
    either row has of their differences, √``penalty2`` for one that only one row has. Row i is
    not its own neighbour when ``leave_out_offset`` ≥ 0 (z[i] is reference[leave_out_offset
    + i]); NaN when fewer than ``neighbours`` distances are numbers."""
    nearest = np.empty(neighbours)
    for i in range(z.shape[0]):
        found = 0  # nearest[:found] ascending
        for j in range(reference.shape[0]):
            distance = row_distance(z, i, reference, j, penalty2)
            if leave_out_offset >= 0 and j == leave_out_offset + i:
                distance = np.inf
            if np.isnan(distance):
                continue  # sorted last: enters the mean only when too few numbers
            if found < neighbours:
                k = found
                found += 1
            elif distance < nearest[neighbours - 1]:
                k = neighbours - 1
            else:
                continue
            while k > 0 and nearest[k - 1] > distance:
                nearest[k] = nearest[k - 1]
                k -= 1
            nearest[k] = distance
        if found == neighbours:
            total = 0.0
            for k in range(neighbours):
                total += nearest[k]
            out[i] = total / neighbours
        else:
            out[i] = np.nan
