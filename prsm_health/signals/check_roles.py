"""Which phase of a health check plays which role, and whether it was recorded whole: the
phases' conditions (commanded, else measured), the roles found by condition
(:func:`find_roles`) and each role's shortfall when its phase is cut or too short
(:func:`role_shortfall`). What each role's phase shows is read by
:mod:`prsm_health.signals.check_indicators` (its module docstring: the roles, cut phases).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.run import Run
from prsm_health.physics.load_rating import load_ratings

from .angle_domain import prsm_periods
from .percentiles import percentiles

#: The roles a check's phases are found for, in order.
ROLES = ("no_load", "torque_pair", "reversal", "high_load")
#: A load at most this share of C_a is "no load" (and a larger one "under load"): 2 % is
#: ≈ 200 N on paper 01 — a controller's residual force, against the check's 10–25 % C_a.
NO_LOAD_SHARE = 0.02
#: The spalls' phase needs at least this share of C_a: the synchronous averages separated
#: 0.5 mm nut and roller spalls from healthy units at 25 % and 40 % of C_a, not at 20 % or below
#: (tools/studies/duty_signatures.py, docs/faults.md "At realistic duty").
HIGH_LOAD_SHARE = 0.2
#: Two phase loads are "one load" within this share of the larger.
SAME_LOAD = 0.05
#: Two phase speeds are "different" when the faster is at least this many times the slower.
SPEED_RATIO = 1.5
#: Below this measured speed [rad/s] (90th percentile of |speed|) a phase is at rest.
REST_SPEED = (
    1.0  #: Welch segment of the no-load spectrum: 512 samples (39 Hz at 20 kHz), 75 % overlap —
)
#: 28 segments in the built-in check's 0.2 s.
CENTROID_SEGMENT = 512
#: Samples a whole phase may lack against its record's span: ``start ≤ t < end`` rounds to a
#: sample at each end (:func:`~prsm_health.core.check_phases.phase_of_samples`).
BOUNDARY_SAMPLES = 2
#: Reversals a reversal phase needs: the lost-motion loop's two branches and back — the play
#: crossed onto the other flanks and back onto the first, so both flank changes (both signs
#: of the speed and of the load) are in the lag's step fit and the percentile spread.
MIN_REVERSALS = 2
#: A reversal counts when the speed goes from beyond this share of its amplitude on one side
#: to beyond it on the other: the play crossed with a settled length of each branch recorded.
REVERSAL_LEVEL = 0.5
#: Periods each synchronous average of the high-load phase needs: the fewest its SNR is defined
#: from (:func:`~prsm_health.signals.angle_domain.periodic_snr`: the spread between replicas)
#: and the motor orders' subtraction needs.
MIN_PERIODS = 2
#: The periods the high-load phase must hold :data:`MIN_PERIODS` of: the spall classes'
#: indicators (nut pass: a nut spall; roller spin: a roller spall) — the carrier and screw SNRs
#: are NaN in a shorter phase, as in the built-in check's design they are not needed for.
NEEDED_PERIODS = ("nut_pass", "roller_spin")


@dataclass(frozen=True)
class PhaseCondition:
    """A phase's condition: as commanded (the check's record) or, where the record lacks it,
    as measured.

    Attributes
    ----------
    name : str
    motion : {"constant", "reversing", "rest"} or None (not known)
    speed : float [rad/s] or NaN (screw; signed; the amplitude of a reversing phase)
    load : float [N] or None (resisting the motion; the amplitude of a reversing phase)
    samples : int
    run : Run
        The phase's settled samples (none when the recording ends before the phase).
    declared : float or None [s]
        Its settled part as the check's record gives it (``end − start``); None without one.
    """

    name: str
    motion: str | None
    speed: float
    load: float | None
    samples: int
    run: Run
    declared: float | None = None

    @property
    def recorded(self) -> float:
        """Its recorded length [s]."""
        return self.samples / self.run.sample_rate

    @property
    def is_cut(self) -> bool:
        """Recorded shorter than its record's span (:data:`BOUNDARY_SAMPLES` aside)."""
        if self.declared is None:
            return False
        return self.samples < self.declared * self.run.sample_rate - BOUNDARY_SAMPLES


# ---------------------------------------------------------------------------- conditions
def measured_speed(part: Run) -> np.ndarray | None:
    """The phase's screw speed [rad/s]: the channel, else the angle's derivative; None
    without either."""
    if "screw_speed" in part.channels:
        return np.asarray(part.channels["screw_speed"], float)
    if "screw_angle" in part.channels and len(part) > 1:
        return np.gradient(np.asarray(part.channels["screw_angle"], float)) * part.sample_rate
    return None


