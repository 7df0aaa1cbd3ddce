"""The nut's axial contact mode: its predicted band and its frequency tracked in a signal.

Paper 01 §3.3 reports that the nut's axial frequency falls as the thread clearance grows. The
mode that falls is the *contact mode*: the nut (with the payload on its linkage) vibrating on the
thread contacts, whose stiffness the clearance takes away over part of a reversing load's cycle.
It is not always the largest peak of the nut's axial acceleration: the nut–payload mode (nut
against payload on the linkage, ≈ 2× higher) and the contact mode's own harmonics (the rattle
across the gap is far from sinusoidal) can outgrow it. So it is tracked inside the band where
the physics puts it for the unit's loads and clearances:

* :func:`contact_mode_frequency` — the mode of the simulator's model linearised on the loaded
  flanks (:func:`prsm_health.simulation.dynamics.modes.nut_modes`, flanks at paper
  04's tangent stiffness at the load) whose frequency depends most on the thread stiffness,
  among the modes a force on the nut makes the nut's acceleration respond to;
* :func:`gap_frequency_ratio` — the free frequency of an impact pair (a mass between two
  springs with a dead zone 2b) against the frequency without the gap;
* :func:`rattle_amplitude` — the contact vibration amplitude a reversal leaves: the nut pushed
  across the gap by the reversing load strikes the other flank at the speed the load gave it;
* :func:`contact_band` — the band the contact mode lies in for a range of load swings and
  clearances: from the softest case (lightest swing, slowest reversal, largest clearance: the
  rattle slows the mode most) to the stiffest (heaviest load, contacts closed);
* :func:`contact_frequency` — the frequency of the contact mode in a signal: the
  power-weighted mean frequency of the peak it makes in the Welch PSD inside the band
  (:func:`band_mean_frequency`).

References
----------
Paper 01 §3.3 (clearance and the nut axial frequency); paper 04 (thread axial stiffness, Hertz
contact k_H = dQ/dδ_H); S. W. Shaw, P. J. Holmes, "A periodically forced piecewise linear
oscillator", J. Sound Vib. 90 (1983) 129–155 (piecewise-linear oscillators); R. J. Comparin,
R. Singh, "Non-linear frequency response characteristics of an impact pair", J. Sound Vib. 134
(1989) 259–290 (the free frequency of an impact pair falls with its clearance).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import asdict, replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import scipy
from scipy.ndimage import uniform_filter1d

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.core.disk_cache import cached_float
from prsm_health.core.errors import require
from prsm_health.physics.load_rating import load_ratings

from .spectra import welch_psd

#: Modes considered structural [Hz]: below, the drive train's rigid-body and torsional modes;
#: above, the rollers' local contact modes (15–30 kHz) and the accelerometer's band edge.
MODE_RANGE = (30.0, 3000.0)
#: A mode counts as seen on the nut when its peak accelerance (nut acceleration per force on the
#: nut) is at least this share of the largest mode's.
VISIBLE_SHARE = 0.1
#: Relative step of the thread contact law's coefficient for the modes' thread sensitivity.
SENSITIVITY_STEP = 0.2
#: Margin of the band on each side, relative: the linearised frequency against the simulated
#: peak under load (≈ 2 % apart; 100 → 1 rad/s moves it +3 %), and the gap model (one impact
#: of one amplitude) against a real rattle of decaying impacts.
BAND_MARGIN = 0.1
#: The flight-EMA duty the indicator's band is made for (:func:`duty_band`), as shares of the
#: design's basic dynamic axial load rating C_a: load swings of 2–30 % C_a about a mean of
#: ±5 % C_a, so the contacts carry up to 35 % C_a (datasets/flight-ema-reference.toml; EMAs run
#: at roughly 10–40 % of C_a, docs/formats.md → Loads).
DUTY_LOAD_SHARES = (0.02, 0.35)
#: The half-clearances b a unit may have in service [m]: new (0) to beyond severe wear
#: (30 µm, docs/faults.md), the range the shipped model is trained on.
DUTY_CLEARANCES = (0.0, 40e-6)
#: The slowest load reversal of the duty [s] (the reference recipe's ramps: 1–20 ms).
DUTY_RAMP_TIME = 0.02
#: Payload masses [kg] and linkage stiffnesses [N/m] a flight EMA's drive train may have when
#: the recording does not say (the reference recipe's spread, datasets/flight-ema-reference.toml:
#: the default drive train's 10 kg and 5e7 N/m inside).
DUTY_PAYLOADS = (5.0, 20.0)
DUTY_LINKAGES = (2e7, 1e8)
#: Loads of the closed-contact reference between which :func:`reference_frequency`
#: interpolates: half-octave steps of this ratio.
REFERENCE_STEP = math.sqrt(2.0)
#: Welch segment of the tracking [s] (rounded to a power of two of samples: 1024 at 20 kHz,
#: 19.5 Hz bins), 75 % overlap.
SEGMENT = 0.05
#: Moving average of the PSD over frequency before the peak is delimited [Hz]: wider than the
#: comb of the reversal rate (8–32 Hz) that splits the mode into lines, narrower than the band.
SMOOTHING = 80.0
#: The peak's extent: from the largest smoothed bin in the band, down each flank while the
#: smoothed PSD falls and stays at or above this share of it (−13 dB). Segment, smoothing and
#: share were chosen on 60 random operating points of another draw than the study's
#: (tools/studies/axial_frequency_tracking.py): the half-power extent of the unsmoothed peak
#: fell with the clearance at 67 % of them, this one at 95 %.
PEAK_SHARE = 0.05


@lru_cache(maxsize=64)  # every window's reference asks for it; a DriveTrain checks 19 fields
def _loaded_drive_train(drive_train: DriveTrain | None) -> DriveTrain:
    # Linearised on loaded flanks: the reduction's backlash and the thrust bearing's play closed,
    # as the threads' clearances are. Left open, a light load leaves the reduction inside its
    # backlash in the linearisation and the screw's rotation (≈ 23 kg of axial inertia through
    # the lead of paper01) drops out of the nut's modes.
    dt = drive_train or DriveTrain()
    return replace(dt, gear_backlash=0.0, thrust_bearing_play=0.0)


@lru_cache(maxsize=1)
def _model_fingerprint() -> str:
    """Hash of the code the contact mode is computed by: this module and the layers that build
    the simulator's model (core, actuator, physics, simulation), with numpy's and scipy's
    versions (their eigensolvers)."""
    package = Path(__file__).resolve().parents[1]
    files = sorted(
        p
        for layer in ("core", "actuator", "physics", "simulation")
        for p in (package / layer).rglob("*.py")
    )
    digest = hashlib.sha256(f"numpy {np.__version__} scipy {scipy.__version__}".encode())
    for path in [*files, Path(__file__).resolve()]:
        digest.update(path.relative_to(package).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


@lru_cache(maxsize=512)
def _contact_mode(design: PRSMDesign, load: float, drive_train: DriveTrain) -> float:
    # Each mode takes ≈ 0.1–0.4 s (two linearisations) and a process's first window needs ten
    # (the duty band's corners, the reference): kept on disk, a new process (a CLI command, a
    # service's diagnosis process) reads them in milliseconds.
    key = {
        "design": asdict(design),
        "load": load,
        "drive_train": asdict(drive_train),
        "code": _model_fingerprint(),
    }
    return cached_float(
        "contact-mode", key, lambda: _computed_contact_mode(design, load, drive_train)
    )


def _computed_contact_mode(design: PRSMDesign, load: float, drive_train: DriveTrain) -> float:
    # imported here: the simulator's model loads numba, which reading a signal needs only now
    from prsm_health.simulation.dynamics.modes import nut_modes

    values, peak = nut_modes(design, load, drive_train)
    stiffer, _ = nut_modes(design, load, drive_train, 1.0 + SENSITIVITY_STEP)
    f = values.imag / (2 * math.pi)
    candidates = np.flatnonzero((f > MODE_RANGE[0]) & (f < MODE_RANGE[1]) & np.isfinite(peak))
    require(
        candidates.size > 0,
        "design",
        design.name,
        f"has no nut axial mode in {MODE_RANGE[0]:g}–{MODE_RANGE[1]:g} Hz",
    )
    visible = candidates[peak[candidates] >= VISIBLE_SHARE * np.max(peak[candidates])]
    # thread sensitivity d ln ω / d ln(law coefficient): the share of the mode's strain energy
    # in the thread contacts, the stiffness the clearance takes away
    sensitivity = [
        math.log(abs(stiffer[np.argmin(np.abs(stiffer - values[j]))]) / abs(values[j]))
        for j in visible
    ]
    return float(f[visible[int(np.argmax(sensitivity))]])


def contact_mode_frequency(
    design: PRSMDesign, load: float, drive_train: DriveTrain | None = None
) -> float:
    """Frequency [Hz] of the nut's axial contact mode with every thread contact closed.

    The model of the simulator (screw on its thrust bearing and drive, rollers, carrier, nut,
    payload on its linkage) linearised on the loaded flanks at the axial ``load``
    (:func:`~prsm_health.simulation.dynamics.modes.nut_modes`): the flanks at paper
    04's tangent stiffness there (the Hertzian load–deflection curve's slope), identical
    rollers, the reduction's backlash and the thrust bearing's play closed. Of the modes between :data:`MODE_RANGE` that a force on the nut makes
    the nut's acceleration respond to (peak accelerance ≥ :data:`VISIBLE_SHARE` of the largest),
    the one whose frequency rises most with the thread stiffness: the mode whose stiffness the
    clearance takes away.

    Parameters
    ----------
    design : PRSMDesign
        A standard PRSM with gears (the dynamic model's).
    load : float [N]
        Axial load the contacts carry (its magnitude; at least 1 N).
    drive_train : DriveTrain, default DriveTrain()

    Returns
    -------
    float [Hz]

    Notes
    -----
    For paper01 with the default drive train: 185 Hz at 20 N, 214 Hz at 300 N, 229 Hz at
    3 kN (the Hertz stiffness k ∝ F^(1/3) rises with the load; the thrust bearing, the screw's
    rotation through its drive and the linkage are in series with it, so the mode rises less);
    the nut–payload mode at ≈ 465 Hz is the larger peak of the nut's accelerance but hardly
    depends on the threads. With ``DriveTrain.paper01()`` (screw held, force on the nut) it is
    the nut on its threads alone, ≈ √(k_axial/m_N)/2π.

    References
    ----------
    Paper 01 §3.3 (the nut axial frequency); paper 04 (the thread stiffness, Hertz contact
    k_H = dQ/dδ_H).
    """
    require(
        isinstance(load, (int, float)) and math.isfinite(load), "load", load, "must be a number"
    )
    load = max(abs(float(load)), 1.0)
    # memoised on a rounded load (4 significant digits): the windows of a recording ask for the
    # same few loads
    load = float(f"{load:.4g}")
    return _contact_mode(design, load, _loaded_drive_train(drive_train))


def gap_frequency_ratio(clearance, amplitude):
    """Free frequency of an impact pair over the frequency without clearance [-].

    A mass oscillating between two linear springs (frequency f_c each while in contact) with a
    dead zone 2b between them, striking each with penetration amplitude a (the vibration
    amplitude in contact): each contact lasts half a period, π/ω_c, and each flight across the
    gap 2b at the impact speed ω_c·a lasts 2b/(ω_c·a). One cycle, two contacts and two flights:

        T = 2π/ω_c + 4b/(ω_c·a),   f/f_c = 1 / (1 + 2b/(π·a)).

    Parameters
    ----------
    clearance : float or array_like [m]
        Half-clearance b (total play 2b), ≥ 0.
    amplitude : float or array_like [m]
        Penetration amplitude a in contact, > 0.

    Returns
    -------
    float or ndarray [-], in (0, 1]; 1 at b = 0.

    References
    ----------
    Comparin & Singh (1989), the impact pair's free frequency; Shaw & Holmes (1983),
    piecewise-linear oscillators; paper 01 §3.3 (the frequency falls with b).
    """
    b = np.asarray(clearance, float)
    a = np.asarray(amplitude, float)
    require(bool(np.all(b >= 0)), "clearance", clearance, "must be ≥ 0 [m]")
    require(bool(np.all(a > 0)), "amplitude", amplitude, "must be > 0 [m]")
    ratio = 1.0 / (1.0 + 2.0 * b / (math.pi * a))
    return float(ratio) if ratio.ndim == 0 else ratio


def gap_crossing(clearance: float, swing: float, ramp_time: float, mass: float):
    """Time [s], speed [m/s] and load [N] at which a reversing load has carried the nut across
    the thread gap 2b.

    The load reverses from +F to −F along a straight ramp of ``ramp_time`` (rate Ḟ = 2F/t_r);
    from its zero crossing the nut, free in the gap, is pushed by F(t) = Ḟ·t, then by F once
    the ramp ends: x(t) = Ḟt³/6m until t_r/2, then uniformly accelerated; it strikes the other
    flank at x = 2b.

    Parameters
    ----------
    clearance : float [m]
        Half-clearance b, ≥ 0.
    swing : float [N]
        Load amplitude F the load reverses between (±F about zero), > 0.
    ramp_time : float [s]
        Duration of the reversal t_r (0: a step).
    mass : float [kg]
        Mass the load moves across the gap (nut plus payload on a stiff linkage).

    Returns
    -------
    (t [s], v [m/s], load at the impact [N])
    """
    require(clearance >= 0, "clearance", clearance, "must be ≥ 0 [m]")
    require(swing > 0, "swing", swing, "must be > 0 [N]")
    require(mass > 0, "mass", mass, "must be > 0 [kg]")
    require(ramp_time >= 0, "ramp_time", ramp_time, "must be ≥ 0 [s]")
    gap = 2.0 * clearance
    half = 0.5 * ramp_time
    if half > 0:
        rate = swing / half
        t = (6.0 * mass * gap / rate) ** (1.0 / 3.0)
        if t <= half:
            return t, rate * t * t / (2.0 * mass), rate * t
        x0, v0 = rate * half**3 / (6.0 * mass), rate * half**2 / (2.0 * mass)
    else:
        x0 = v0 = 0.0
    # after the ramp: x0 + v0·τ + F/2m·τ² = 2b
    acc = swing / mass
    tau = (-v0 + math.sqrt(v0 * v0 + 2.0 * acc * (gap - x0))) / acc
    return half + tau, v0 + acc * tau, swing


def rattle_amplitude(
    clearance: float, swing: float, ramp_time: float, mass: float, frequency: float
) -> float:
    """Penetration amplitude [m] the impact after a load reversal leaves: a = v/ω_c.

    The nut strikes the other flank at the speed v of :func:`gap_crossing` and rebounds in
    contact at ω_c = 2π·``frequency`` [Hz] (the contact mode's).

    References
    ----------
    Paper 01 §3.3; Comparin & Singh (1989) (impact pair).
    """
    require(frequency > 0, "frequency", frequency, "must be > 0 [Hz]")
    if clearance <= 0:
        return math.inf
    _, speed, _ = gap_crossing(clearance, swing, ramp_time, mass)
    return speed / (2 * math.pi * frequency)


def moving_mass(design: PRSMDesign, drive_train: DriveTrain | None = None) -> float:
    """Mass [kg] the axial load carries across the thread gap: the nut, plus the payload when
    the load acts on it through the linkage."""
    dt = drive_train or DriveTrain()
    payload = dt.payload_mass if dt.load_application == "payload" else 0.0
    return design.masses.nut_mass + payload


def contact_band(
    design: PRSMDesign,
    loads: tuple[float, float],
    clearances: tuple[float, float],
    *,
    drive_train: DriveTrain | None = None,
    ramp_time: float = 0.02,
    margin: float = BAND_MARGIN,
) -> tuple[float, float]:
    """Band [Hz] the nut's axial contact mode lies in under reversing loads.

    Upper edge: the stiffest case, every contact closed at the heaviest load —
    :func:`contact_mode_frequency` at ``loads[1]``; no clearance raises it. Lower edge: the
    softest case, the lightest swing ``loads[0]`` reversing over ``ramp_time`` across the largest
    clearance ``clearances[1]``: the nut strikes at the load of :func:`gap_crossing`, where the
    contact mode is :func:`contact_mode_frequency` of that load, and rattles with the
    amplitude of :func:`rattle_amplitude`, which slows it by :func:`gap_frequency_ratio`:

        f_lo = f_c(F*) / (1 + 2b_max/(π·a)),   a = v*/(2π f_c(F*)),
        f_hi = f_c(F_max),

    widened by ``margin`` on each side.

    Parameters
    ----------
    design : PRSMDesign
    loads : (float, float) [N]
        Lightest and heaviest load amplitudes the unit reverses between (±F about zero; the
        heaviest may include the mean load: the largest load the contacts carry).
    clearances : (float, float) [m]
        Range of the half-clearance b the unit may have (only the largest sets the band).
    drive_train : DriveTrain, default DriveTrain()
    ramp_time : float [s]
        The slowest reversal of the duty (a slower reversal strikes more gently, rattles with a
        smaller amplitude and slows the mode more).
    margin : float [-]
        Relative widening of each edge (:data:`BAND_MARGIN`).

    Returns
    -------
    (f_lo, f_hi) [Hz]

    Notes
    -----
    The gap model is one impact of one amplitude; the spectrum of a run mixes the ringing at
    every load of the cycle, so the tracked frequency lies well inside the band (paper01,
    default drive train, 10 ms ramps, b = 10–30 µm: 150–226 Hz tracked at random points of
    the flight-EMA duty, whose band is 85–252 Hz). At ``clearances[1] = 0`` the band is the
    contact modes between the two loads, and with ``DriveTrain.paper01()`` the upper edge is
    close to √(k_axial/m_N)/2π at the load (5 % below).

    References
    ----------
    Paper 01 §3.3; paper 04 (Hertzian thread stiffness); Comparin & Singh (1989) (impact pair).
    """
    lo, hi = (float(v) for v in loads)
    b_lo, b_hi = (float(v) for v in clearances)
    require(
        0 < lo <= hi,
        "loads",
        loads,
        "must be (lightest, heaviest) with 0 < lightest ≤ heaviest [N]",
    )
    require(0 <= b_lo <= b_hi, "clearances", clearances, "must be (smallest, largest) ≥ 0 [m]")
    require(0 <= margin < 1, "margin", margin, "must lie in [0, 1)")
    f_hi = contact_mode_frequency(design, hi, drive_train)
    if b_hi > 0:
        mass = moving_mass(design, drive_train)
        _, _, strike = gap_crossing(b_hi, lo, ramp_time, mass)
        f_strike = contact_mode_frequency(design, min(strike, hi), drive_train)
        amplitude = rattle_amplitude(b_hi, lo, ramp_time, mass, f_strike)
        f_lo = f_strike * gap_frequency_ratio(b_hi, amplitude)
    else:
        f_lo = contact_mode_frequency(design, lo, drive_train)
    return (1.0 - margin) * min(f_lo, f_hi), (1.0 + margin) * f_hi


@lru_cache(maxsize=32)
def _duty_band(design: PRSMDesign, drive_train: DriveTrain) -> tuple[float, float]:
    rating = load_ratings(design).dynamic
    loads = (DUTY_LOAD_SHARES[0] * rating, DUTY_LOAD_SHARES[1] * rating)
    return contact_band(
        design, loads, DUTY_CLEARANCES, drive_train=drive_train, ramp_time=DUTY_RAMP_TIME
    )


def duty_band(design: PRSMDesign, drive_train: DriveTrain | None = None) -> tuple[float, float]:
    """:func:`contact_band` [Hz] of a unit in flight-EMA service: load swings of
    :data:`DUTY_LOAD_SHARES` of C_a reversing in up to :data:`DUTY_RAMP_TIME`, clearances of
    :data:`DUTY_CLEARANCES`. One band per design and drive train (memoised), so the tracked
    frequency of every window of a unit is read in the same band.

    Parameters
    ----------
    design : PRSMDesign
    drive_train : DriveTrain or None
        The unit's drive train. None (not known, as for a recording): the union of the bands
        of the default drive train with its payload and linkage at the corners of
        :data:`DUTY_PAYLOADS` × :data:`DUTY_LINKAGES` — the payload and linkage move the
        contact mode more than the load does.

    Returns
    -------
    (f_lo, f_hi) [Hz] — paper01: ≈ (85, 252) Hz with the default drive train, ≈ (75, 382) Hz
    not knowing it.

    References
    ----------
    Paper 01 §3.3; ISO 3408-5 (C_a, via :mod:`prsm_health.physics.load_rating`).
    """
    if drive_train is not None:
        return _duty_band(design, drive_train)
    return _unknown_duty_band(design)


@lru_cache(maxsize=32)
def _unknown_duty_band(design: PRSMDesign) -> tuple[float, float]:
    # once per design: its five drive trains cost more than tracking the mode in a window
    default = DriveTrain()
    bands = [
        _duty_band(design, replace(default, payload_mass=m, linkage_stiffness=k))
        for m in DUTY_PAYLOADS
        for k in DUTY_LINKAGES
    ]
    return min(lo for lo, _ in bands), max(hi for _, hi in bands)


def reference_frequency(
    design: PRSMDesign, load: float | None = None, drive_train: DriveTrain | None = None
) -> float:
    """Contact mode [Hz] with every contact closed at a load: the healthy reference of the
    tracked frequency.

    :func:`contact_mode_frequency` interpolated in log load between loads a half octave apart
    (:data:`REFERENCE_STEP` from C_a), so the windows of a recording with a load cell, each
    at its own load, share a few linearisations (the mode changes by < 1 % per half octave above
    100 N for paper01).

    Parameters
    ----------
    design : PRSMDesign
    load : float or None [N]
        The load the contacts carry at the peak of the window; None: the default duty's mean
        load, :data:`~prsm_health.actuator.states.DEFAULT_LOAD_SHARE` of C_a.
    drive_train : DriveTrain, default DriveTrain()

    Returns
    -------
    float [Hz]

    References
    ----------
    Paper 01 §3.3; paper 04 (Hertzian thread stiffness).
    """
    from prsm_health.actuator.states import DEFAULT_LOAD_SHARE

    rating = load_ratings(design).dynamic
    if load is None or not math.isfinite(load):
        load = DEFAULT_LOAD_SHARE * rating
    steps = math.log(max(abs(load), 1.0) / rating) / math.log(REFERENCE_STEP)
    lower = math.floor(steps)
    nodes = [
        contact_mode_frequency(design, rating * REFERENCE_STEP**k, drive_train)
        for k in (lower, lower + 1)
    ]
    return nodes[0] + (steps - lower) * (nodes[1] - nodes[0])


def contact_frequency(
    x: np.ndarray,
    sample_rate: float,
    band: tuple[float, float],
    *,
    segment: float = SEGMENT,
) -> float | np.ndarray:
    """Frequency [Hz] of the nut's axial contact mode in an acceleration signal.

    The power-weighted mean frequency of the peak the mode makes in the Welch PSD inside
    ``band`` (:func:`band_mean_frequency`).

    Parameters
    ----------
    x : ndarray (..., n)
        Nut axial acceleration (any unit; each segment's mean is removed); leading axes are
        windows.
    sample_rate : float [Hz]
    band : (float, float) [Hz]
        Where the contact mode lies (:func:`contact_band`).
    segment : float [s]
        Welch segment (Hann, 75 % overlap), rounded to a power of two of samples and to no
        more than the signal.

    Returns
    -------
    float [Hz] (ndarray of the leading shape for several signals)

    References
    ----------
    Paper 01 §3.3 (the nut axial frequency); Welch (1967) (the PSD).
    """
    x = np.asarray(x, float)
    require(sample_rate > 0, "sample_rate", sample_rate, "must be > 0 [Hz]")
    nperseg = tracking_segment(x.shape[-1], sample_rate, segment)
    f, psd = welch_psd(x, sample_rate, nperseg, 3 * nperseg // 4)
    return band_mean_frequency(f, psd, band)


def contact_indicators(
    x: np.ndarray,
    sample_rate: float,
    design: PRSMDesign,
    windows: list[dict],
    drive_train: DriveTrain | None = None,
    *,
    welch: tuple[np.ndarray, np.ndarray] | None = None,
) -> list[dict[str, float]]:
    """The contact-mode indicators of windows of nut axial acceleration.

    ``axial_contact_frequency`` [Hz]: :func:`contact_frequency` in the unit's
    :func:`duty_band`; ``axial_contact_frequency_shift`` [Hz]: it minus
    :func:`reference_frequency` at the window's peak load |mean| + range/2 (the default duty's
    load without a load cell; the default drive train's when none is given). NaN for a design
    the dynamic model does not cover (no gears, recirculating).

    Parameters
    ----------
    x : ndarray (windows, n)
        Mean-removed nut axial acceleration [m/s²].
    sample_rate : float [Hz]
    design : PRSMDesign
    windows : list of dict
        Each window's indicators so far: its ``load_mean`` and ``load_range`` [N] are read
        (NaN without a load cell).
    drive_train : DriveTrain or None
        The unit's, when known (None: the band covers the drive trains of :func:`duty_band`).
    welch : (frequencies [Hz], PSD (windows, bins)) or None
        The Welch spectra of ``x`` at the tracking segment (:func:`tracking_segment`, Hann,
        75 % overlap, as :func:`prsm_health.signals.spectra.welch_psd` gives them), when the
        caller has them; None: computed here.

    Returns
    -------
    list of dict, one per window

    References
    ----------
    Paper 01 §3.3 (the shifted axial frequency).
    """
    names = ("axial_contact_frequency", "axial_contact_frequency_shift")
    if design.gear is None or design.variant == "recirculating":
        return [dict.fromkeys(names, np.nan) for _ in windows]
    band = duty_band(design, drive_train)
    if welch is None:
        tracked = np.atleast_1d(contact_frequency(x, sample_rate, band))
    else:
        tracked = np.atleast_1d(band_mean_frequency(*welch, band))
    out = []
    for value, window in zip(tracked, windows):
        peak = abs(window.get("load_mean", np.nan)) + 0.5 * window.get("load_range", np.nan)
        load = peak if math.isfinite(peak) else None
        reference = reference_frequency(design, load, drive_train)
        out.append(dict(zip(names, (float(value), float(value) - reference))))
    return out


def tracking_segment(n: int, sample_rate: float, segment: float = SEGMENT) -> int:
    """Welch segment [samples] of the tracking: ``segment`` seconds rounded to a power of two,
    at most ``n``."""
    return int(min(n, 2 ** round(math.log2(max(segment * sample_rate, 16.0)))))


def band_mean_frequency(
    f: np.ndarray,
    psd: np.ndarray,
    band: tuple[float, float],
    *,
    share: float = PEAK_SHARE,
    smoothing: float = SMOOTHING,
) -> float | np.ndarray:
    """Power-weighted mean frequency [Hz] of the peak a PSD makes inside a band.

    The PSD is smoothed over ``smoothing`` Hz (a moving average). From its largest bin inside
    ``band``, the peak extends down each flank while the smoothed PSD falls and stays at or
    above ``share`` of that bin, within the band (a valley ends it: beyond rises another mode's
    skirt); the result is the mean frequency of those bins weighted by the unsmoothed PSD — the
    first spectral moment of the peak.

    For one lightly damped resonance standing clear of its surroundings this is its frequency
    (biased upwards by a few per cent for an accelerance, whose skirt above the resonance is
    flat and below falls as f²). For the contact mode under load reversals, whose energy moves
    from the loaded ringing to the slower rattle across the gap as the clearance grows, it
    follows where the mode's power sits, continuously and with less scatter than the highest
    bin. NaN when the largest unsmoothed bin inside sits on the band's edge with the PSD still
    rising beyond it (no peak inside, only the skirt of a mode outside), or when the band holds
    fewer than three bins.

    Parameters
    ----------
    f : ndarray (m,) [Hz]
        Uniform frequencies of the PSD.
    psd : ndarray (..., m)
        One PSD per leading index.
    band : (float, float) [Hz]
    share : float [-]
        Lowest smoothed PSD, relative to the peak's, counted into the peak.
    smoothing : float [Hz]
        Width of the moving average (0 or less than a bin: none).

    Returns
    -------
    float [Hz] (ndarray of the leading shape for several PSDs)

    References
    ----------
    Paper 01 §3.3 (the nut axial frequency).
    """
    lo, hi = float(band[0]), float(band[1])
    require(0 <= lo < hi, "band", band, "must be (low, high) with 0 ≤ low < high [Hz]")
    require(0 < share < 1, "share", share, "must lie in (0, 1)")
    psd = np.asarray(psd, float)
    f = np.asarray(f, float)
    inside = np.flatnonzero((f >= lo) & (f <= hi))
    flat = psd.reshape(-1, psd.shape[-1])
    width = max(1, int(round(smoothing / (f[1] - f[0]))))
    smooth = uniform_filter1d(flat, width, axis=-1, mode="nearest") if width > 1 else flat
    out = np.full(len(flat), np.nan)
    if inside.size >= 3:
        first, last = int(inside[0]), int(inside[-1])
        for row, (p, raw) in enumerate(zip(smooth, flat)):
            k = first + int(np.argmax(p[first : last + 1]))
            # the unsmoothed PSD highest on an edge bin and still rising beyond it: the skirt of
            # a mode outside the band, none inside
            top = first + int(np.argmax(raw[first : last + 1]))
            beyond = (top == first and first > 0 and raw[first - 1] > raw[top]) or (
                top == last and last + 1 < len(raw) and raw[last + 1] > raw[top]
            )
            if beyond or not p[k] > 0:
                continue
            a = k
            while a > first and share * p[k] <= p[a - 1] <= p[a]:
                a -= 1
            b = k
            while b < last and share * p[k] <= p[b + 1] <= p[b]:
                b += 1
            weights = raw[a : b + 1]
            total = float(np.sum(weights))
            out[row] = float(np.dot(f[a : b + 1], weights) / total) if total > 0 else f[k]
    return float(out[0]) if psd.ndim == 1 else out.reshape(psd.shape[:-1])
