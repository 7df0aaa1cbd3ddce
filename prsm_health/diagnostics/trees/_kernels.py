"""numba kernel of the compiled tree ensembles (:mod:`prsm_health.diagnostics.trees`): every tree of a
boosted model walked for every row in one call, in scikit-learn's order of summation."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def add_tree_values(x, roots, output_of, feature, threshold, missing_left, left, right, leaf,
                    value, raw):  # fmt: skip
    """raw[i, output_of[t]] += value of the leaf row ``i`` reaches in tree ``t``, for the trees
    in order (iteration by iteration, output by output: scikit-learn's order, so the sums are
    the same floating-point sums). A missing value (NaN) follows the node's learnt side; a
    value equal to the threshold goes left (HistGradientBoosting's numerical splits)."""
    for i in range(x.shape[0]):
        for t in range(roots.shape[0]):
            node = roots[t]
            while not leaf[node]:
                v = x[i, feature[node]]
                if math.isnan(v):
                    node = left[node] if missing_left[node] else right[node]
                elif v <= threshold[node]:
                    node = left[node]
                else:
                    node = right[node]
            raw[i, output_of[t]] += value[node]
