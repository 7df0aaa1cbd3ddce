"""The data logger's anti-alias decimation from the integration rate to the sample rate.

The simulator records its truth signals at the integration rate f_int = m·f_s (m integer);
:func:`decimate` turns a signal into what a logger stores at the sample rate f_s: a polyphase
FIR (``scipy.signal.resample_poly``, Kaiser window β = 5, cut-off at the new Nyquist;
``padtype="line"`` so ramps such as angles and positions have no edge transients). The sensors
themselves — their errors, bandwidths, noise — are in :mod:`prsm_health.simulation.instrumentation`.
"""

from __future__ import annotations

import numpy as np
from scipy import signal


def decimate(values: np.ndarray, factor: int) -> np.ndarray:
    """Anti-aliased decimation by an integer factor along axis 0 (polyphase FIR).

    Parameters
    ----------
    values : ndarray, shape (n, …)
    factor : int

    Returns
    -------
    ndarray, shape (ceil(n / factor), …)
    """
    if factor == 1:
        return np.array(values, dtype=float)
    return signal.resample_poly(values, 1, factor, axis=0, window=("kaiser", 5.0), padtype="line")
