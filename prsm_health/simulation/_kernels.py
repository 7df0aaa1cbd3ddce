"""numba kernels of the simulation's signal chain (the dynamics' own: ``dynamics/_kernels.py``).

Float64 arrays and scalars only; the public wrapper, its filter and its contract are in
:mod:`prsm_health.simulation.decimation`.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def fir_decimate_columns(x, taps, factor, out):
    """Every column of ``x`` (n, k), C-contiguous, filtered by the odd-length zero-phase FIR
    ``taps`` and kept at rows 0, factor, 2·factor, … into ``out`` (ceil(n/factor), k).

    Beyond either end a column continues along the line through its first and last samples
    (scipy.signal.upfirdn's ``mode="line"``), so ramps have no edge transient. The innermost
    loop runs along a row's k columns, contiguous in memory: the compiler vectorises it, which a
    filter of one signal at a time (scipy's upfirdn, column by column) cannot.
    """
    n, k = x.shape
    half = (taps.shape[0] - 1) // 2
    slope = (x[n - 1] - x[0]) / max(n - 1, 1)
    acc = x[0] * 0.0
    for j in range(out.shape[0]):
        centre = j * factor
        acc[:] = 0.0
        if centre - half >= 0 and centre + half < n:
            for t in range(taps.shape[0]):
                w = taps[t]
                row = centre + half - t
                for c in range(k):
                    acc[c] += w * x[row, c]
        else:  # a filter reaching past an end: the line's value there
            for t in range(taps.shape[0]):
                w = taps[t]
                row = centre + half - t
                if 0 <= row < n:
                    for c in range(k):
                        acc[c] += w * x[row, c]
                else:
                    for c in range(k):
                        acc[c] += w * (x[0, c] + slope[c] * row)
        out[j, :] = acc