def _measured_motion(speed: np.ndarray | None) -> str | None:
    if speed is None or len(speed) == 0:
        return None
    if float(np.percentile(np.abs(speed), 90)) < REST_SPEED:
        return "rest"
    # both signs reached by a tenth of the range or more: a reversal, not noise about a mean
    margin = 0.1 * float(np.ptp(speed))
    low, high = percentiles(speed, [2, 98])
    if float(low) < -margin and float(high) > margin:
        return "reversing"
    return "constant"


def _measured_load(part: Run, motion: str | None, speed: np.ndarray | None) -> float | None:
    """The load resisting the motion from a load cell (positive resists a positive speed, the
    kernel's convention): the mean for a constant phase, the 95th-percentile magnitude with
    the mean's sign for a reversing one; None without a load cell."""
    load = part.channels.get("axial_load")
    if load is None or len(load) == 0:
        return None
    load = np.asarray(load, float)
    if motion == "rest" or speed is None:
        return float(np.mean(load))
    resisting = load * np.sign(speed)
    if motion == "reversing":
        return math.copysign(float(np.percentile(np.abs(load), 95)), float(np.mean(resisting)))
    return float(np.mean(resisting))


def phase_conditions(run: Run) -> list[PhaseCondition]:
    """Every phase of a check recording with its condition, in check order (empty for a run
    that is no check): motion, speed and load as the check's record gives them, each that it
    lacks (older files, a load left as a share of a rating) as measured — the motion from the
    sign changes of the measured speed, the speed as its mean (its largest magnitude for a
    reversal), the load from a load cell (None without one). A phase of the record the
    recording ends before (or starts after) is listed too, with no samples."""
    phases = run.phases()
    records = {p.name: p for p in run.check.phases} if run.check is not None else {}
    for name in records:
        if name not in phases:
            phases[name] = run.slice(0, 0)
    order = {name: k for k, name in enumerate(records)}
    out = []
    for name, part in sorted(phases.items(), key=lambda item: order.get(item[0], len(order))):
        record = records.get(name)
        speed_signal = measured_speed(part)
        motion = (record and record.motion) or _measured_motion(speed_signal)
        speed = record.speed if record is not None else None
        if not is_number(speed):
            if speed_signal is None or len(speed_signal) == 0:
                speed = math.nan
            elif motion == "reversing":
                speed = float(np.percentile(np.abs(speed_signal), 98))
            else:
                speed = float(np.mean(speed_signal))
        load = record.load if record is not None else None
        if not is_number(load):
            load = _measured_load(part, motion, speed_signal)
        declared = None if record is None else float(record.end - record.start)
        out.append(PhaseCondition(name, motion, float(speed), load, len(part), part, declared))
    return out


