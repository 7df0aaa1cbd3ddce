"""Angle-domain processing and the gear condition indicators of the literature.

A vibration signal sampled in time is resampled to a uniform grid of a shaft's angle (order
tracking) and averaged over that shaft's revolutions — the **time-synchronous average** (TSA):
what turns with the shaft adds up, the rest averages down as 1/√(revolutions) [McFadden 1987].
From the TSA's order spectrum (one bin per order of the averaging period) come the signals the
indicators read:

* **regular** signal: the shaft orders 1…``shaft_orders``, the mesh harmonics and their
  first-order sidebands — what a healthy gear makes;
* **difference** signal d: the TSA without the regular components;
* **residual** signal r: the TSA without the shaft orders and the mesh harmonics (sidebands kept).

The indicators (definitions as compiled by Lebold et al. 2000, from Stewart 1977 and
Zakrajsek, Townsend & Decker 1993 / Decker et al. 1994), N samples per period:

* FM0 = PP(TSA) / Σ_h A(h·mesh) — peak-to-peak over the sum of the mesh harmonics' amplitudes;
* FM4 = N Σ(d − d̄)⁴ / [Σ(d − d̄)²]² — kurtosis of the difference signal (3 for Gaussian);
* M6A = N² Σ(d − d̄)⁶ / [Σ(d − d̄)²]³ and M8A = N³ Σ(d − d̄)⁸ / [Σ(d − d̄)²]⁴;
* NA4 = N Σ(r − r̄)⁴ / {(1/M) Σ_j Σ_i (r_ij − r̄_j)²}² — the residual's fourth moment over the
  mean variance of the M residuals of the run so far (the run ensemble: a baseline that grows
  with the damage, unlike FM4's own variance);
* NB4 = NA4 of the envelope of the TSA band-passed around the mesh frequency (± half the mesh
  order, the sidebands of a local fault);
* energy ratio ER = RMS(d) / RMS(regular);
* sideband index SI = (S₋₁ + S₊₁)/2 and sideband level factor SLF = (S₋₁ + S₊₁)/σ(TSA), with
  S±₁ the amplitudes of the first-order sidebands of the mesh fundamental.

The PRSM's speed ratios are not integers (carrier 0.375 of the screw for paper 01), so the
averaging period is given in radians of the **measured** angle: a carrier revolution is
2π/|ω_c/ω_s| screw radians, and the grid spans whole periods of it. Within one carrier period
the ring gear meshes z_ring times (an integer order); within one roller spin relative to the
carrier its gear meshes z_roller times.

References
----------
P. D. McFadden, "A revised model for the extraction of periodic waveforms by time domain
averaging", MSSP 1 (1987) 83–95. R. M. Stewart, "Some useful data analysis techniques for
gearbox diagnostics", ISVR MHM/R/10/77 (1977). J. J. Zakrajsek, D. P. Townsend, H. J. Decker,
"An analysis of gear fault detection methods as applied to pitting fatigue failure data", NASA
TM-105950 (1993). H. J. Decker, R. F. Handschuh, J. J. Zakrajsek, "An enhancement to the NA4
gear vibration diagnostic parameter", NASA TM-106553 (1994). M. Lebold, K. McClintic, R.
Campbell, C. Byington, K. Maynard, "Review of vibration analysis methods for gearbox diagnostics
and prognostics", Proc. 54th MFPT (2000) 623–634.
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.core.errors import PRSMHealthError

# order tracking and the TSA live in angle_domain (one implementation); re-exported here,
# where they were first public
from .angle_domain import AngleRecord
from .angle_domain import angle_resample as angle_resample
from .angle_domain import time_synchronous_average as time_synchronous_average
from .spectra import hilbert_envelope

#: Fewest whole periods a TSA averages before its indicators are given (NaN below): with one
#: period nothing is averaged, and the ensemble of NA4 needs two.
MIN_PERIODS = 2
#: Shaft orders counted as regular (the period's own once-, twice- … per-turn components:
#: eccentricity, misalignment).
SHAFT_ORDERS = 2
#: Mesh harmonics counted as regular and summed by FM0.
MESH_HARMONICS = 3


def _orders(tsa: np.ndarray) -> np.ndarray:
    return np.fft.rfft(tsa, axis=-1)


def _keep(n_bins: int, orders: list[int]) -> np.ndarray:
    mask = np.zeros(n_bins, bool)
    for k in orders:
        if 0 <= k < n_bins:
            mask[k] = True
    return mask


def _component_orders(mesh_order: int, sidebands: bool) -> list[int]:
    orders = list(range(1, SHAFT_ORDERS + 1))
    for h in range(1, MESH_HARMONICS + 1):
        orders.append(h * mesh_order)
        if sidebands:
            orders += [h * mesh_order - 1, h * mesh_order + 1]
    return orders


def _value(x):
    """A float for the indicator of one record, the array of several records' as it is."""
    return float(x) if np.ndim(x) == 0 else x


