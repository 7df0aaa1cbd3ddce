"""Are a recording's declared units plausible for its actuator? Physics that ties channels to
the design catches a unit slip — a position in mm declared m, an acceleration in g declared
m/s², a current in mA declared A — which the diagnosis would otherwise read as a strange
actuator.

Three checks, each a ratio of what the recording implies to what the design says (1 for a
recording in SI); a ratio near a *slip factor* (a power of ten, or a factor between two units
of the channel's quantity the caller gives) names the channel:

- **lead**: the nut moves one effective lead per screw turn (rigid-body kinematics,
  :func:`prsm_health.physics.kinematics.speed_ratios`: paper 04's s(θ_S), paper 03 eq. 29), so
  the slope of ``nut_position`` against ``screw_angle`` × 2π is the lead;
- **acceleration**: below the nut's vibration band the axial accelerometer reads the nut's
  rigid-body acceleration, the second derivative of its travel (lead/2π × the screw's angular
  acceleration, or of ``nut_position``); where the speed changes enough to be seen, the slope
  of one against the other is 1. Beyond the full scale of any vibration accelerometer the
  values are too large whatever the motion;
- **torque**: the motor torque holding an axial load F is F·L/(2π·η_s·N·η) (the screw's
  power balance, :func:`prsm_health.actuator.drive_train.duty_check`), so ``drive_torque``
  against ``axial_load`` is about 1 once the reduction N is taken out.

:func:`unit_mismatches` gives the structured findings, :func:`unit_warnings` one sentence
each; :func:`prsm_health.io.read_with_warnings` words them with the file's column and
declared unit. Checks that lack a channel, a lead or enough motion are skipped silently: a
quiet check is no evidence either way. Cost: block means and one low-pass of a few thousand
points — negligible beside the diagnosis.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

import numpy as np

from prsm_health.actuator.design_files import design_of
from prsm_health.core.channels import VIBRATION
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.physics.kinematics import speed_ratios

#: How far (decades) a ratio may sit from a slip factor and still be that slip: ×/÷1.41. A
#: recording in SI sits within a few percent of 1 (the simulated recordings: 0.2–0.6 % off
#: the lead, 1–3 % off the rigid-body acceleration; an LVDT's gain and nonlinearity, ±0.5 % and
#: 0.25 %, an accelerometer's sensitivity, ±3 %), and 0.15 keeps every power of ten apart.
TOLERANCE = 0.15
#: The torque check's tolerance [decades]: the efficiencies (η_s 0.8–0.9, gear 0.9–0.97),
#: friction at light load and an unknown reduction spread the ratio over ~×3 (the simulated
#: recordings: 1.18–1.32 with their reduction), so only a factor 1000 (mA, N·mm) is named.
TORQUE_TOLERANCE = 0.5
#: The torque check's slips: ±3 decades only. A mapped recording says no reduction (N = 1),
#: and a gearhead of ratio 10 or 100 would look like a power of ten.
TORQUE_SLIPS = (1e3, 1e-3)
#: Powers of ten tried for the position and the acceleration (10⁻⁶…10⁶, 1 excluded).
DECADES = tuple(10.0**k for k in range(-6, 7) if k)

#: Fewest moving lead blocks, and the correlation of the nut's steps with the screw's that
#: says the two move together (unit-free: a slip scales the slope, not the correlation).
MIN_BLOCKS, MIN_CORRELATION = 8, 0.9
#: Length of a lead block [s]: 10 ms steps of an LVDT's 5 µm noise and 4.6 µm resolution
#: (flight-ema) are far below a 10 mm lead's 16 µm per 10 mrad.
LEAD_BLOCK = 0.01
#: Screw travel the lead check needs [rad]: a tenth of a turn moves a 1 mm lead by 0.1 mm,
#: twenty times a linear scale's or an LVDT's noise.
MIN_TRAVEL = 0.6

#: Rate [Hz] the rigid-body acceleration is read at (block means), its low-pass corner [Hz]
#: and the edge dropped [s]: the nut's axial modes lie at hundreds of hertz and more
#: (:mod:`prsm_health.signals.axial_mode`), a speed ramp of 20 ms lies below 50 Hz.
RIGID_RATE, RIGID_CORNER, RIGID_EDGE = 1000.0, 20.0, 0.05
#: Smallest RMS of the rigid-body reference [m/s²] worth comparing (the short simulated check:
#: 1.8 m/s²; a constant-speed run: noise), and the correlation it needs.
MIN_RIGID_RMS, MIN_RIGID_CORRELATION = 0.3, 0.9
#: Largest plausible nut vibration [m/s²], 99th percentile of |a|: 500 g, the full scale of
#: general-purpose IEPE vibration accelerometers (±50 g for the ADXL1002 of flight-ema). The
#: simulated nut reads at most ~45 m/s² (a 10 Hz ±300 N reversal at 100 rad/s). There is no
#: lower bound: a slow, lightly loaded actuator reads 0.03 m/s² RMS (5 rad/s, simulated).
MAX_VIBRATION = 500 * 9.80665

#: Samples the percentiles read at most (a strided subset of a long recording).
SAMPLED = 100_000
#: Smallest 95th percentile of |axial_load| [N] the torque check reads: below it the screw's
#: friction torque rivals the load's.
MIN_LOAD = 100.0


@dataclass(frozen=True)
class UnitMismatch:
    """One channel whose values look scaled by a unit slip.

    Attributes
    ----------
    channel : str
        The channel blamed (a contract channel name).
    check : {"lead", "acceleration", "torque"}
    evidence : str
        What the recording implies against what the design says, in words with units.
    ratio : float
        The values over their plausible SI size, as measured (a lower bound for a vibration
        beyond any accelerometer's range).
    factor : float
        The slip factor the ratio is nearest: the values are ``factor`` × their SI size.
    hint : str
        What else the ratio could mean, or "".
    """

    channel: str
    check: str
    evidence: str
    ratio: float
    factor: float
    hint: str = ""

    def sentence(
        self, column: str | None = None, declared: str | None = None, likely: str | None = None
    ) -> str:
        """One line: the channel (and its file ``column``), the evidence, the ``declared``
        unit and the ``likely`` one when the caller knows them, the factor."""
        who = (
            self.channel
            if column in (None, self.channel)
            else f"column {column!r} ({self.channel})"
        )
        large = self.factor >= 1
        size = _number(self.factor if large else 1 / self.factor)  # "÷9.81", not "×0.102"
        if likely is not None:
            verdict = f"the values look like {likely} ({'×' if large else '÷'}{size})"
        else:
            verdict = f"the values look {size}× too {'large' if large else 'small'}"
        if declared is not None:
            verdict = f"declared {declared}, {verdict}"
        hint = f" ({self.hint})" if self.hint else ""
        return f"{who}: {self.evidence} — {verdict}{hint}"


def unit_mismatches(
    run: Run, *, slips: Mapping[str, Iterable[float]] | None = None
) -> list[UnitMismatch]:
    """The channels of ``run`` whose values look scaled by a unit slip, at most one finding
    per channel.

    Parameters
    ----------
    run : Run
        Channels in SI as declared; its design (:func:`~prsm_health.actuator.design_files.design_of`)
        or ``operating.lead`` gives the lead, ``operating.gear_ratio`` the reduction.
    slips : mapping of channel → factors, optional
        Factors beyond the powers of ten that a channel's declared unit may be off by (the
        ratios between the units of its quantity: 39.37 for inches declared m, 1/9.80665 for
        g declared m/s²…). Without them, the lead blames ``screw_angle`` never.
    """
    slips = {k: tuple(v) for k, v in (slips or {}).items()}
    rate = float(run.sample_rate)
    # Before Run.validate (the reader checks units first): channels it would refuse are skipped.
    usable = {
        k: v for k, v in run.channels.items() if len(v) == len(run) and np.all(np.isfinite(v))
    }
    if not (np.isfinite(rate) and rate > 0) or len(run) < 2:
        return []
    run = replace(run, channels=usable)
    found = []
    lead, whose = _lead(run)
    blamed = None
    if lead is not None:
        finding = _lead_check(run, lead, whose, slips)
        if finding is not None:
            found.append(finding)
            blamed = finding.channel
    found += _acceleration_checks(run, lead, blamed, slips)
    if lead is not None:
        finding = _torque_check(run, lead, slips)
        if finding is not None:
            found.append(finding)
    return found


def unit_warnings(run: Run) -> list[str]:
    """:func:`unit_mismatches` as one sentence each (no column names or units: the run's)."""
    return [m.sentence() for m in unit_mismatches(run)]


# ------------------------------------------------------------------------------ helpers
def _lead(run: Run) -> tuple[float | None, str]:
    """The lead [m per screw turn] the run's design or operating point gives, and whose."""
    if run.operating.lead is not None:
        return run.operating.lead, "the given lead"
    try:
        design = design_of(run)
    except PRSMHealthError:  # a design that does not rebuild is the diagnosis's to report
        return None, ""
    if design is None:
        return None, ""
    return speed_ratios(design).nut * 2 * math.pi, "the design's lead"


def _snap(
    ratio: float, named: Iterable[float], others: Iterable[float] = (), tolerance: float = TOLERANCE
) -> float | None:
    """The slip factor nearest ``ratio`` (in decades) within ``tolerance``, else None: of the
    ``named`` ones (a unit of the channel's quantity) first, else of the ``others``; so g
    (9.807) names a ratio of 10 ± 40 %, which no acceleration unit is off by."""
    if not (np.isfinite(ratio) and ratio > 0):
        return None
    for factors in (named, others):
        best = min(factors, key=lambda f: abs(math.log10(ratio / f)), default=None)
        if best is not None and abs(math.log10(ratio / best)) < tolerance:
            return best
    return None


def _blocks(values: np.ndarray, size: int) -> np.ndarray:
    """Means of consecutive blocks of ``size`` samples (the tail dropped)."""
    n = len(values) // size * size
    return np.asarray(values[:n], float).reshape(-1, size).mean(axis=1)


def _lead_check(run: Run, lead: float, whose: str, slips: dict) -> UnitMismatch | None:
    if not {"screw_angle", "nut_position"} <= set(run.channels):
        return None
    size = max(1, int(round(LEAD_BLOCK * run.sample_rate)))
    turn = np.diff(_blocks(run.channels["screw_angle"], size))
    travel = np.diff(_blocks(run.channels["nut_position"], size))
    if len(turn) < MIN_BLOCKS:
        return None
    # moving blocks that keep their neighbours' direction: a reversal's lost motion is left out
    sign = np.sign(turn)
    keep = np.abs(turn) > 0.1 * np.percentile(np.abs(turn), 90)
    keep[1:] &= sign[1:] == sign[:-1]
    keep[:-1] &= sign[:-1] == sign[1:]
    turn, travel = turn[keep], travel[keep]
    if len(turn) < MIN_BLOCKS or np.sum(np.abs(turn)) < MIN_TRAVEL:
        return None
    # uncentred: at constant speed the steps hardly vary, and still move together
    if abs(_cosine(turn, travel)) < MIN_CORRELATION:
        return None
    implied = abs(float(np.dot(turn, travel) / np.dot(turn, turn))) * 2 * math.pi
    ratio = implied / lead
    # the position's slip scales the lead up, the angle's down
    position = _snap(ratio, slips.get("nut_position", ()), DECADES)
    angle = _snap(1 / ratio, slips.get("screw_angle", ()))
    if position is None and angle is None:
        return None
    evidence = (
        f"implied lead {_number(1e3 * implied)} mm/rev against {whose} {_number(1e3 * lead)} mm/rev"
    )
    if angle is not None and (
        position is None or abs(math.log10(ratio * angle)) < abs(math.log10(ratio / position))
    ):
        return UnitMismatch("screw_angle", "lead", evidence, 1 / ratio, angle)
    # a motor angle read as the screw's (N times too many radians) looks like a position slip
    motor = "or screw_angle is the motor's angle: the contract's is the gearbox output's"
    return UnitMismatch(
        "nut_position", "lead", evidence, ratio, position, motor if ratio < 1 else ""
    )


def _acceleration_checks(
    run: Run, lead: float | None, blamed: str | None, slips: dict
) -> list[UnitMismatch]:
    found = []
    rigid = _rigid_body_check(run, lead, blamed, slips)
    if rigid is not None:
        found.append(rigid)
    for name in VIBRATION:
        if name not in run.channels or any(m.channel == name for m in found):
            continue
        values = np.asarray(run.channels[name], float)
        if np.max(np.abs(values)) <= MAX_VIBRATION:  # one pass: a recording in range stops here
            continue
        values = _sample(values)
        peak = float(np.percentile(np.abs(values - np.median(values)), 99))
        if peak <= MAX_VIBRATION:
            continue
        # the smallest slip that brings the values within range: mm/s² declared m/s² is 10³
        large = sorted(f for f in (1e3, 1e6, *slips.get(name, ())) if f > 1)
        factor = next((f for f in large if peak / f <= MAX_VIBRATION), large[-1])
        found.append(
            UnitMismatch(
                name,
                "acceleration",
                f"vibration {_number(peak)} m/s² (99th percentile) beyond 500 g, a vibration "
                "accelerometer's range",
                peak / MAX_VIBRATION,
                factor,
            )
        )
    return found


def _rigid_body_check(
    run: Run, lead: float | None, blamed: str | None, slips: dict
) -> UnitMismatch | None:
    """The nut's low-passed axial acceleration against the second derivative of its travel."""
    from scipy import signal

    name = "nut_axial_accel"
    if name not in run.channels or run.sample_rate < 10 * RIGID_CORNER:
        return None
    if lead is not None and "screw_angle" in run.channels and blamed != "screw_angle":
        travel, source = run.channels["screw_angle"] * (lead / (2 * math.pi)), "screw_angle"
    elif "nut_position" in run.channels and blamed != "nut_position":
        travel, source = run.channels["nut_position"], "nut_position"
    else:
        return None
    size = max(1, int(run.sample_rate // RIGID_RATE))
    rate = run.sample_rate / size
    edge = int(RIGID_EDGE * rate)
    if len(run) // size <= 4 * edge + 32:
        return None
    sos = signal.butter(4, RIGID_CORNER, "low", fs=rate, output="sos")
    x = signal.sosfiltfilt(sos, _blocks(travel, size))
    reference = np.gradient(np.gradient(x, 1 / rate), 1 / rate)[edge:-edge]
    measured = signal.sosfiltfilt(sos, _blocks(run.channels[name], size))[edge:-edge]
    measured = measured - measured.mean()  # a DC accelerometer's gravity and offset
    reference = reference - reference.mean()
    if np.std(reference) < MIN_RIGID_RMS:
        return None
    if abs(_correlation(reference, measured)) < MIN_RIGID_CORRELATION:
        return None
    ratio = abs(float(np.dot(reference, measured) / np.dot(reference, reference)))
    factor = _snap(ratio, slips.get(name, ()), DECADES)
    if factor is None:
        return None
    of = f"{source} × lead/2π" if source == "screw_angle" else source
    return UnitMismatch(
        name,
        "acceleration",
        f"acceleration below {RIGID_CORNER:g} Hz {_number(ratio)}× the rigid-body one "
        f"(d²/dt² of {of})",
        ratio,
        factor,
    )


def _torque_check(run: Run, lead: float, slips: dict) -> UnitMismatch | None:
    if not {"drive_torque", "axial_load"} <= set(run.channels):
        return None
    load = np.abs(_sample(run.channels["axial_load"]))
    level = float(np.percentile(load, 95))
    if level < MIN_LOAD:
        return None
    loaded = load >= 0.5 * level  # where the load's torque outweighs the screw's friction
    needed = load[loaded] * lead / (2 * math.pi * run.operating.gear_ratio)
    torque = np.abs(_sample(run.channels["drive_torque"]))[loaded]
    ratio = float(np.median(torque) / np.median(needed))
    factor = _snap(ratio, slips.get("drive_torque", ()), TORQUE_SLIPS, TORQUE_TOLERANCE)
    if factor is None:
        return None
    return UnitMismatch(
        "drive_torque",
        "torque",
        f"drive torque {_number(ratio)}× what the axial load needs "
        f"(F·lead/(2π·N), N = {run.operating.gear_ratio:g})",
        ratio,
        factor,
        f"or axial_load {'÷' if factor > 1 else '×'}{max(factor, 1 / factor):.4g}",
    )


def _sample(values: np.ndarray) -> np.ndarray:
    """Every k-th sample, at most ~:data:`SAMPLED` of them: percentiles of a long recording
    at a fraction of the cost, as exact as a tolerance of 40 % needs."""
    return np.asarray(values[:: max(1, len(values) // SAMPLED)], float)


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    return _cosine(a - a.mean(), b - b.mean())


def _cosine(a: np.ndarray, b: np.ndarray) -> float:
    norm = math.sqrt(float(np.dot(a, a)) * float(np.dot(b, b)))
    return float(np.dot(a, b)) / norm if norm else 0.0


def _number(value: float) -> str:
    """Three significant digits, never in exponent form (10000, 0.104)."""
    return np.format_float_positional(value, precision=3, fractional=False, trim="-")


__all__ = ["UnitMismatch", "unit_mismatches", "unit_warnings"]
