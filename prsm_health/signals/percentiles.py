"""Percentiles of a window's samples from one sort: ``np.percentile``'s values, faster.

numpy's percentile selects its order statistics with a partition on several k, which for a
window of 10,000–20,000 samples costs three times its vectorised sort; the lost motion, the
torque rattle and the reversal test each read two percentiles of a window. The sorted array
holds the same order statistics, and numpy's linear-interpolation formulas are applied to
them as numpy applies them, so the values are equal bitwise (tests/signals/test_percentiles.py).
"""

from __future__ import annotations

import numpy as np


def percentiles(x: np.ndarray, q) -> np.ndarray:
    """``np.percentile(x, q)`` (method "linear") of a 1-D array of finite values, for
    percentiles ``q`` in [0, 100], from one ``np.sort``.

    numpy's steps (``numpy.lib._function_base_impl._quantile``): the virtual index
    (n − 1)·q/100, its floor and the next index (both the last one at or beyond it), the weight
    γ = index − floor, then a + (b − a)·γ, or b − (b − a)·(1 − γ) where γ ≥ 0.5.
    """
    ordered = np.sort(np.asarray(x, float))
    n = len(ordered)
    virtual = (n - 1) * np.true_divide(np.asarray(q, float), 100)
    previous = np.floor(virtual)
    following = previous + 1
    last = virtual >= n - 1
    previous[last] = -1
    following[last] = -1
    previous, following = previous.astype(np.intp), following.astype(np.intp)
    gamma = virtual - previous
    a, b = ordered[previous], ordered[following]
    difference = b - a
    return np.where(gamma >= 0.5, b - difference * (1 - gamma), a + difference * gamma)
