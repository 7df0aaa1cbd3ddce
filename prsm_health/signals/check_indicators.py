"""Indicators of a health-check recording, each read in the phase whose commanded condition
brings it out (docs/angle-domain.md).

A health check (:mod:`prsm_health.actuator.health_check`) drives the actuator through a few
conditions; each fault shows best under one of them. The phases are found by their
**condition** — motion, speed, load, as the check's record gives them (the controller
commands them, so a hardware recording has them too), else as measured — never by their name,
so a user-defined check is read the same way. Four roles:

* ``no_load`` — a constant-speed phase without load (|load| ≤ :data:`NO_LOAD_SHARE` of C_a):
  the preload alone holds the nut on its threads, so the nut's axial resonance on them — the
  spectral centroid of the nut axial acceleration, 200–3000 Hz — moves as the preload goes;
  its RMS with it.
* ``torque_pair`` — two constant phases under one load at different speeds: the ratio of the
  mean |drive torque| low/high speed grows as the lubricant degrades (the film thins at low
  entrainment speed), and needs neither a load cell nor the motor's torque constant. The
  check's mean housing temperature is given beside it: temperature thins the oil too, so a
  classifier can tell the two apart.
* ``reversal`` — a reversing phase under load: the lost motion (LVDT against the resolver,
  :func:`~prsm_health.signals.features.extract_features`) and the other reversal indicators
  of that phase.
* ``high_load`` — the constant phase with the largest |load|: the spalls, read in the angle
  domain (:mod:`prsm_health.signals.angle_domain`) on the nut axial acceleration band-passed
  to :data:`IMPACT_BAND`, the reduction's orders removed: synchronous-average SNRs at the nut
  pass, the roller spin, the carrier and the screw revolution, and of its squared envelope at
  the nut pass, the roller spin and the carrier (an impact train stays periodic in the
  envelope when the resonance it rings is not phase-locked); kurtosis, crest factor and RMS
  of that residual; the stroke-position profile (a screw spall); for a recirculating PRSM, the
  reset comb's shape (:mod:`prsm_health.signals.reset_comb`: a nut spall, a worn chamfer, a
  chipped re-entry edge move where the passage's energy sits).

:func:`check_indicators` returns every indicator of :data:`CHECK_INDICATORS`, NaN where the
check lacks the phase or the recording the channel, with the reason.

**Cut phases.** A recording can end early (a truncated file, a logger stopped): the check's
record says how long each phase was commanded, the samples how long it was recorded. A phase
with fewer samples than its settled part (:data:`BOUNDARY_SAMPLES` aside) is **cut** and not
read — the models were trained on whole phases, and a part of one reads differently (the lost
motion of one reversal instead of four; an average over fewer turns) — nor is a whole phase
shorter than its role needs (:func:`role_shortfall`). Its role is then in
:attr:`CheckReading.cut`, never in :attr:`CheckReading.roles`.

Measured on simulated checks (paper01, flight-ema, built-in ``health-check``, seeds 1–3;
:func:`measure_classes` prints the table, docs/angle-domain.md keeps it) — a summary:
the nut-pass SNR separates a nut spall, the roller-spin SNR a roller spall, the kurtosis (with
those two SNRs low) and the position contrast a screw spall, the no-load centroid a preloaded
nut from one with clearance and the lost motion an intact preload from a 60 % lost one, the
torque ratio a degraded lubricant. The position SNR does not separate the screw spall (its
sporadic impacts scatter the replicas of its bins as much as they raise the profile).

References
----------
See :mod:`prsm_health.signals.angle_domain` (order tracking, synchronous averages) and
:mod:`prsm_health.signals.features` (lost motion). Spectral centroid: the power-weighted mean
frequency of a Welch PSD (Welch 1967). Kurtosis of the residual after the discrete components
are removed: Randall & Antoni 2011 §3. Synchronous averages of the squared envelope:
P. D. McFadden, M. M. Toozhy, "Application of synchronous averaging to vibration monitoring of
rolling element bearings", Mechanical Systems and Signal Processing 14(6) (2000) 891–906;
the squared envelope of the band-passed signal: Randall & Antoni 2011 §2.2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.design_files import load_design
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings

from .angle_domain import (
    position_profile,
    prsm_periods,
    subtract_synchronous,
    synchronous_average_periods,
)
from .check_roles import (
    CENTROID_SEGMENT,
    NO_LOAD_SHARE,
    ROLES,
    PhaseCondition,
    is_number,
    measured_speed,
    phase_conditions,
    read_roles,
    role_shortfall,
)
from .features import extract_features, run_design
from .indicator_table import SEARCH_SHARE
from .lost_motion import lost_motion_step, settled_lost_motion_step, settled_samples
from .reset_comb import RESET_COMB, reset_comb_indicators
from .spectra import bandpass_rows, hilbert_envelope, welch_psd

#: Band of the no-load spectral centroid [Hz]: around the nut's axial resonance on its threads
#: (400–1200 Hz on paper 01 as the preload goes), above the drive's low orders.
CENTROID_BAND = (200.0, 3000.0)
#: Band the spalls are read in [Hz]: a spall's impacts are broadband, while the healthy nut
#: vibration (the axial resonance near 200–300 Hz, the gearhead's mesh at 764 Hz and its
#: second harmonic at 100 rad/s) lies below 2 kHz. Measured (docs/angle-domain.md): in this
#: band a nut spall's nut-pass SNR is 0.41–0.47 against ≤ 0.04 for every other class;
#: broadband it drowns in the healthy periodic content (−0.03…0.63 across seeds, faulty or
#: not). The upper edge stays below 0.4 of the sampling rate.
IMPACT_BAND = (2000.0, 8000.0)
#: The angle-domain periods of the high-load indicators (:func:`prsm_periods`).
SNR_PERIODS = ("nut_pass", "roller_spin", "carrier", "screw")
#: The periods of the envelope's synchronous averages: the spalls on the nut and on a roller
#: (a roller spall recurs at the roller spin and, the roller orbiting, at the carrier period).
#: The squared envelope keeps an impact train periodic where the band's waveform is not: the
#: resonance each impact rings at is a kHz wave whose phase the resolver's angle error and the
#: contact's slip shift from impact to impact, so the raw average cancels it. Measured on
#: fresh units (docs/angle-domain.md): healthy against 0.5 mm spalls, ROC AUC of the raw /
#: envelope SNR 0.90–0.96 / 0.99–1.00 (roller spin, roller spall; carrier, nut spall).
ENVELOPE_PERIODS = ("nut_pass", "roller_spin", "carrier")
#: Position bins of the stroke profile, as a share of the engaged length (threads × pitch): a
#: screw spall is met while the nut is within ± half of it, so it spans ≈ 4 bins.
POSITION_BIN_SHARE = 0.25
#: The reversal indicators of :func:`~prsm_health.signals.features.extract_features` kept
#: (module docstring of :func:`check_indicators`).
REVERSAL_FEATURES = ("lost_motion", "torque_rattle_rate", "drive_torque_ripple", "efficiency")
#: The reset comb's indicators a recirculating PRSM's high-load phase gives (signals.reset_comb):
#: its resets and whatever strikes on the comb's line (a nut spall, a chipped re-entry edge), at
#: the commanded load; the load slope needs a load that varies, which a constant phase has not.
COMB_FEATURES = tuple(k for k in RESET_COMB if k != "comb_load_slope")


def _indicator_table() -> dict[str, str]:
    units = {"check_noload_centroid": "Hz", "check_noload_rms": "m/s²"}
    units.update(
        {
            "check_torque_low": "N·m",
            "check_torque_high": "N·m",
            "check_torque_ratio": "-",
            "check_temperature": "K",
        }
    )
    reversal_units = {
        "lost_motion": "m",
        "torque_rattle_rate": "1/s",
        "drive_torque_ripple": "N·m",
        "efficiency": "-",
    }
    units.update({f"check_reversal_{k}": reversal_units[k] for k in REVERSAL_FEATURES})
    units["check_reversal_lost_motion_step"] = "m"
    units.update({f"check_highload_snr_{k}": "-" for k in SNR_PERIODS})
    units.update({f"check_highload_envelope_snr_{k}": "-" for k in ENVELOPE_PERIODS})
    units.update(
        {
            "check_highload_kurtosis": "-",
            "check_highload_crest": "-",
            "check_highload_rms": "m/s²",
            "check_highload_position_snr": "-",
            "check_highload_position_contrast": "-",
        }
    )
    units.update({f"check_highload_{k}": RESET_COMB[k] for k in COMB_FEATURES})
    return units


#: Indicator name → unit, in the order :func:`check_indicators` gives them.
CHECK_INDICATORS: dict[str, str] = _indicator_table()
#: The indicators of each role (``check_temperature``: the whole check's, given with the
#: torque pair it disambiguates).
ROLE_INDICATORS: dict[str, tuple[str, ...]] = {
    "no_load": tuple(k for k in CHECK_INDICATORS if k.startswith("check_noload_")),
    "torque_pair": tuple(
        k for k in CHECK_INDICATORS if k.startswith("check_torque_") or k == "check_temperature"
    ),
    "reversal": tuple(k for k in CHECK_INDICATORS if k.startswith("check_reversal_")),
    "high_load": tuple(k for k in CHECK_INDICATORS if k.startswith("check_highload_")),
}
#: The measured channels each role reads.
ROLE_CHANNELS: dict[str, tuple[str, ...]] = {
    "no_load": ("nut_axial_accel",),
    "torque_pair": ("drive_torque",),
    "reversal": ("nut_position", "screw_angle", "drive_torque"),
    "high_load": ("nut_axial_accel", "screw_angle"),
}


@dataclass(frozen=True)
class CheckReading:
    """What :func:`check_indicators` read from one check recording.

    Attributes
    ----------
    indicators : dict of name → float
        Every indicator of :data:`CHECK_INDICATORS`, in its order and unit; NaN where not read.
    roles : dict of role → phase name
        The phase each role was read in (roles of :data:`ROLES` found; for the torque pair
        ``"<low-speed phase> / <high-speed phase>"``).
    missing : dict of role → reason
        Why a role's indicators are NaN, or some of them: the condition the check lacks
        ("no constant phase without load …"), or the channels the recording lacks (then the
        role is in ``roles`` too), or the phase cut short (then in ``cut``).
    cut : dict of role → shortfall
        The roles whose phase the recording has, but cut short or too short to read
        (:func:`role_shortfall`): ``'"<phase>" 0.09 s of the 0.25 s it needs'``; not read,
        not in ``roles``.
    reversals : tuple of ReversalStep
        Every whole reversing phase under a known load, read for the clearance by physics
        (:func:`reversal_steps`), heaviest first.
    unread_reversals : dict of phase → reason
        The reversing phases under load not read, with why (cut, too short, a channel).
    """

    indicators: dict[str, float]
    roles: dict[str, str] = field(default_factory=dict)
    missing: dict[str, str] = field(default_factory=dict)
    cut: dict[str, str] = field(default_factory=dict)
    reversals: tuple[ReversalStep, ...] = ()
    unread_reversals: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class ReversalStep:
    """One whole reversing phase under a known load, read for the thread clearance by physics
    (:mod:`prsm_health.diagnostics.clearance_gauge`): its lost-motion step over the settled
    samples (:func:`~prsm_health.signals.lost_motion.settled_lost_motion_step`).

    Attributes
    ----------
    phase : str
    load : float [N]
        The load amplitude (commanded, else from a load cell), > 0.
    speed : float [rad/s]
        The screw speed amplitude (commanded, else measured), > 0.
    lost_motion : float [m]
    load_shares : ndarray
        |load|/``load`` of the samples the step was fitted on (the load follows the speed).
    drive_torque : float [N·m]
        The mean |drive torque| over those samples (NaN without the channel): the torque
        that winds up the reduction and the coupling.
    """

    phase: str
    load: float
    speed: float
    lost_motion: float
    load_shares: np.ndarray = field(repr=False)
    drive_torque: float = math.nan


# ---------------------------------------------------------------------------- indicators
def spectral_centroid(x: np.ndarray, sample_rate: float, band=CENTROID_BAND) -> float:
    """Power-weighted mean frequency of the Welch PSD of ``x`` inside ``band`` [Hz]
    (:data:`CENTROID_SEGMENT`-sample Hann segments, 75 % overlap); NaN for a record shorter
    than a segment or without power in the band."""
    x = np.asarray(x, float)
    if len(x) < CENTROID_SEGMENT:
        return math.nan
    f, p = welch_psd(x - np.mean(x), sample_rate, CENTROID_SEGMENT, 3 * CENTROID_SEGMENT // 4)
    inside = (f >= band[0]) & (f <= band[1])
    total = float(np.sum(p[inside]))
    return float(np.sum(f[inside] * p[inside]) / total) if total > 0 else math.nan


def impact_band(sample_rate: float) -> tuple[float, float] | None:
    """:data:`IMPACT_BAND` at a sampling rate, its top at most 0.4 of the rate; None when
    less than an octave is left."""
    low, high = IMPACT_BAND[0], min(IMPACT_BAND[1], 0.4 * sample_rate)
    return (low, high) if high >= 2 * low else None


def _no_load(phase: Run, out: dict) -> None:
    x = phase.channels["nut_axial_accel"]
    out["check_noload_centroid"] = spectral_centroid(x, phase.sample_rate)
    out["check_noload_rms"] = float(np.std(x))


def _torque_pair(slow: Run, fast: Run, out: dict) -> None:
    low = float(np.mean(np.abs(slow.channels["drive_torque"])))
    high = float(np.mean(np.abs(fast.channels["drive_torque"])))
    out["check_torque_low"], out["check_torque_high"] = low, high
    out["check_torque_ratio"] = low / high if high > 0 else math.nan


def _reversal(phase: Run, design: PRSMDesign, out: dict) -> None:
    # only the channels the reversal indicators read: extract_features then skips the
    # spectra, envelopes and averages of the vibration (measured: 5 ms instead of 80 ms)
    wanted = ["screw_angle", "screw_speed", "drive_torque", "nut_position", "axial_load"]
    if "nut_position" not in phase.channels:
        wanted.append("nut_axial_accel")  # extract_features needs a position or a vibration
    channels = {k: phase.channels[k] for k in wanted if k in phase.channels}
    part = Run(phase.time, channels, phase.sample_rate, operating=phase.operating)
    try:
        values = extract_features(part, design)
    except PRSMHealthError:  # too short for a window, or no position and no vibration
        return
    for name in REVERSAL_FEATURES:
        out[f"check_reversal_{name}"] = float(values[name])
    # the lost motion again, as the fitted jump between the flank sides: it averages the
    # LVDT's noise out, which the percentile spread above grows with
    if {"nut_position", "screw_angle", "screw_speed"} <= set(channels):
        out["check_reversal_lost_motion_step"] = lost_motion_step(
            channels["nut_position"],
            channels["screw_angle"],
            speed_ratios(design).nut,
            np.sign(channels["screw_speed"]),
        )


def impact_residual(phase: Run, design: PRSMDesign, gear_ratio: float) -> np.ndarray:
    """The high-load phase's nut axial acceleration in the impact band, the motor's orders
    removed (``gear_ratio`` > 1) [m/s²]: what the high-load indicators average
    (:func:`check_indicators`) and a reader draws (:mod:`prsm_health.signals.check_averages`).

    Raises
    ------
    PRSMHealthError
        The sampling rate leaves no impact band; the angle stops or turns back.
    """
    band = impact_band(phase.sample_rate)
    if band is None:
        raise PRSMHealthError(
            f"sample rate {phase.sample_rate:g} Hz too low for the {IMPACT_BAND} Hz band"
        )
    x = np.asarray(phase.channels["nut_axial_accel"], float)
    # band first, then the reduction's orders: resampling the broadband signal on the measured
    # angle turns the resolver's angle noise into phase noise of the strong mesh line, which
    # leaks into the band (measured: carrier SNR 0.27 against 0.08 band-first)
    y = bandpass_rows(x[None], phase.sample_rate, [band])[0]  # zero phase, 4th order
    if gear_ratio > 1:
        angle = np.asarray(phase.channels["screw_angle"], float)
        y, _ = subtract_synchronous(y, angle, prsm_periods(design, gear_ratio)["motor"])
    return y


def _high_load(phase: Run, design: PRSMDesign, gear_ratio: float, out: dict) -> str | None:
    """The spall indicators of the high-load phase; a reason when they cannot be read."""
    band = impact_band(phase.sample_rate)
    if band is None:
        return f"sample rate {phase.sample_rate:g} Hz too low for the {IMPACT_BAND} Hz band"
    angle = np.asarray(phase.channels["screw_angle"], float)
    periods = prsm_periods(design, gear_ratio)
    try:
        y = impact_residual(phase, design, gear_ratio)
        # each signal up-sampled once for all its periods
        averages = synchronous_average_periods(y, angle, {k: periods[k] for k in SNR_PERIODS})
        for name, average in averages.items():
            out[f"check_highload_snr_{name}"] = average.snr
        envelope = hilbert_envelope(y) ** 2
        envelope -= np.mean(envelope)  # its mean is no periodic content
        wanted = {k: periods[k] for k in ENVELOPE_PERIODS}
        for name, average in synchronous_average_periods(envelope, angle, wanted).items():
            out[f"check_highload_envelope_snr_{name}"] = average.snr
    except PRSMHealthError as exc:  # the angle stopped or turned back, too short
        return f"no angle domain in the phase: {exc}"
    rms = float(np.sqrt(np.mean(y * y)))
    out["check_highload_rms"] = rms
    if rms > 0:
        out["check_highload_kurtosis"] = float(np.mean(y**4) / rms**4)
        out["check_highload_crest"] = float(np.max(np.abs(y)) / rms)
    if "nut_position" in phase.channels:
        position = np.asarray(phase.channels["nut_position"], float)
    else:  # the nut's travel from the screw angle (a relative position)
        position = speed_ratios(design).nut * angle
    width = POSITION_BIN_SHARE * design.engaged_threads * design.pitch
    profile = position_profile(y, position, width)
    out["check_highload_position_snr"] = profile.snr
    out["check_highload_position_contrast"] = profile.contrast
    if design.variant == "recirculating":  # its resets' comb, at the commanded load
        comb = reset_comb_indicators(phase.channels, design, SEARCH_SHARE)
        out.update({f"check_highload_{k}": comb[k] for k in COMB_FEATURES})
    return None


def check_indicators(
    run: Run,
    design: PRSMDesign | str | dict | None = None,
    gear_ratio: float | None = None,
) -> CheckReading:
    """The indicators of a health-check recording, each read in the phase of its role.

    Parameters
    ----------
    run : Run
        A check recording: ``check_phase`` and ``check`` (phases with ``motion``, ``speed``
        [rad/s], ``load`` [N] when the record has them). Missing channels make the indicators
        that need them NaN.
    design : PRSMDesign, preset name, design file, dict or None
        None: the run's own (:func:`~prsm_health.signals.features.run_design`). Gives C_a
        (the no-load threshold), the PRSM's periods, the position bins.
    gear_ratio : float or None
        Motor turns per screw turn; None: the run's ``operating.gear_ratio`` (1 when the
        recording does not say: no reduction, nothing is removed before the averages).

    Returns
    -------
    CheckReading
        Roles (module docstring) found by condition: ``no_load`` the longest constant phase
        with |load| ≤ 2 % C_a; ``torque_pair`` the two constant phases under one load
        (within 5 %) with the largest speed ratio (≥ 1.5); ``reversal`` the reversing phase
        under the largest load (a load the record does not give counts as a load);
        ``high_load`` the constant phase with the largest |load|. A role whose phase is
        cut short or too short (:func:`role_shortfall`) is not read: it is in ``cut``.

        The reversal indicators kept from :func:`~prsm_health.signals.features.extract_features`
        are those about the play and the friction across it: ``lost_motion`` (the play
        crossed, LVDT against resolver: clearance, preload), ``torque_rattle_rate`` (bounces
        across the play: the more clearance the more), ``drive_torque_ripple`` (the torque
        swing under the commanded load swing: friction hysteresis) and ``efficiency``
        (friction under a reversing load; NaN without a load cell). The vibration indicators
        of that phase are left out: the slow reversal excites little and the other roles read
        the vibration.

        ``reversals``: every whole reversing phase under a known load read for the clearance
        by physics (:func:`reversal_steps`), heaviest first; ``unread_reversals`` those it
        could not read, with why.

    Raises
    ------
    PRSMHealthError
        A run labelled with a design that cannot be resolved, no ``design`` given.
    """
    out = dict.fromkeys(CHECK_INDICATORS, math.nan)
    if run.check_phase is None or run.check is None:
        reason = "the run is no health check (no check phases)"
        return CheckReading(out, {}, dict.fromkeys(ROLES, reason))
    design = run_design(run) if design is None else load_design(design)
    if design is None:
        reason = "no PRSM design (an imported rig): no load rating, no kinematics"
        return CheckReading(out, {}, dict.fromkeys(ROLES, reason))
    if gear_ratio is None:
        gear_ratio = run.operating.gear_ratio
    gear_ratio = float(gear_ratio) if is_number(gear_ratio) and gear_ratio > 0 else 1.0
    conditions = phase_conditions(run)
    found, missing, cut = read_roles(conditions, design, gear_ratio)
    roles: dict[str, str] = {}
    if "housing_temperature" in run.channels:
        out["check_temperature"] = float(np.mean(run.channels["housing_temperature"]))
    for role in ROLES:
        if role not in found:
            continue
        phase = found[role]
        if role == "torque_pair":
            roles[role] = f"{phase[0].name} / {phase[1].name}"
        else:
            roles[role] = phase.name
        lacking = [c for c in ROLE_CHANNELS[role] if c not in run.channels]
        if lacking:
            missing[role] = "missing channel(s) " + ", ".join(lacking)
            # the reversal's torque indicators need the torque only, its lost motion the rest
            if role != "reversal" or "drive_torque" not in run.channels:
                continue
        if role == "no_load":
            _no_load(phase.run, out)
        elif role == "torque_pair":
            _torque_pair(phase[0].run, phase[1].run, out)
        elif role == "reversal":
            _reversal(phase.run, design, out)
        else:
            reason = _high_load(phase.run, design, gear_ratio, out)
            if reason:
                missing[role] = reason
    reversals, unread = reversal_steps(conditions, design, gear_ratio)
    return CheckReading(out, roles, missing, cut, reversals, unread)


def reversal_steps(
    conditions: list[PhaseCondition], design: PRSMDesign, gear_ratio: float = 1.0
) -> tuple[tuple[ReversalStep, ...], dict[str, str]]:
    """(steps, unread): the lost-motion step of every whole reversing phase under a known
    load (above :data:`NO_LOAD_SHARE` of C_a) that has the position, angle and speed it needs,
    heaviest load first; and the reversing phases under load left out, with why (cut or too
    short, :func:`role_shortfall`; channels missing)."""
    limit = NO_LOAD_SHARE * load_ratings(design).dynamic
    lead = speed_ratios(design).nut
    out, unread = [], {}
    for c in conditions:
        if c.motion != "reversing" or c.load is None or not abs(c.load) > limit:
            continue
        channels = c.run.channels
        speed = measured_speed(c.run)
        lacking = [k for k in ("nut_position", "screw_angle") if k not in channels]
        if speed is None or lacking:
            unread[c.name] = "missing channel(s) " + ", ".join(lacking or ["screw_speed"])
            continue
        short = role_shortfall("reversal", c, design, gear_ratio)
        if short is not None:
            unread[c.name] = short
            continue
        step, shares = settled_lost_motion_step(
            channels["nut_position"], channels["screw_angle"], speed, lead
        )
        amplitude = abs(c.speed) if is_number(c.speed) and c.speed != 0 else math.nan
        torque = math.nan
        if "drive_torque" in channels:  # over the samples the step was fitted on
            settled, _ = settled_samples(speed)
            torque = float(np.mean(np.abs(np.asarray(channels["drive_torque"])[settled])))
        if math.isfinite(step) and math.isfinite(amplitude):
            out.append(ReversalStep(c.name, abs(float(c.load)), amplitude, step, shares, torque))
        else:
            unread[c.name] = "no lost motion: the nut did not cross the play both ways"
    return tuple(sorted(out, key=lambda r: -r.load)), unread


# ---------------------------------------------------------------------------- measurement
def _preloaded(lost: float) -> dict:
    faults = ({"kind": "preload_loss", "fraction": lost},) if lost else ()
    return {
        "clearance_screw": 0.0,
        "clearance_nut": 0.0,
        "clearance_gear": 10e-6,
        "preload": 5e-6,
        "faults": faults,
    }


#: The classes :func:`measure_classes` simulates: name → HealthState fields.
MEASURED_CLASSES: dict[str, dict] = {
    "healthy": {},
    "nut spall": {"faults": ({"kind": "spall", "location": "nut"},)},
    "roller spall": {"faults": ({"kind": "spall", "location": "roller"},)},
    "screw spall": {"faults": ({"kind": "spall", "location": "screw"},)},
    "preload 5 µm": _preloaded(0.0),
    "preload 60 % lost": _preloaded(0.6),
    "lubricant degraded": {"lubricant_degradation": 1.0},
}


def measure_classes(
    seeds=(1, 2, 3),
    design: str = "paper01",
    drive: str = "flight-ema",
    check: str = "health-check",
    classes: dict[str, dict] | None = None,
    show: bool = True,
) -> dict[str, dict[str, list[float]]]:
    """Simulate a check per class and seed, read it, print a table: the measurement behind
    docs/angle-domain.md (≈ 5 s of simulation per run on one core)::

        python -c "from prsm_health.signals.check_indicators import measure_classes; measure_classes()"

    Returns {indicator: {class: [value per seed]}} (and ``"_time_ms"``: the time
    :func:`check_indicators` took per run, after a first call that compiles its kernels).
    """
    import time

    from prsm_health.actuator.states import HealthState, OperatingProfile
    from prsm_health.simulation.scenario import simulate

    classes = MEASURED_CLASSES if classes is None else classes
    table: dict[str, dict[str, list[float]]] = {k: {} for k in CHECK_INDICATORS}
    table["_time_ms"] = {}
    for name, health in classes.items():
        for seed in seeds:
            run = simulate(
                design, HealthState(**health), OperatingProfile(check=check), drive, seed=seed
            )
            check_indicators(run)  # the first call compiles the kernels
            start = time.perf_counter()
            reading = check_indicators(run)
            table["_time_ms"].setdefault(name, []).append(1e3 * (time.perf_counter() - start))
            for key, value in reading.indicators.items():
                table[key].setdefault(name, []).append(value)
    if show:
        print("| indicator | " + " | ".join(classes) + " |")
        print("|---|" + "---|" * len(classes))
        for key, row in table.items():
            cells = []
            for name in classes:
                values = np.asarray(row.get(name, [math.nan]), float)
                if np.all(np.isnan(values)):
                    cells.append("NaN")
                    continue
                lo, mid, hi = np.nanmin(values), np.nanmedian(values), np.nanmax(values)
                cells.append(f"{mid:.3g} ({lo:.3g}–{hi:.3g})")
            print(f"| {key} | " + " | ".join(cells) + " |")
    return table