def is_number(value) -> bool:
    """A finite int or float (no bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


# ---------------------------------------------------------------------------- roles
def find_roles(
    conditions: list[PhaseCondition], rating: float
) -> tuple[dict[str, object], dict[str, str]]:
    """({role: the phase, or (low, high) phases for the torque pair}, {role: why not found})
    for phases with the conditions given and a design of dynamic rating ``rating`` [N]."""
    limit = NO_LOAD_SHARE * rating
    constant = [c for c in conditions if c.motion == "constant"]
    known = [c for c in constant if c.load is not None]
    loaded = [c for c in known if abs(c.load) > limit]
    found: dict[str, object] = {}
    missing: dict[str, str] = {}

    free = [c for c in known if abs(c.load) <= limit]
    if free:
        found["no_load"] = max(free, key=lambda c: c.samples)
    elif not constant:
        missing["no_load"] = "no constant-speed phase"
    elif not known:
        missing["no_load"] = "no constant-speed phase with a known load (no load in the record)"
    else:
        missing["no_load"] = (
            f"no constant-speed phase without load (|load| ≤ {NO_LOAD_SHARE:.0%} C_a)"
        )

    pairs = []
    for i, a in enumerate(loaded):
        for b in loaded[i + 1 :]:
            same = abs(a.load - b.load) <= SAME_LOAD * max(abs(a.load), abs(b.load))
            slow, fast = sorted((a, b), key=lambda c: abs(c.speed))
            if same and abs(fast.speed) >= SPEED_RATIO * abs(slow.speed) > 0:
                pairs.append((abs(fast.speed) / abs(slow.speed), abs(a.load), slow, fast))
    if pairs:
        _, _, slow, fast = max(pairs, key=lambda p: (p[0], p[1]))
        found["torque_pair"] = (slow, fast)
    else:
        missing["torque_pair"] = "no two constant-speed phases under one load at different speeds"

    reversing = [c for c in conditions if c.motion == "reversing"]
    under_load = [c for c in reversing if c.load is None or abs(c.load) > limit]
    if under_load:
        # a known load first (an unknown one may be none), the largest
        found["reversal"] = max(
            under_load, key=lambda c: (c.load is not None, abs(c.load or 0.0), c.samples)
        )
    elif reversing:
        missing["reversal"] = "no reversing phase under load (the reversing phases have none)"
    else:
        missing["reversal"] = "no reversing phase under load"

    heavy = [c for c in loaded if abs(c.load) >= HIGH_LOAD_SHARE * rating]
    if heavy:
        found["high_load"] = max(heavy, key=lambda c: (abs(c.load), c.samples))
    elif loaded:
        missing["high_load"] = (
            f"no constant-speed phase at ≥ {HIGH_LOAD_SHARE:.0%} of C_a (the highest has "
            f"{max(abs(c.load) for c in loaded) / rating:.0%})"
        )
    elif constant:
        missing["high_load"] = "no constant-speed phase under a known load"
    else:
        missing["high_load"] = "no constant-speed phase"
    return found, missing


# ---------------------------------------------------------------------------- lengths
def count_reversals(speed) -> int:
    """Reversals of a measured speed: changes of side between beyond ±:data:`REVERSAL_LEVEL`
    of its amplitude (98th percentile of |speed|), so noise about zero counts none."""
    speed = np.asarray(speed, float)
    if len(speed) == 0:
        return 0
    level = REVERSAL_LEVEL * float(np.percentile(np.abs(speed), 98))
    side = np.sign(speed) * (np.abs(speed) > level)
    side = side[side != 0]
    return int(np.count_nonzero(np.diff(side)))


def role_shortfall(
    role: str, phase: PhaseCondition, design: PRSMDesign, gear_ratio: float = 1.0
) -> str | None:
    """Why ``phase`` cannot be read for ``role``, as ``'"<phase>" <has> of the <need> it
    needs'`` (or ``'"<phase>" not recorded (its <span>)'``); None when it can.

    Every role needs the phase's whole settled part (:attr:`PhaseCondition.is_cut`: the models
    were trained on whole phases); a whole phase needs besides, per role:

    * ``no_load`` — one Welch segment of the centroid (:data:`CENTROID_SEGMENT` samples; below
      it :func:`spectral_centroid` has no spectrum);
    * ``torque_pair`` — nothing more: the mean |torque| of whatever its settled part is;
    * ``reversal`` — :data:`MIN_REVERSALS` reversals of the measured speed;
    * ``high_load`` — :data:`MIN_PERIODS` of each of :data:`NEEDED_PERIODS` and of the motor
      turn (its orders are removed first) in the measured screw angle.
    """
    name, part = phase.name, phase.run
    if phase.is_cut and phase.samples == 0:
        return f'"{name}" not recorded (its {phase.declared:.2g} s)'
    if phase.is_cut:
        return f'"{name}" {phase.recorded:.2g} s recorded of the {phase.declared:.2g} s it needs'
    if role == "no_load" and phase.samples < CENTROID_SEGMENT:
        return (
            f'"{name}" {phase.recorded:.2g} s of the {CENTROID_SEGMENT / part.sample_rate:.2g} s '
            "it needs (one spectrum segment)"
        )
    if role == "reversal":
        speed = measured_speed(part)
        count = None if speed is None else count_reversals(speed)
        if count is not None and count < MIN_REVERSALS:
            return f'"{name}" {count} reversal(s) of the {MIN_REVERSALS} it needs (a closed loop)'
    if role == "high_load" and "screw_angle" in part.channels and len(part) > 1:
        periods = prsm_periods(design, gear_ratio)
        longest = max(
            [periods[k] for k in NEEDED_PERIODS] + ([periods["motor"]] if gear_ratio > 1 else [])
        )
        angle = np.asarray(part.channels["screw_angle"], float)
        travel = abs(float(angle[-1] - angle[0]))
        if travel < MIN_PERIODS * longest:
            return (
                f'"{name}" {travel / (2 * math.pi):.2g} screw turn(s) of the '
                f"{MIN_PERIODS * longest / (2 * math.pi):.2g} it needs ({MIN_PERIODS} periods "
                "of each synchronous average)"
            )
    return None


def read_roles(
    conditions: list[PhaseCondition], design: PRSMDesign, gear_ratio: float
) -> tuple[dict[str, object], dict[str, str], dict[str, str]]:
    """(found, missing, cut): :func:`find_roles` on the whole phases, then the roles whose
    phase is cut or too short (:func:`role_shortfall`) moved from ``found`` to ``cut`` — a
    role only a cut phase would fill is named cut, not absent."""
    rating = load_ratings(design).dynamic
    found, missing = find_roles([c for c in conditions if not c.is_cut], rating)
    if any(c.is_cut for c in conditions):
        with_cut, _ = find_roles(conditions, rating)
        found |= {r: p for r, p in with_cut.items() if r not in found}
    cut: dict[str, str] = {}
    for role in list(found):
        phases = found[role] if role == "torque_pair" else (found[role],)
        short = [s for c in phases if (s := role_shortfall(role, c, design, gear_ratio))]
        if short:
            cut[role] = "; ".join(short)
            missing[role] = f"cut short or too short to read: {cut[role]}"
            del found[role]
    return found, missing, cut
