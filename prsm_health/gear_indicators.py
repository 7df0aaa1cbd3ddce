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
from scipy import signal

from .errors import PRSMHealthError

#: Fewest whole periods a TSA averages before its indicators are given (NaN below): with one
#: period nothing is averaged, and the ensemble of NA4 needs two.
MIN_PERIODS = 2
#: Shaft orders counted as regular (the period's own once-, twice- … per-turn components:
#: eccentricity, misalignment).
SHAFT_ORDERS = 2
#: Mesh harmonics counted as regular and summed by FM0.
MESH_HARMONICS = 3


def angle_resample(
    x: np.ndarray, angle: np.ndarray, period: float, samples_per_period: int
) -> tuple[np.ndarray, int]:
    """Resample ``x`` to a uniform grid of ``angle`` covering whole periods.

    Parameters
    ----------
    x : ndarray
        Signal sampled in time.
    angle : ndarray [rad]
        The measured shaft angle at the same instants; monotonic in either direction (a
        negative direction is mirrored so the grid increases).
    period : float [rad of ``angle``]
        The averaging period, e.g. 2π/|carrier ratio| for a carrier revolution.
    samples_per_period : int

    Returns
    -------
    (resampled signal of ``n_periods·samples_per_period`` samples, n_periods)
        Linear interpolation: at the 20 kHz diagnostics rate a mesh cycle spans ≥ 30 samples, so
        its error (McFadden 1987: attenuation of high orders) stays below 1 % of the mesh line.
    """
    x, angle = np.asarray(x, float), np.asarray(angle, float)
    if x.shape != angle.shape or x.ndim != 1:
        raise PRSMHealthError(
            f"x and angle must be 1-D of one length, got {x.shape}, {angle.shape}"
        )
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(angle))):
        raise PRSMHealthError("x and angle must be finite")
    if not (math.isfinite(period) and period > 0):
        raise PRSMHealthError(f"period = {period!r} must be a positive angle [rad]")
    if not (isinstance(samples_per_period, (int, np.integer)) and samples_per_period >= 8):
        raise PRSMHealthError(f"samples_per_period = {samples_per_period!r} must be an integer ≥ 8")
    step = np.diff(angle)
    direction = np.sign(angle[-1] - angle[0])
    if direction == 0 or np.any(step * direction <= 0):
        raise PRSMHealthError("angle must be strictly monotonic (no stop or reversal in a window)")
    angle = angle * direction
    n_periods = int((angle[-1] - angle[0]) // period)
    if n_periods < 1:
        return np.empty(0), 0
    grid = angle[0] + np.arange(n_periods * samples_per_period) * (period / samples_per_period)
    return np.interp(grid, angle, x), n_periods


def time_synchronous_average(
    x: np.ndarray, angle: np.ndarray, period: float, samples_per_period: int = 1024
) -> tuple[np.ndarray, np.ndarray]:
    """TSA of ``x`` over whole periods of ``angle``: (average over one period, the periods).

    The second array holds every period's samples (rows), the ensemble NA4 and NB4 read.
    """
    resampled, n = angle_resample(x, angle, period, samples_per_period)
    periods = resampled.reshape(n, samples_per_period) if n else np.empty((0, samples_per_period))
    return (periods.mean(axis=0) if n else np.empty(0)), periods


def _orders(tsa: np.ndarray) -> np.ndarray:
    return np.fft.rfft(tsa)


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


def split_signals(tsa: np.ndarray, mesh_order: int) -> dict[str, np.ndarray]:
    """The regular, difference and residual signals of a TSA (see the module docstring)."""
    spectrum = _orders(tsa)
    n = len(tsa)
    regular_mask = _keep(len(spectrum), _component_orders(mesh_order, sidebands=True))
    residual_mask = _keep(len(spectrum), _component_orders(mesh_order, sidebands=False))
    regular = np.fft.irfft(np.where(regular_mask, spectrum, 0.0), n)
    centred = tsa - np.mean(tsa)
    return {
        "regular": regular,
        "difference": centred - regular,
        "residual": centred - np.fft.irfft(np.where(residual_mask, spectrum, 0.0), n),
    }


def _moment_ratio(d: np.ndarray, power: int) -> float:
    """N^(p/2−1) Σ(d − d̄)^p / [Σ(d − d̄)²]^(p/2): FM4 (p = 4), M6A (6), M8A (8)."""
    d = d - np.mean(d)
    s2 = float(np.sum(d**2))
    if s2 <= 0:
        return math.nan
    n = len(d)
    return float(n ** (power / 2 - 1) * np.sum(d**power) / s2 ** (power / 2))


def fm4(difference: np.ndarray) -> float:
    """FM4 of a difference signal (Stewart 1977; Lebold et al. 2000)."""
    return _moment_ratio(difference, 4)


def m6a(difference: np.ndarray) -> float:
    """M6A of a difference signal (Martin 1989, in Zakrajsek et al. 1993)."""
    return _moment_ratio(difference, 6)


def m8a(difference: np.ndarray) -> float:
    """M8A of a difference signal (Martin 1989, in Zakrajsek et al. 1993)."""
    return _moment_ratio(difference, 8)


def fm0(tsa: np.ndarray, mesh_order: int, harmonics: int = MESH_HARMONICS) -> float:
    """FM0 = peak-to-peak of the TSA / Σ amplitudes of its mesh harmonics (Stewart 1977)."""
    amplitude = 2.0 * np.abs(_orders(tsa)) / len(tsa)
    lines = [
        amplitude[h * mesh_order]
        for h in range(1, harmonics + 1)
        if h * mesh_order < len(amplitude)
    ]
    total = float(np.sum(lines))
    return float(np.ptp(tsa)) / total if total > 0 else math.nan


def ensemble_ratio(current: np.ndarray, earlier: list[float] = ()) -> float:
    """N Σ(x − x̄)⁴ / {(1/M) Σ_j Σ_i (x_ij − x̄_j)²}²: NA4 (x = residual signal) and NB4
    (x = mesh-band envelope) of the current record, ``earlier`` the Σ_i (x_ij − x̄_j)² of the
    run's earlier records (Zakrajsek et al. 1993; Decker et al. 1994). Without earlier records
    (M = 1) it is the current record's kurtosis, as at the start of a run."""
    c = current - np.mean(current)
    variance = float(np.mean([np.sum(c**2), *earlier]))
    if variance <= 0:
        return math.nan
    return float(len(c) * np.sum(c**4) / variance**2)


def sum_of_squares(x: np.ndarray) -> float:
    """Σ_i (x_i − x̄)², a record's entry in the run ensemble of NA4/NB4."""
    return float(np.sum((x - np.mean(x)) ** 2))


def mesh_band_envelope(tsa: np.ndarray, mesh_order: int) -> np.ndarray:
    """Envelope (Hilbert magnitude) of the TSA band-passed around the mesh fundamental (the
    NB4 signal, Zakrajsek et al. 1993): orders mesh ± mesh/2, half-way to the neighbouring
    harmonics, so the sidebands a local tooth fault spreads around the mesh are kept (a band
    of the first-order sidebands only would smooth a one-tooth burst away)."""
    spectrum = _orders(tsa)
    half = max(1, mesh_order // 2)
    band = _keep(len(spectrum), list(range(mesh_order - half, mesh_order + half + 1)))
    return np.abs(signal.hilbert(np.fft.irfft(np.where(band, spectrum, 0.0), len(tsa))))


def sideband_amplitudes(tsa: np.ndarray, mesh_order: int) -> tuple[float, float]:
    """Amplitudes of the first-order sidebands of the mesh fundamental (S₋₁, S₊₁)."""
    amplitude = 2.0 * np.abs(_orders(tsa)) / len(tsa)
    if mesh_order + 1 >= len(amplitude) or mesh_order < 2:
        return math.nan, math.nan
    return float(amplitude[mesh_order - 1]), float(amplitude[mesh_order + 1])


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
    out = dict.fromkeys(GEAR_INDICATORS, math.nan)
    try:
        tsa, periods = time_synchronous_average(x, angle, period, samples_per_period)
    except PRSMHealthError:
        if np.all(np.isfinite(angle)) and np.all(np.isfinite(x)):
            return out  # the shaft stopped or turned back in this window: no angle domain
        raise
    out["periods"] = float(len(periods))
    if len(periods) < MIN_PERIODS:
        return out
    out["tsa_rms"] = float(np.std(tsa))
    if mesh_order is None or not 2 <= mesh_order < samples_per_period // 2 - 1:
        return out
    parts = split_signals(tsa, mesh_order)
    d = parts["difference"]
    out["fm0"] = fm0(tsa, mesh_order)
    out["fm4"], out["m6a"], out["m8a"] = fm4(d), m6a(d), m8a(d)
    rms_regular = float(np.sqrt(np.mean(parts["regular"] ** 2)))
    out["energy_ratio"] = (
        float(np.sqrt(np.mean(d**2))) / rms_regular if rms_regular > 0 else math.nan
    )
    ensemble = ensemble if ensemble is not None else {"residual": [], "envelope": []}
    envelope = mesh_band_envelope(tsa, mesh_order)
    out["na4"] = ensemble_ratio(parts["residual"], ensemble["residual"])
    out["nb4"] = ensemble_ratio(envelope, ensemble["envelope"])
    ensemble["residual"].append(sum_of_squares(parts["residual"]))
    ensemble["envelope"].append(sum_of_squares(envelope))
    lower, upper = sideband_amplitudes(tsa, mesh_order)
    out["sideband_index"] = 0.5 * (lower + upper)
    sigma = float(np.std(tsa))
    out["sideband_level_factor"] = (lower + upper) / sigma if sigma > 0 else math.nan
    return out
