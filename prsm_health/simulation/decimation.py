"""The data logger's anti-alias decimation from the integration rate to the sample rate.

The simulator records its truth signals at the integration rate f_int = m·f_s (m integer);
:func:`decimate` turns a signal into what a logger stores at the sample rate f_s: a polyphase
FIR with scipy.signal.resample_poly's design (Kaiser window β = 5, 20·m + 1 taps, cut-off at the
new Nyquist) and its ``padtype="line"`` edges, so ramps such as angles and positions have no
edge transients. The sensors themselves — their errors, bandwidths, noise — are in
:mod:`prsm_health.simulation.sensors`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal

from ._kernels import fir_decimate_columns

#: Columns from which a 2-D signal is filtered by the numba kernel, all columns at once (its
#: inner loop vectorised along a row): 16 truth signals of a one-second run in 20 ms instead of
#: scipy's 80 ms one at a time; a single signal stays with scipy (4 ms against the kernel's 14).
COLUMNS_TOGETHER = 4


@lru_cache(maxsize=16)
def _taps(factor: int) -> np.ndarray:
    # resample_poly's own design for up = 1, down = factor
    half = 10 * factor
    taps = signal.firwin(2 * half + 1, 1.0 / factor, window=("kaiser", 5.0))
    taps.flags.writeable = False  # shared by every call
    return taps


def decimate(values: np.ndarray, factor: int) -> np.ndarray:
    """Anti-aliased decimation by an integer factor along axis 0 (polyphase FIR).

    Parameters
    ----------
    values : ndarray, shape (n, …)
    factor : int

    Returns
    -------
    ndarray, shape (ceil(n / factor), …)
        Equal to ``scipy.signal.resample_poly(values, 1, factor, axis=0, window=("kaiser", 5),
        padtype="line")`` to round-off.
    """
    if factor == 1:
        return np.array(values, dtype=float)
    values = np.asarray(values, dtype=float)
    if values.ndim == 2 and values.shape[1] >= COLUMNS_TOGETHER and len(values) > 1:
        out = np.empty((-(-len(values) // factor), values.shape[1]))
        fir_decimate_columns(np.ascontiguousarray(values), _taps(factor), factor, out)
        return out
    return signal.resample_poly(values, 1, factor, axis=0, window=_taps(factor), padtype="line")