def split_signals(
    tsa: np.ndarray, mesh_order: int, spectrum: np.ndarray | None = None
) -> dict[str, np.ndarray]:
    """The regular, difference and residual signals of a TSA (see the module docstring); of
    every TSA on the leading axes of ``tsa`` (..., N). ``spectrum``: the TSA's order spectrum
    (``np.fft.rfft(tsa, axis=-1)``) when the caller has it (here and below)."""
    spectrum = _orders(tsa) if spectrum is None else spectrum
    n = tsa.shape[-1]
    regular_mask = _keep(spectrum.shape[-1], _component_orders(mesh_order, sidebands=True))
    residual_mask = _keep(spectrum.shape[-1], _component_orders(mesh_order, sidebands=False))
    regular = np.fft.irfft(np.where(regular_mask, spectrum, 0.0), n, axis=-1)
    centred = tsa - np.mean(tsa, axis=-1, keepdims=True)
    return {
        "regular": regular,
        "difference": centred - regular,
        "residual": centred - np.fft.irfft(np.where(residual_mask, spectrum, 0.0), n, axis=-1),
    }


def _moment_ratio(d: np.ndarray, power: int) -> float:
    """N^(p/2−1) Σ(d − d̄)^p / [Σ(d − d̄)²]^(p/2): FM4 (p = 4), M6A (6), M8A (8), along the
    last axis."""
    return _moment_ratios(d, (power,))[0]


def _moment_ratios(d: np.ndarray, powers=(4, 6, 8)) -> list:
    """:func:`_moment_ratio` of each power, the signal centred and squared once."""
    d = d - np.mean(d, axis=-1, keepdims=True)
    squared = d * d
    s2 = np.sum(squared, axis=-1)
    n = d.shape[-1]
    # d^p from products: numpy's general power costs ten times a multiplication
    fourth = squared * squared
    out = []
    for power in powers:
        d_p = fourth if power == 4 else fourth * squared if power == 6 else fourth * fourth
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = n ** (power / 2 - 1) * np.sum(d_p, axis=-1) / s2 ** (power / 2)
        out.append(_value(np.where(s2 > 0, ratio, math.nan)))
    return out


def fm4(difference: np.ndarray) -> float:
    """FM4 of a difference signal (Stewart 1977; Lebold et al. 2000)."""
    return _moment_ratio(difference, 4)


def m6a(difference: np.ndarray) -> float:
    """M6A of a difference signal (Martin 1989, in Zakrajsek et al. 1993)."""
    return _moment_ratio(difference, 6)


def m8a(difference: np.ndarray) -> float:
    """M8A of a difference signal (Martin 1989, in Zakrajsek et al. 1993)."""
    return _moment_ratio(difference, 8)


