"""Angle-domain processing on the measured drive angle: order tracking, synchronous averages,
their periodic-vs-residual SNR, removal of the reduction's orders, stroke-position averages.

A PRSM's vibration is made by parts that turn at fixed, mostly non-integer ratios to the screw
(per screw turn, paper 01's carrier turns 0.375 times and a roller spins 1.875 times relative
to the carrier) and by the drive's reduction, which turns with the motor. What a spall on one
of them makes repeats once per turn of that part, so it is read in **the angle of that part**,
measured as the angle the resolver gives (``screw_angle``), scaled by the kinematics:

* **Computed order tracking** (:func:`angle_resample`): the time signal interpolated at
  constant increments of the measured angle (Fyfe & Munck 1997). Where the angle grid is
  coarser than the time samples (the signal has more samples per turn than the grid), content
  above the grid's Nyquist order would fold onto lower orders; with ``antialias`` the signal is
  interpolated onto a grid ``m`` times finer (at least as fine as the time samples), low-passed
  there in the angle domain and decimated by ``m`` — an anti-alias filter fixed in orders, right
  whatever the speed did (the angle-domain low-pass of Bonnardot et al. 2005 §2).
* **Synchronous average at a period** (:func:`synchronous_average`): the resampled signal cut
  into whole periods and averaged (McFadden 1987). The period is any angle of the measured
  shaft, so a part whose ratio to the shaft is not an integer is averaged by resampling each of
  its periods to the same number of samples (the "resampling per period" TSA of Bechhoefer &
  Kingsley 2009). The per-period matrix is kept: the periodic-vs-residual SNR reads it.
* **Periodic SNR** (:func:`periodic_snr`): the energy of what repeats at the period over the
  energy of what does not, the noise left in the average (1/n of the residual's) subtracted —
  see the function for its expected value.
* **Removal of the motor-synchronous part** (:func:`subtract_synchronous`): the drive's
  reduction (a planetary gearhead, its mesh the strongest line of the nut vibration) is
  periodic in a motor turn, 2π/gear_ratio of screw angle. Its synchronous average is
  subtracted from the time signal before the PRSM's periods are averaged — the separation of
  one shaft's discrete components by subtracting its synchronous average (Randall & Antoni
  2011 §3; McFadden 1987). The carrier period is 8 motor turns and the screw's 3 for paper 01
  with the flight-EMA's ratio-3 gearhead, so without it the reduction's orders would be a
  large, healthy, "periodic" part of those averages.
* **Averages by stroke position** (:func:`position_profile`): a spall fixed on the screw is
  met only while the rollers' threads span it, i.e. over one stretch of the nut's stroke; its
  signature repeats in position, not in any turn. The RMS (or mean |x|) per position bin, over
  the passes a recording makes, and an SNR of that profile against its own scatter.
* **The PRSM's periods** (:func:`prsm_periods`): in radians of screw angle, for a design and
  a reduction ratio.

References
----------
K. R. Fyfe, E. D. S. Munck, "Analysis of computed order tracking", Mechanical Systems and
Signal Processing 11(2) (1997) 187–205 — resampling at constant angle increments from the
measured angle; interpolation and the anti-aliasing the resampling needs.
P. D. McFadden, "A revised model for the extraction of periodic waveforms by time domain
averaging", Mechanical Systems and Signal Processing 1(1) (1987) 83–95 — the synchronous
average; what is not synchronous is reduced as 1/√n in amplitude (1/n in power).
F. Bonnardot, M. El Badaoui, R. B. Randall, J. Danière, F. Guillet, "Use of the acceleration
signal of a gearbox in order to perform angular resampling (with limited speed fluctuation)",
Mechanical Systems and Signal Processing 19(4) (2005) 766–785 — angular resampling with a
low-pass in the angle domain.
E. Bechhoefer, M. Kingsley, "A review of time synchronous average algorithms", Annual
Conference of the Prognostics and Health Management Society (2009) — TSA by resampling each
period to a fixed number of samples, for shafts without a once-per-turn tachometer.
R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", Mechanical
Systems and Signal Processing 25(2) (2011) 485–520 — §3: separating the discrete (gear)
components by subtracting each shaft's synchronous average, the residual then carrying the
non-synchronous, impulsive content (kurtosis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.signal import firwin, resample_poly

from prsm_health.core.errors import PRSMHealthError
from prsm_health.physics.kinematics import speed_ratios

from .kernels import interp_rows

#: Largest oversampling of the anti-aliased resampling: the fine grid holds at most this many
#: points per output point. It is as fine as the time samples while the slowest speed of the
#: record is ≥ 1/32 of the speed the grid matches; slower stretches (a near-stop) keep content
#: above 32 grid Nyquists unfiltered, which linear interpolation itself attenuates (sinc²).
MAX_OVERSAMPLING = 32
#: Up-sampling of the time signal before the angle interpolation in the synchronous averages
#: (:func:`angle_resample`): 4 keeps ≥ 96 % of a line up to 0.35 f_s midway between samples
#: (the 2–8 kHz band of a 20 kHz recording), where linear interpolation alone keeps 48 %.
UPSAMPLING = 4
#: Fourier up-sampling of an average before it is evaluated at the time samples' angles
#: (:func:`subtract_synchronous`): linear interpolation between points 8× finer than the
#: average's grid errs by ≤ (π/(8p))²/2 of a line with p grid points per cycle — 3e-4 at the
#: grid's Nyquist (p = 2).
EVALUATION_UPSAMPLING = 8


def angle_resample(
    x: np.ndarray,
    angle: np.ndarray,
    period: float,
    samples_per_period: int,
    *,
    antialias: bool = False,
    upsampling: int = 1,
) -> tuple[np.ndarray, int]:
    """Resample ``x`` to a uniform grid of ``angle`` covering whole periods (computed order
    tracking).

    Parameters
    ----------
    x : ndarray (..., n)
        Signal sampled in time; several signals of the same instants on leading axes.
    angle : ndarray (n,) [rad]
        The measured shaft angle at the same instants; monotonic in either direction (a
        negative direction is mirrored so the grid increases).
    period : float [rad of ``angle``]
        The averaging period, e.g. 2π/|carrier ratio| for a carrier revolution.
    samples_per_period : int
    antialias : bool
        Low-pass in the angle domain where the grid is coarser than the time samples (module
        docstring): the signal is interpolated onto a grid ``m`` times finer, ``m`` the
        smallest integer that makes it at least as fine as the time samples everywhere (at
        most :data:`MAX_OVERSAMPLING`), filtered and decimated by
        ``scipy.signal.resample_poly(·, 1, m)`` (Kaiser-windowed FIR, β = 5, 20·m + 1 taps,
        zero phase: flat within 0.3 % up to 0.8 of the grid's Nyquist order, −6 dB at it,
        < 0.2 % beyond 1.2 of it). False (default, the gear indicators' processing): linear
        interpolation only.
    upsampling : int
        Band-limited up-sampling of the time signal by this factor before the linear
        interpolation (``scipy.signal.resample_poly(·, upsampling, 1)``, the angle linearly
        in time): Fyfe & Munck 1997's remedy for the interpolation error at high orders —
        linear interpolation between time samples keeps cos(πf/f_s) of a line at f midway
        between samples (0.48 at 6.9 kHz for 20 kHz sampling), between samples 4 times
        denser cos(πf/4f_s) (0.96). 1 (default, the gear indicators' processing): none.

    Returns
    -------
    (resampled signal of ``n_periods·samples_per_period`` samples (..., n_periods·samples_per_period), n_periods)
        Linear interpolation: at the 20 kHz diagnostics rate a mesh cycle spans ≥ 30 samples, so
        its error (McFadden 1987: attenuation of high orders) stays below 1 % of the mesh line.

    Raises
    ------
    PRSMHealthError
        ``x`` and ``angle`` of different lengths or not finite, a period that is not a positive
        angle, fewer than 8 samples per period, an angle that stops or turns back.

    References
    ----------
    Fyfe & Munck 1997 (resampling at constant angle increments); Bonnardot et al. 2005 §2
    (low-pass in the angle domain).
    """
    record = AngleRecord(x, angle, upsampling)
    return record.resample(period, samples_per_period, antialias=antialias)


class AngleRecord:
    """A record on its measured angle, checked once and up-sampled at most once, to be
    resampled over one period or several (:meth:`resample`, :func:`angle_resample`'s steps):
    the periods of one signal share its up-sampling, the costliest step.

    Raises
    ------
    PRSMHealthError
        ``x`` and ``angle`` of different lengths or not finite, a bad ``upsampling``, an angle
        that stops or turns back.
    """

    def __init__(self, x: np.ndarray, angle: np.ndarray, upsampling: int = 1):
        x, angle = np.asarray(x, float), np.asarray(angle, float)
        if x.shape[-1:] != angle.shape or angle.ndim != 1:
            raise PRSMHealthError(
                f"x and angle must be 1-D of one length, got {x.shape}, {angle.shape}"
            )
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(angle))):
            raise PRSMHealthError("x and angle must be finite")
        if not (isinstance(upsampling, (int, np.integer)) and 1 <= upsampling <= 64):
            raise PRSMHealthError(f"upsampling = {upsampling!r} must be an integer in 1…64")
        step = np.diff(angle)
        direction = np.sign(angle[-1] - angle[0])
        if direction == 0 or np.any(step * direction <= 0):
            raise PRSMHealthError(
                "angle must be strictly monotonic (no stop or reversal in a window)"
            )
        self.x, self.upsampling = x, int(upsampling)
        self.angle = angle * direction  # increasing
        self.finest = float(np.min(step * direction))  # the smallest recorded angle step
        self._fine: tuple[np.ndarray, np.ndarray] | None = None

    def _upsampled(self) -> tuple[np.ndarray, np.ndarray]:
        """(signal, angle) up-sampled by ``upsampling``, made at the first call."""
        if self.upsampling == 1:
            return self.x, self.angle
        if self._fine is None:
            # the k-th up-sampled point is at k/upsampling samples; the last ones, past the
            # last sample, have no angle and are dropped
            n, up = len(self.angle), self.upsampling
            kept = (n - 1) * up + 1
            self._fine = (
                _resample(self.x, up, 1)[..., :kept],
                np.interp(np.arange(kept) / up, np.arange(n), self.angle),
            )
        return self._fine

    def resample(
        self, period: float, samples_per_period: int, *, antialias: bool = False
    ) -> tuple[np.ndarray, int]:
        """:func:`angle_resample` of the record over ``period``."""
        if not (math.isfinite(period) and period > 0):
            raise PRSMHealthError(f"period = {period!r} must be a positive angle [rad]")
        if not (isinstance(samples_per_period, (int, np.integer)) and samples_per_period >= 8):
            raise PRSMHealthError(
                f"samples_per_period = {samples_per_period!r} must be an integer ≥ 8"
            )
        n_periods = int((self.angle[-1] - self.angle[0]) // period)
        if n_periods < 1:
            return np.empty(self.x.shape[:-1] + (0,)), 0
        spacing = period / samples_per_period
        # oversampling that makes the grid at least as fine as the time samples everywhere
        # (the recorded ones: up-sampling adds no content above their Nyquist)
        m = 1
        if antialias:
            m = min(MAX_OVERSAMPLING, max(1, math.ceil(spacing / self.finest - 1e-9)))
        x, angle = self._upsampled()
        grid = angle[0] + np.arange(n_periods * samples_per_period * m) * (spacing / m)
        rows = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
        out = np.empty((len(rows), len(grid)))
        interp_rows(grid, angle, rows, out)  # np.interp of every row, bitwise, one walk for all
        if m > 1:
            # the anti-alias low-pass at the output grid's Nyquist order, then every m-th
            # point; "line" padding: the ends see the signal's trend, not a step to zero
            out = _resample(out, 1, m)
        return out.reshape(x.shape[:-1] + (out.shape[-1],)), n_periods

    def synchronous_average(
        self, period: float, samples_per_period: int, *, antialias: bool = False
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`time_synchronous_average` of the record over ``period``."""
        resampled, n = self.resample(period, samples_per_period, antialias=antialias)
        periods = resampled.reshape(resampled.shape[:-1] + (n, samples_per_period))
        return (periods.mean(axis=-2) if n else resampled), periods


def _resample(x: np.ndarray, up: int, down: int) -> np.ndarray:
    """``scipy.signal.resample_poly(x, up, down, axis=-1, padtype="line")`` with its default
    low-pass (Kaiser β = 5) designed once (:func:`_resample_filter`): the same filter and
    result, without ``firwin`` on every call (it cost more than the filtering)."""
    return resample_poly(x, up, down, axis=-1, padtype="line", window=_resample_filter(up, down))


@lru_cache(maxsize=32)
def _resample_filter(up: int, down: int) -> np.ndarray:
    # resample_poly's own design for coprime up, down: 20·max + 1 taps, cut-off at 1/max of
    # Nyquist (it copies the array it is given)
    rate = max(up, down)
    taps = firwin(2 * 10 * rate + 1, 1.0 / rate, window=("kaiser", 5.0))
    taps.flags.writeable = False
    return taps


def time_synchronous_average(
    x: np.ndarray,
    angle: np.ndarray,
    period: float,
    samples_per_period: int = 1024,
    *,
    antialias: bool = False,
    upsampling: int = 1,
) -> tuple[np.ndarray, np.ndarray]:
    """TSA of ``x`` (..., n) over whole periods of ``angle``: (average over one period
    (..., samples_per_period), the periods (..., n_periods, samples_per_period)).

    The second array holds every period's samples (rows), the ensemble NA4 and NB4 read.
    ``antialias``, ``upsampling``: see :func:`angle_resample`.

    References
    ----------
    McFadden 1987; Bechhoefer & Kingsley 2009 (each period resampled to a fixed count).
    """
    record = AngleRecord(x, angle, upsampling)
    return record.synchronous_average(period, samples_per_period, antialias=antialias)


def default_samples_per_period(angle: np.ndarray, period: float) -> int:
    """Grid points per period that match the time samples at the record's mean speed: the
    period over the mean angle step, rounded up (at least 8) — a grid as fine as the
    recording where the speed is at its mean, anti-aliased where it is slower."""
    angle = np.asarray(angle, float)
    if len(angle) < 2 or angle[-1] == angle[0]:
        return 8
    mean_step = abs(float(angle[-1] - angle[0])) / (len(angle) - 1)
    return max(8, math.ceil(period / mean_step))


def periodic_snr(periods: np.ndarray, *, debias: bool = True):
    """Energy of what repeats at the period over the energy of what does not.

    With ``y_j`` the rows of ``periods`` (n periods of N samples each), ȳ their average and
    r_j = y_j − ȳ the residuals:

    * periodic energy: the variance of the average over its N samples,
      ``E_p = (1/N) Σ_i (ȳ_i − ⟨ȳ⟩)²``;
    * residual energy per sample: ``σ̂² = Σ_j Σ_i r_ij² / (N (n − 1))`` (unbiased: n − 1
      degrees of freedom per sample once the average is taken out);
    * ``SNR = E_p/σ̂² − (N − 1)/(N n)`` — the second term takes out the noise the average still
      holds (σ²/n per sample, less its mean over the N samples: McFadden 1987's 1/n power
      reduction); ``debias=False`` leaves it in (``E_p/σ̂²``, a noise floor of ≈ 1/n).

    **Expected value.** Rows ``y_j = s + e_j``, s any periodic waveform of variance P over the
    period (A²/2 for A·sin), e_j white Gaussian noise of variance σ² independent between
    periods: the average and the residuals are independent and σ̂² ~ σ² χ²_ν/ν with
    ν = N(n − 1), so

        E[SNR] = (P/σ²)·ν/(ν − 2) + 2(N − 1)/(N n (ν − 2)),

    i.e. P/σ² to within 2/ν relative (≤ 0.1 % for N ≥ 64, n ≥ 30): 0 on average for noise
    alone (negative about half the time), A²/(2σ²) for a sine. σ² is the noise as resampled:
    for noise band-limited below the grid's Nyquist order its variance; for noise white up to
    the time Nyquist, the anti-alias filter keeps only the grid's band of it and linear
    interpolation between time samples lowers it (to ½ midway) — so compare SNRs of one
    resampling setup (one period, one grid, one commanded speed: a check phase).

    Parameters
    ----------
    periods : ndarray (..., n, N)
        The per-period matrix (:attr:`SynchronousAverage.periods`).
    debias : bool

    Returns
    -------
    float (or ndarray (...) for several matrices): NaN with fewer than 2 periods or no
    residual and no periodic energy; inf for a periodic signal without residual.

    References
    ----------
    McFadden 1987 (1/n reduction of the non-synchronous power by the average).
    """
    periods = np.asarray(periods, float)
    if periods.ndim < 2 or periods.shape[-2] < 2 or periods.shape[-1] < 2:
        return math.nan if periods.ndim <= 2 else np.full(periods.shape[:-2], math.nan)
    n, size = periods.shape[-2:]
    average = periods.mean(axis=-2)
    periodic = np.var(average, axis=-1)
    residual = periods - average[..., None, :]
    noise = np.sum(residual * residual, axis=(-2, -1)) / (size * (n - 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        snr = periodic / noise
    if debias:
        snr = snr - (size - 1) / (size * n)
    snr = np.where(noise > 0, snr, np.where(periodic > 0, math.inf, math.nan))
    return float(snr) if np.ndim(snr) == 0 else snr


@dataclass(frozen=True)
class SynchronousAverage:
    """A synchronous average and the periods it averages.

    Attributes
    ----------
    average : ndarray (..., N)
        The average over one period, N samples from the record's first angle (mirrored for a
        decreasing angle) [unit of the signal].
    periods : ndarray (..., n, N)
        Every whole period's samples, one row each.
    period : float [rad of the angle]
    """

    average: np.ndarray
    periods: np.ndarray
    period: float

    @property
    def n_periods(self) -> int:
        return int(self.periods.shape[-2])

    @property
    def residual(self) -> np.ndarray:
        """The periods less the average (..., n, N): what does not repeat."""
        return self.periods - self.average[..., None, :]

    @property
    def snr(self):
        """:func:`periodic_snr` of the periods (bias-corrected)."""
        return periodic_snr(self.periods)


def synchronous_average(
    x: np.ndarray,
    angle: np.ndarray,
    period: float,
    samples_per_period: int | None = None,
    *,
    antialias: bool = True,
    upsampling: int | None = None,
) -> SynchronousAverage:
    """Synchronous average of ``x`` (..., n) over whole periods of the measured ``angle``.

    Parameters
    ----------
    x : ndarray (..., n)
    angle : ndarray (n,) [rad]
        Measured angle, strictly monotonic (either direction).
    period : float [rad of ``angle``]
        Any angle, a non-integer share of a turn included (:func:`prsm_periods`).
    samples_per_period : int or None
        Grid points per period; None: :func:`default_samples_per_period` (as fine as the
        recording at its mean speed).
    antialias : bool
        The angle-domain low-pass of :func:`angle_resample` (default on).
    upsampling : int or None
        Up-sampling before interpolation (:func:`angle_resample`); None: :data:`UPSAMPLING`.

    Returns
    -------
    SynchronousAverage
        With ``n_periods`` 0 when the record spans less than a period.

    Raises
    ------
    PRSMHealthError
        As :func:`angle_resample` (an angle that stops or turns back: no angle domain).

    References
    ----------
    McFadden 1987; Bechhoefer & Kingsley 2009; Fyfe & Munck 1997.
    """
    found = synchronous_average_periods(
        x,
        angle,
        {"period": period},
        samples_per_period,
        antialias=antialias,
        upsampling=upsampling,
    )
    return found["period"]


def synchronous_average_periods(
    x: np.ndarray,
    angle: np.ndarray,
    periods: dict[str, float],
    samples_per_period: int | None = None,
    *,
    antialias: bool = True,
    upsampling: int | None = None,
) -> dict[str, SynchronousAverage]:
    """:func:`synchronous_average` of one signal over each of several periods (name → period
    [rad]): the record checked and up-sampled once for all of them."""
    upsampling = UPSAMPLING if upsampling is None else upsampling
    record = AngleRecord(x, angle, upsampling)
    out = {}
    for name, period in periods.items():
        count = samples_per_period
        if count is None:
            count = default_samples_per_period(angle, period)
        average, rows = record.synchronous_average(period, count, antialias=antialias)
        if rows.shape[-2] == 0:
            average = np.full(record.x.shape[:-1] + (count,), math.nan)
        out[name] = SynchronousAverage(average, rows, float(period))
    return out


def evaluate_periodic(average: np.ndarray, angle: np.ndarray, period: float) -> np.ndarray:
    """The periodic waveform ``average`` (N samples over one period, from ``angle[0]``, in the
    direction the angle runs) at every angle of ``angle``: Fourier up-sampled by
    :data:`EVALUATION_UPSAMPLING`, then linearly interpolated, periodically."""
    average = np.asarray(average, float)
    angle = np.asarray(angle, float)
    size = average.shape[-1]
    fine_size = EVALUATION_UPSAMPLING * size
    fine = np.fft.irfft(np.fft.rfft(average), fine_size) * EVALUATION_UPSAMPLING
    direction = 1.0 if angle[-1] >= angle[0] else -1.0
    where = (angle - angle[0]) * direction
    grid = np.arange(fine_size) * (period / fine_size)
    return np.interp(where, grid, fine, period=period)


def subtract_synchronous(
    x: np.ndarray,
    angle: np.ndarray,
    period: float,
    samples_per_period: int | None = None,
    *,
    antialias: bool = True,
    upsampling: int | None = None,
) -> tuple[np.ndarray, SynchronousAverage]:
    """``x`` less its synchronous average at ``period``, in time: (residual (n,), the average).

    The average (:func:`synchronous_average`) is evaluated at every sample's angle
    (:func:`evaluate_periodic`) and subtracted, so every order of the period — the shaft's
    harmonics, a gear's mesh and its harmonics — leaves the signal, with its mean; what
    turns at other ratios stays. With ``period`` a motor turn (2π/gear_ratio of screw angle)
    it removes the reduction's orders before the PRSM's periods are averaged. Orders above the
    grid's Nyquist order (``samples_per_period``/2 per period) are not removed: the default
    grid resolves what the recording does at its mean speed.

    ``antialias``, ``upsampling``: as :func:`synchronous_average`; a line left by an
    imperfect resampling stays in the residual as a periodic line, so the default is the
    accurate one.

    Orders the period shares with another part go too: a screw order that is a multiple of
    the gear ratio is a motor order (3k for a ratio-3 reduction), a carrier order a multiple
    of 8 for paper 01 with it.

    Raises
    ------
    PRSMHealthError
        As :func:`angle_resample`; fewer than 2 whole periods (the average of one period is
        the signal itself: nothing would be left).

    References
    ----------
    Randall & Antoni 2011 §3 (synchronous-average subtraction); McFadden 1987.
    """
    x = np.asarray(x, float)
    found = synchronous_average(
        x, angle, period, samples_per_period, antialias=antialias, upsampling=upsampling
    )
    if found.n_periods < 2:
        raise PRSMHealthError(
            f"{found.n_periods} whole period(s) of {period:.4g} rad in the record: at least 2 "
            "are needed to subtract a synchronous average"
        )
    return x - evaluate_periodic(found.average, angle, period), found


# ---------------------------------------------------------------------------- stroke position
POSITION_STATISTICS = ("rms", "mean_abs")


@dataclass(frozen=True)
class PositionProfile:
    """A signal's level by stroke position (:func:`position_profile`).

    Attributes
    ----------
    centres : ndarray (bins,) [m]
        Centres of the bins kept, in increasing position (each ``bin_width`` wide, their edges
        on multiples of it; a bin left out leaves a gap).
    bin_width : float [m]
    profile : ndarray (bins,)
        The statistic of each bin over all its samples [unit of the signal].
    replicas : ndarray (splits, bins)
        The statistic of each of a bin's ``splits`` consecutive shares of its samples: the
        profile's repeated measurements, whose scatter is the residual.
    counts : ndarray (bins,)
        Samples per bin.
    """

    centres: np.ndarray
    bin_width: float
    profile: np.ndarray
    replicas: np.ndarray
    counts: np.ndarray

    @property
    def snr(self) -> float:
        """:func:`periodic_snr` of the replicas: the position-dependent energy of the profile
        over the scatter of its replicas, the estimation noise of the profile subtracted —
        about 0 for a level that does not depend on position."""
        if self.replicas.shape[-1] < 2:
            return math.nan
        return periodic_snr(self.replicas)

    @property
    def contrast(self) -> float:
        """Largest bin over the median bin [-]."""
        if len(self.profile) == 0:
            return math.nan
        median = float(np.median(self.profile))
        return float(np.max(self.profile)) / median if median > 0 else math.nan

    @property
    def peak_position(self) -> float:
        """Centre of the largest bin [m]."""
        if len(self.profile) == 0:
            return math.nan
        return float(self.centres[int(np.argmax(self.profile))])


def position_profile(
    x: np.ndarray,
    position: np.ndarray,
    bin_width: float,
    *,
    splits: int = 4,
    statistic: str = "rms",
    min_fill: float = 0.5,
) -> PositionProfile:
    """The level of ``x`` by stroke position: the average for a defect fixed on the screw.

    A spall on the screw thread is met only while the rollers' engaged threads span it, i.e.
    while the nut is within about half its engaged length of the spall: its bursts come back
    at the same **positions**, on every pass, whatever the speed. Binning by position and
    taking the RMS (or mean |x|) of each bin over all the passes is the synchronous average
    of that position-locked energy.

    Parameters
    ----------
    x : ndarray (n,)
        Signal (its mean is removed first), e.g. the nut acceleration with the reduction's
        orders removed (:func:`subtract_synchronous`).
    position : ndarray (n,) [m]
        Nut position along the screw (LVDT), or the screw angle × nut travel per radian.
    bin_width : float [m]
        Bins on multiples of it, so recordings of one unit share their bins.
    splits : int
        Each bin's samples (in time order, over every pass) cut into this many consecutive
        shares; the statistic of each is a replica of the bin's level (≥ 2).
    statistic : {"rms", "mean_abs"}
    min_fill : float
        Bins with fewer samples than this share of the fullest bin are left out (the partly
        covered bins at the ends of a stroke, whose level is less certain).

    Returns
    -------
    PositionProfile

    Raises
    ------
    PRSMHealthError
        Arrays of different lengths or not finite, a bad ``bin_width``, ``splits`` or
        ``statistic``.

    References
    ----------
    McFadden 1987 (averaging what repeats at a known period — here a position — over its
    repetitions); Randall & Antoni 2011 §3 (the residual after the discrete components are
    removed carries the impulsive content).
    """
    x, position = np.asarray(x, float), np.asarray(position, float)
    if x.ndim != 1 or x.shape != position.shape:
        raise PRSMHealthError(
            f"x and position must be 1-D of one length, got {x.shape}, {position.shape}"
        )
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(position))):
        raise PRSMHealthError("x and position must be finite")
    if not (math.isfinite(bin_width) and bin_width > 0):
        raise PRSMHealthError(f"bin_width = {bin_width!r} must be a positive length [m]")
    if not (isinstance(splits, (int, np.integer)) and splits >= 2):
        raise PRSMHealthError(f"splits = {splits!r} must be an integer ≥ 2")
    if statistic not in POSITION_STATISTICS:
        raise PRSMHealthError(
            f"statistic = {statistic!r} must be one of {', '.join(POSITION_STATISTICS)}"
        )
    empty = PositionProfile(
        np.empty(0), float(bin_width), np.empty(0), np.empty((splits, 0)), np.empty(0, int)
    )
    if len(x) == 0:
        return empty
    x = x - np.mean(x)
    value = x * x if statistic == "rms" else np.abs(x)
    first = math.floor(float(np.min(position)) / bin_width)
    index = np.floor(position / bin_width).astype(np.int64) - first
    counts = np.bincount(index)
    keep = np.flatnonzero((counts >= min_fill * counts.max()) & (counts >= 2 * splits))
    if len(keep) == 0:
        return empty
    order = np.argsort(index, kind="stable")  # each bin's samples together, in time order
    starts = np.concatenate(([0], np.cumsum(counts)))
    profile = np.empty(len(keep))
    replicas = np.empty((splits, len(keep)))
    for k, b in enumerate(keep):
        members = value[order[starts[b] : starts[b + 1]]]
        profile[k] = np.mean(members)
        replicas[:, k] = [np.mean(part) for part in np.array_split(members, splits)]
    if statistic == "rms":
        profile, replicas = np.sqrt(profile), np.sqrt(replicas)
    centres = (first + keep + 0.5) * bin_width
    return PositionProfile(centres, float(bin_width), profile, replicas, counts[keep])


# ---------------------------------------------------------------------------- periods
#: The periods :func:`prsm_periods` gives, in order.
PERIODS = ("nut_pass", "roller_spin", "carrier", "screw", "motor")


def prsm_periods(design, gear_ratio: float | None = None) -> dict[str, float]:
    """The PRSM's periods in radians of screw angle, for synchronous averages.

    Parameters
    ----------
    design : PRSMDesign
    gear_ratio : float or None
        Motor turns per screw turn of the drive's reduction; None: 1 (direct drive, the motor
        is the screw).

    Returns
    -------
    dict with, in :data:`PERIODS` order [rad of screw angle]:

    * ``nut_pass`` — 2π/|ω_c/ω_s|/n_rollers: every roller passes a point of the nut (a nut
      spall) once per carrier turn, n_rollers passes per carrier turn;
    * ``roller_spin`` — 2π/|(ω_r − ω_c)/ω_s|: one spin of a roller relative to the carrier
      (a roller spall meets the screw and the nut once each per spin);
    * ``carrier`` — 2π/|ω_c/ω_s|: one carrier turn (ring-gear mesh, roller set);
    * ``screw`` — 2π;
    * ``motor`` — 2π/gear_ratio: one motor turn, in which the reduction's orders are
      periodic.

    Raises
    ------
    PRSMHealthError
        A gear ratio that is not a positive number.

    References
    ----------
    Paper 01 §3.1–3.2 (carrier/screw speed ratio); paper 03 eqs. (25)–(27) (carrier and roller
    spin), via :func:`prsm_health.physics.kinematics.speed_ratios`.
    """
    ratio = 1.0 if gear_ratio is None else gear_ratio
    try:
        ratio = float(ratio)
    except (TypeError, ValueError):
        raise PRSMHealthError(f"gear_ratio = {gear_ratio!r} must be a positive number") from None
    if not (math.isfinite(ratio) and ratio > 0):
        raise PRSMHealthError(f"gear_ratio = {gear_ratio!r} must be a positive number")
    ratios = speed_ratios(design)
    carrier = 2 * math.pi / abs(ratios.carrier)
    return {
        "nut_pass": carrier / design.n_rollers,
        "roller_spin": 2 * math.pi / abs(ratios.roller_spin_relative),
        "carrier": carrier,
        "screw": 2 * math.pi,
        "motor": 2 * math.pi / ratio,
    }
