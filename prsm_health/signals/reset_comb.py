"""The recirculating PRSM's reset comb: indicators of the pulses the rollers' resets make.

Once per carrier revolution each grooved roller of a recirculating PRSM crosses the threadless
sector (orbital angle 2β): the cam ring's chamfer pushes it forward by one lead — an impact on
the nut, its size set by the speed, not by the axial load — and at the sector's exit, 2β/ω_c
later, it lands back on the nut thread (load-dependent). The nut's axial acceleration therefore
carries a comb of pulse pairs at the roller-passage rate N·f_c in every recording. A nut-flank
spall strikes once per roller passage too — the same line — but at its own phase, and its
strike grows with the load. So the comb is read in the **passage's angle domain**, not in a
spectrum: synchronous averages over the passage period, 2π/(N·|ω_c/ω_s|) of screw angle, from
the measured ``screw_angle`` (:func:`prsm_health.signals.angle_domain.synchronous_average`:
resampled period by period, so the non-integer ratio needs no tachometer), of two signals:

* the mean-removed nut acceleration — its time-synchronous average (TSA): what repeats, phase
  and all, at every passage;
* its instantaneous power (the squared Hilbert envelope of the window) — the **energy
  profile**: where in the passage the vibration's energy sits, whatever the phase of the
  ringing that carries it.

A rig does not know where the sector is relative to its resolver's zero: the carrier angle is
known only up to an offset (ratio × screw angle). Every indicator is therefore **invariant to
the averages' phase** (a circular shift of them):

* ``comb_rms`` [m/s²] — RMS of the TSA: is the comb there;
* ``comb_sync_share`` [-] — the TSA's power over the signal's, the noise the average still
  holds taken out: how much of the vibration is locked to the passages;
* ``comb_outside_share`` [-] — the share of the energy profile outside the best-placed reset
  window (:func:`reset_window_share` of the period, placed where it holds the most): a healthy
  unit's energy lies in it, a strike elsewhere in the period (a spall) puts energy outside;
* ``comb_doublet_spacing`` [-] — circular phase distance (share of the period, 0–0.5) from the
  largest peak of the amplitude profile (√ energy profile) to the second largest (at least
  :data:`MIN_SEPARATION` away): the entry-to-landing spacing 2β·N/2π in a healthy unit;
* ``comb_peak_ratio`` [-] — second peak over the largest;
* ``comb_load_slope`` [-] — with a load cell and a load that varies: the relative growth of the
  amplitude profile's peak per relative growth of |load| (passages split at the median
  |load|), ≈ 0 for a load-independent impact, ≈ 1 for a strike proportional to the load.

Why the shape indicators read the energy profile and not the TSA: each impact rings the nut on
its threads (its axial mode: 5.6 kHz in the simulated paper03 at 20 kN, a period of 0.18 ms),
and the TSA keeps that ring only while the impacts stay locked to the passage phase within a
fraction of its period. Under a steady load they do (≈ 96 % of the measured power is
synchronous once the start has settled); under a load that varies they do not — the roller's
place in its clearance moves the instant the chamfer meets it — and the TSA cancels (simulated, 20 kN sine through zero: the
synchronous share falls to ≈ 0 and the TSA's envelope peak *fell* with the load, slope ≈ −0.8,
where the pulses themselves do not). The energy profile does not depend on the ring's phase: it
keeps the pulses' places and sizes under any load, and it is the natural object for "the share
of the energy outside the window".

What the simulations show (``tools/studies/reset_comb_indicators.py``, paper03, 40π rad/s,
20 kN): the comb is in every unit (``comb_rms`` 900–1400 m/s², ≈ 360 through flight-ema's
±50 g accelerometer, which the resets' ringing saturates; ``comb_sync_share`` ≈ 0.96), and a
healthy unit's shape indicators lie in a narrow band set by its clearance
(``comb_outside_share`` 0.15–0.19 over 3–10 µm unclipped). A nut-flank spall moves them off
that band **either way** — its strike lands on the ring the last reset left, adding to it or
cancelling it by their relative phase — so they separate a spall as a distance from the
healthy band, not as a higher value. And the model's healthy comb grows with the load (the
roller leaving the threads at the sector's entry drops its share of the load onto the others):
``comb_load_slope`` reads 0.25–0.8 for a healthy unit, not 0 (≈ 0.05 through the saturating
accelerometer, whose peaks are its range).

A window that cannot support them (a standard PRSM: no resets; fewer than
:data:`MIN_PASSAGES` whole passages; a screw that stops or turns back; a passage rate whose
first :data:`RESOLVED_HARMONICS` harmonics do not fit in the recording's band) leaves them NaN.

References
----------
Paper 03, eqs. 9–11 (the threadless sector and the crossing). P. D. McFadden, "A revised
model for the extraction of periodic waveforms by time domain averaging", Mechanical Systems
and Signal Processing 1(1) (1987) 83–95 — the synchronous average; what is not synchronous is
reduced as 1/n in power. P. D. McFadden, M. M. Toozhy, "Application of synchronous averaging
to vibration monitoring of rolling element bearings", Mechanical Systems and Signal Processing
14(6) (2000) 891–906 — the synchronous average of the squared envelope (the energy profile).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import PRSMHealthError
from prsm_health.physics.recirculating import orbital_angle

from .angle_domain import periodic_snr, prsm_periods, synchronous_average
from .spectra import hilbert_envelope

#: The indicators and their units, in the feature table's order.
RESET_COMB = {
    "comb_rms": "m/s²",
    "comb_sync_share": "-",
    "comb_outside_share": "-",
    "comb_doublet_spacing": "-",
    "comb_peak_ratio": "-",
    "comb_load_slope": "-",
}
#: Fewest whole roller passages a window averages (NaN below): the TSA of n passages keeps
#: 1/n of the non-synchronous power, so 8 keep ≤ 12.5 % of it in the average.
MIN_PASSAGES = 8
#: Ringing after the sector's passage counted in the reset window [share of the period]: the
#: impacts ring the nut on its threads after the roller has left the sector (simulated paper03
#: at 40π rad/s, 20 kN: a 5.6 kHz ring whose RMS halves in ≈ 4 ms, 0.4 of the 10.3 ms
#: period); a quarter of the period takes the loud start of that ring, and the window (0.44 of
#: the period for paper03) stays under half of it, so a strike opposite the resets is outside.
RINGING_SHARE = 0.25
#: Harmonics of the passage rate N·f_c the averages must resolve (the window's band must hold them,
#: NaN otherwise): features of 1/20 of the period, half the doublet's smallest spacing
#: (:data:`MIN_SEPARATION`) — the entry and the landing 0.19 of the period apart for paper03.
RESOLVED_HARMONICS = 20
#: A roller passage rate [Hz] to size the group's sample rate by (the indicator table's
#: ``min_rate``): paper03 at paper 03's 40π rad/s passes 97 Hz.
REFERENCE_PASSAGE_RATE = 100.0
#: Width of the circular moving average on the energy profile [share of the period]: smooths
#: the ring's beat without merging the entry and the landing (0.19 apart).
SMOOTHING_SHARE = 0.03
#: Least circular distance from the amplitude profile's largest peak to the second one [share
#: of the period]: the largest pulse's own ringing shoulder is not a second pulse.
MIN_SEPARATION = 0.1
#: Least relative spread of |load| between the passages of high and low load, (|F|_high −
#: |F|_low)/mean|F|, for ``comb_load_slope`` (NaN below): the slope divides the peaks' relative
#: change by it, so a quarter keeps the slope's scatter within 4× the peaks' (a commanded load
#: held steady spreads by its noise, ≪ 0.25; a load sine through zero by ≈ 1).
MIN_LOAD_SPREAD = 0.25


@dataclass(frozen=True)
class CombAverage:
    """The passages' synchronous averages of one window, from the window's first angle (an
    arbitrary phase), on ``bins`` points per passage period.

    Attributes
    ----------
    average : ndarray (bins,) [m/s²]
        TSA of the mean-removed nut acceleration.
    periods : ndarray (n, bins) [m/s²]
        Every whole passage's resampled acceleration.
    power : ndarray (n, bins) [(m/s²)²]
        Every whole passage's instantaneous power (squared Hilbert envelope of the window).
    loads : ndarray (n,) or None [N]
        Mean |axial load| of each passage (None without a load channel).
    """

    average: np.ndarray
    periods: np.ndarray
    power: np.ndarray
    loads: np.ndarray | None

    @property
    def n_passages(self) -> int:
        return int(self.periods.shape[0])


def passage_period(design: PRSMDesign) -> float:
    """The roller-passage period in radians of screw angle, 2π/(N·|ω_c/ω_s|) [rad]: every
    roller crosses the sector once per carrier revolution (paper 03, eqs. 9–11)."""
    return prsm_periods(design)["nut_pass"]


def reset_window_share(design: PRSMDesign) -> float:
    """Width of the reset window [share of the passage period]: the sector's passage, 2β of
    the 2π/N between rollers (paper 03, eq. 11's β), plus :data:`RINGING_SHARE`; at most 1."""
    sector = 2.0 * orbital_angle(design) * design.n_rollers / (2.0 * math.pi)
    return min(1.0, sector + RINGING_SHARE)


def comb_average(
    accel: np.ndarray,
    screw_angle: np.ndarray,
    design: PRSMDesign,
    load: np.ndarray | None = None,
) -> CombAverage | None:
    """The passages' synchronous averages (McFadden 1987) of a window: the mean-removed nut
    acceleration [m/s²], its instantaneous power (squared Hilbert envelope, [(m/s²)²]) and,
    when ``load`` [N] is given, |load|, over the passage period of the measured screw angle
    [rad] — resampled period by period on one grid point per recorded sample at the window's
    mean speed, anti-aliased (:func:`~prsm_health.signals.angle_domain.synchronous_average`):
    206 points per passage for paper03 at 40π rad/s and 20 kHz, so the ring of the nut's
    axial mode (5.6 kHz simulated) stays inside the grid's band (128 points would put its
    Nyquist at 6.2 kHz, the anti-alias filter already down there). Every point of every
    passage is interpolated from the recording: no bin is ever empty. None when the screw
    stops or turns back in the window (no angle domain)."""
    x = np.asarray(accel, float)
    x = x - np.mean(x)
    rows = [x, hilbert_envelope(x) ** 2]
    if load is not None:
        rows.append(np.abs(np.asarray(load, float)))
    rows = np.stack(rows)
    try:
        found = synchronous_average(rows, screw_angle, passage_period(design))
    except PRSMHealthError:
        if np.all(np.isfinite(screw_angle)) and np.all(np.isfinite(rows)):
            return None  # the speed is not one-signed
        raise
    loads = None if load is None else np.mean(found.periods[2], axis=-1)
    return CombAverage(found.average[0], found.periods[0], found.periods[1], loads)


def energy_profile(power: np.ndarray) -> np.ndarray:
    """The mean instantaneous power by passage phase [(m/s²)²] of passages (n, bins) [(m/s²)²],
    smoothed by a circular moving average over :data:`SMOOTHING_SHARE` of the period."""
    size = max(1, round(SMOOTHING_SHARE * power.shape[-1]))
    return uniform_filter1d(np.mean(power, axis=0), size, mode="wrap")


def outside_share(energy: np.ndarray, width: float) -> float:
    """Share of an energy profile's sum (bins,) [any unit] outside the circular window of
    ``width`` [share of the period] that holds the most of it [-] (the window tried at every
    bin: invariant to the profile's phase)."""
    energy = np.asarray(energy, float)
    total = float(np.sum(energy))
    if not total > 0:
        return math.nan
    n = len(energy)
    span = min(n, max(1, round(width * n)))
    cumulative = np.concatenate(([0.0], np.cumsum(np.concatenate([energy, energy]))))
    held = cumulative[span : span + n] - cumulative[:n]  # the window starting at each bin
    return max(0.0, 1.0 - float(np.max(held)) / total)


def doublet(profile: np.ndarray) -> tuple[float, float]:
    """(spacing [share of the period, 0–0.5], second peak / largest [-]) of a periodic
    amplitude profile (bins,): the second peak is the largest local maximum at least
    :data:`MIN_SEPARATION` (circularly) from the profile's maximum. (NaN, 0) when there is
    none (a single pulse), (NaN, NaN) for a profile without energy."""
    n = len(profile)
    first = int(np.argmax(profile))
    top = float(profile[first])
    if not top > 0:
        return math.nan, math.nan
    local = (profile >= np.roll(profile, 1)) & (profile > np.roll(profile, -1))
    distance = np.abs(np.arange(n) - first) / n
    distance = np.minimum(distance, 1.0 - distance)
    candidates = np.flatnonzero(local & (distance >= MIN_SEPARATION))
    if len(candidates) == 0:
        return math.nan, 0.0
    second = candidates[int(np.argmax(profile[candidates]))]
    return float(distance[second]), float(profile[second]) / top


def load_slope(power: np.ndarray, loads: np.ndarray) -> float:
    """Relative growth of the comb's peak per relative growth of |load| [-]: the passages'
    power (n, bins) [(m/s²)²] split at the median of their mean |load| ``loads`` (n,) [N], the
    peak amplitude of each half (√ of its :func:`energy_profile`'s maximum, [m/s²]),
    ((peak_high − peak_low)/mean peak) / ((|F|_high − |F|_low)/mean |F|): 0 for a pulse that
    does not feel the load, 1 for one proportional to it. NaN when |load| spreads by less
    than :data:`MIN_LOAD_SPREAD` between the halves."""
    order = np.argsort(loads, kind="stable")
    half = len(order) // 2
    if half < 2:
        return math.nan
    low, high = order[:half], order[-half:]  # an odd count leaves the median passage out
    f_low, f_high = float(np.mean(loads[low])), float(np.mean(loads[high]))
    f_mean = 0.5 * (f_low + f_high)
    if not (f_mean > 0 and (f_high - f_low) / f_mean >= MIN_LOAD_SPREAD):
        return math.nan
    p_low = math.sqrt(float(np.max(energy_profile(power[low]))))
    p_high = math.sqrt(float(np.max(energy_profile(power[high]))))
    p_mean = 0.5 * (p_low + p_high)
    if not p_mean > 0:
        return math.nan
    return ((p_high - p_low) / p_mean) / ((f_high - f_low) / f_mean)


def reset_comb_indicators(
    channels: dict[str, np.ndarray], design: PRSMDesign | None, band_share: float
) -> dict[str, float]:
    """:data:`RESET_COMB` of one window (see the module docstring), NaN where it cannot
    support them.

    Parameters
    ----------
    channels : dict of name → ndarray
        The window's measured channels: ``nut_axial_accel`` [m/s²] and ``screw_angle`` [rad]
        needed, ``axial_load`` [N] read when present (``comb_load_slope``).
    design : PRSMDesign or None
        A standard design (or none) has no resets: all NaN.
    band_share : float [-]
        Top of the recording's usable band as a share of its sample rate (below the
        anti-alias roll-off): the first :data:`RESOLVED_HARMONICS` harmonics of the window's
        mean passage rate must lie below it.
    """
    out = dict.fromkeys(RESET_COMB, math.nan)
    if design is None or design.variant != "recirculating":
        return out
    if "nut_axial_accel" not in channels or "screw_angle" not in channels:
        return out
    angle = np.asarray(channels["screw_angle"], float)
    if len(angle) < 2:
        return out
    # passages per sample: the passage rate over the sample rate
    per_sample = abs(float(angle[-1] - angle[0])) / passage_period(design) / (len(angle) - 1)
    if not 0 < RESOLVED_HARMONICS * per_sample <= band_share:
        return out
    found = comb_average(channels["nut_axial_accel"], angle, design, channels.get("axial_load"))
    if found is None or found.n_passages < MIN_PASSAGES:
        return out
    return _indicators(found, design, out)


def _indicators(found: CombAverage, design: PRSMDesign, out: dict) -> dict[str, float]:
    """The indicators of a window's :class:`CombAverage` into ``out``."""
    n, bins = found.periods.shape
    out["comb_rms"] = math.sqrt(float(np.var(found.average)))
    # the synchronous power over the whole, from the average's debiased SNR (periodic_snr:
    # E_p/σ̂² less the noise the average still holds, McFadden 1987): the whole is
    # E_p + σ̂²·(n − 1)/n, so the share is SNR/(SNR + 1 − 1/(bins·n)) — 1 without a residual
    snr = periodic_snr(found.periods)
    if snr == math.inf:
        out["comb_sync_share"] = 1.0
    elif math.isfinite(snr):
        out["comb_sync_share"] = max(0.0, snr) / (snr + 1.0 - 1.0 / (bins * n))
    energy = energy_profile(found.power)
    out["comb_outside_share"] = outside_share(energy, reset_window_share(design))
    amplitude = np.sqrt(np.maximum(energy, 0.0))  # the moving average may round below 0
    out["comb_doublet_spacing"], out["comb_peak_ratio"] = doublet(amplitude)
    if found.loads is not None:
        out["comb_load_slope"] = load_slope(found.power, found.loads)
    return out