def fm0(
    tsa: np.ndarray,
    mesh_order: int,
    harmonics: int = MESH_HARMONICS,
    spectrum: np.ndarray | None = None,
) -> float:
    """FM0 = peak-to-peak of the TSA / Σ amplitudes of its mesh harmonics (Stewart 1977)."""
    amplitude = 2.0 * np.abs(_orders(tsa) if spectrum is None else spectrum) / tsa.shape[-1]
    total = np.zeros(tsa.shape[:-1])
    for h in range(1, harmonics + 1):
        if h * mesh_order < amplitude.shape[-1]:
            total = total + amplitude[..., h * mesh_order]
    with np.errstate(invalid="ignore", divide="ignore"):
        return _value(np.where(total > 0, np.ptp(tsa, axis=-1) / total, math.nan))


def ensemble_ratio(current: np.ndarray, earlier: list[float] = ()) -> float:
    """N Σ(x − x̄)⁴ / {(1/M) Σ_j Σ_i (x_ij − x̄_j)²}²: NA4 (x = residual signal) and NB4
    (x = mesh-band envelope) of the current record, ``earlier`` the Σ_i (x_ij − x̄_j)² of the
    run's earlier records (Zakrajsek et al. 1993; Decker et al. 1994). Without earlier records
    (M = 1) it is the current record's kurtosis, as at the start of a run. Several current
    records on the leading axes of ``current`` (..., N): each as the first of its run."""
    c = current - np.mean(current, axis=-1, keepdims=True)
    squared = c * c
    variance = np.sum(squared, axis=-1)
    if len(earlier):
        variance = np.mean([float(variance), *earlier])
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = c.shape[-1] * np.sum(squared * squared, axis=-1) / variance**2
    return _value(np.where(variance > 0, ratio, math.nan))


def sum_of_squares(x: np.ndarray) -> float:
    """Σ_i (x_i − x̄)², a record's entry in the run ensemble of NA4/NB4."""
    return _value(np.sum((x - np.mean(x, axis=-1, keepdims=True)) ** 2, axis=-1))


def mesh_band_envelope(
    tsa: np.ndarray, mesh_order: int, spectrum: np.ndarray | None = None
) -> np.ndarray:
    """Envelope (Hilbert magnitude) of the TSA band-passed around the mesh fundamental (the
    NB4 signal, Zakrajsek et al. 1993): orders mesh ± mesh/2, half-way to the neighbouring
    harmonics, so the sidebands a local tooth fault spreads around the mesh are kept (a band
    of the first-order sidebands only would smooth a one-tooth burst away)."""
    spectrum = _orders(tsa) if spectrum is None else spectrum
    half = max(1, mesh_order // 2)
    band = _keep(spectrum.shape[-1], list(range(mesh_order - half, mesh_order + half + 1)))
    kept = np.where(band, spectrum, 0.0)
    return hilbert_envelope(np.fft.irfft(kept, tsa.shape[-1], axis=-1), kept)


def sideband_amplitudes(
    tsa: np.ndarray, mesh_order: int, spectrum: np.ndarray | None = None
) -> tuple[float, float]:
    """Amplitudes of the first-order sidebands of the mesh fundamental (S₋₁, S₊₁)."""
    amplitude = 2.0 * np.abs(_orders(tsa) if spectrum is None else spectrum) / tsa.shape[-1]
    if mesh_order + 1 >= amplitude.shape[-1] or mesh_order < 2:
        nan = _value(np.full(tsa.shape[:-1], math.nan))
        return nan, nan
    return _value(amplitude[..., mesh_order - 1]), _value(amplitude[..., mesh_order + 1])


#: The indicators :func:`gear_indicators` returns, in order.
GEAR_INDICATORS = (
    "fm0",
    "fm4",
    "na4",
    "nb4",
    "m6a",
    "m8a",
    "energy_ratio",
    "sideband_index",
    "sideband_level_factor",
    "tsa_rms",
    "periods",
)


def gear_indicators(
    x: np.ndarray,
    angle: np.ndarray,
    period: float,
    mesh_order: int | None,
    samples_per_period: int = 1024,
    ensemble: dict[str, list[float]] | None = None,
) -> dict[str, float]:
    """Every indicator of one window, NaN where the window cannot support it.

    ``ensemble``: the run so far for NA4 and NB4 — ``{"residual": [...], "envelope": [...]}``
    of the earlier windows' :func:`sum_of_squares`; this window's are appended. None: the window
    is the first record of its run (M = 1), so a diagnosis of one window does not depend on
    what came before it. ``mesh_order`` None (a period without a gear mesh): only the TSA's RMS
    and the period count.
    """
    averages = synchronous_averages(x, angle, [period], samples_per_period)
    if averages is None:
        return dict.fromkeys(GEAR_INDICATORS, math.nan)
    tsa, n_periods = averages[0]
    values = tsa_indicators(tsa[None], n_periods, mesh_order, ensemble)
    return {name: float(values[name][0]) for name in GEAR_INDICATORS}


def synchronous_averages(
    x: np.ndarray, angle: np.ndarray, periods, samples_per_period: int = 1024
) -> list[tuple[np.ndarray, int]] | None:
    """(TSA (..., samples_per_period), periods averaged) of the signals ``x`` (..., n) over
    ``angle`` for each of ``periods`` [rad] (the record checked once for all), or None when
    the shaft stopped or turned back in the window (no angle domain).

    Raises
    ------
    PRSMHealthError
        Non-finite input, a bad period.
    """
    try:
        record = AngleRecord(x, angle)
        found = [record.synchronous_average(p, samples_per_period) for p in periods]
    except PRSMHealthError:
        if np.all(np.isfinite(angle)) and np.all(np.isfinite(x)):
            return None
        raise
    return [(tsa, rows.shape[-2]) for tsa, rows in found]


def tsa_indicators(
    tsa: np.ndarray,
    n_periods: int,
    mesh_order: int | None,
    ensemble: dict[str, list[float]] | None = None,
) -> dict[str, np.ndarray]:
    """:data:`GEAR_INDICATORS` of the TSAs on the rows of ``tsa`` (rows, N), each over
    ``n_periods`` periods, as arrays (rows,); see :func:`gear_indicators` (``ensemble`` only
    for one row)."""
    rows = tsa.shape[0]
    out = {name: np.full(rows, math.nan) for name in GEAR_INDICATORS}
    out["periods"][:] = n_periods
    if n_periods < MIN_PERIODS:
        return out
    out["tsa_rms"] = np.std(tsa, axis=-1)
    if mesh_order is None or not 2 <= mesh_order < tsa.shape[-1] // 2 - 1:
        return out
    spectrum = _orders(tsa)  # one order spectrum for every indicator that reads it
    parts = split_signals(tsa, mesh_order, spectrum)
    d = parts["difference"]
    out["fm0"] = np.atleast_1d(fm0(tsa, mesh_order, spectrum=spectrum))
    out["fm4"], out["m6a"], out["m8a"] = (np.atleast_1d(r) for r in _moment_ratios(d))
    rms_regular = np.sqrt(np.mean(parts["regular"] ** 2, axis=-1))
    with np.errstate(invalid="ignore", divide="ignore"):
        out["energy_ratio"] = np.where(
            rms_regular > 0, np.sqrt(np.mean(d**2, axis=-1)) / rms_regular, math.nan
        )
    envelope = mesh_band_envelope(tsa, mesh_order, spectrum)
    if ensemble is None:
        out["na4"] = np.atleast_1d(ensemble_ratio(parts["residual"]))
        out["nb4"] = np.atleast_1d(ensemble_ratio(envelope))
    else:
        out["na4"][0] = ensemble_ratio(parts["residual"][0], ensemble["residual"])
        out["nb4"][0] = ensemble_ratio(envelope[0], ensemble["envelope"])
        ensemble["residual"].append(sum_of_squares(parts["residual"][0]))
        ensemble["envelope"].append(sum_of_squares(envelope[0]))
    lower, upper = (np.atleast_1d(s) for s in sideband_amplitudes(tsa, mesh_order, spectrum))
    out["sideband_index"] = 0.5 * (lower + upper)
    sigma = out["tsa_rms"]
    with np.errstate(invalid="ignore", divide="ignore"):
        out["sideband_level_factor"] = np.where(sigma > 0, (lower + upper) / sigma, math.nan)
    return out
