"""A health check the actuator runs: a named sequence of phases, compiled to the kernel's knots.

Flight-control electromechanical actuators run a built-in test before flight: the drive moves
the actuator through a few commanded conditions and the health monitor reads the signatures
each condition brings out. A :class:`HealthCheck` is such a sequence of :class:`CheckPhase`
(motion, screw speed, axial load, duration); :attr:`BUILT_IN` holds the package's own one,
``"health-check"``, and :func:`load_check` reads user-defined ones from TOML::

    [check]
    name = "my-check"

    [[check.phases]]
    name = "no-load stroke"
    motion = "constant"          # "constant", "reversing" (slow reversal) or "rest"
    speed = 50.0                 # rad/s of the screw; negative retracts the nut
    load = 0                     # N, "4.4 kN", "20 % C_a", "5 % C_0a" (resisting the motion)
    duration = 0.2               # s, the settled part
    ramp_time = 0.05             # s, from the previous phase's speed and load to this one's

    [[check.phases]]
    name = "slow reversal"
    motion = "reversing"
    speed = 10.0                 # speed amplitude [rad/s]
    load = "25 % C_a"            # load amplitude: ± with the motion
    reversal_shape = "cosine"    # speed over one period: "cosine" or "linear" (triangle)
    reversal_period = 0.25       # s
    duration = 0.5

**Timeline.** Phase k starts with its ramp (``ramp_time``, a raised cosine in speed and load
from where phase k−1 ended, the first from rest), then holds its condition for ``duration``;
after the last phase the actuator ramps back to rest (no speed, no load) over that phase's
``ramp_time``, as a built-in test ends. The ramps belong to no phase:
:meth:`HealthCheck.phase_at` gives −1 there, so a reader who cuts a recording by phase gets
settled conditions only. The check lasts Σ(ramp_time + duration) + the last ramp_time.

**Load sign.** A phase's ``load`` resists the phase's motion (positive: opposes it, the usual
case of an actuator working against the surface; negative: aids it). The knots carry the
kernel's convention of :class:`~prsm_health.actuator.states.OperatingProfile` (positive
resists a positive screw speed): a constant phase's load is ``load·sign(speed)``; a reversing
phase's follows the speed, ``load·speed(t)/|speed|``, so the nut is pushed onto the other
flanks at each reversal and the play is crossed (lost motion); at rest, the load is applied as
written in the kernel's convention.

**Loads as shares** of the design's ratings (``"20 % C_a"``, :mod:`prsm_health.core.quantities`)
are kept as written until :meth:`HealthCheck.resolved` turns them into newtons with the
design's ratings (``{"C_a": …, "C_0a": …}``, from
:func:`prsm_health.physics.load_rating.load_ratings`); an unresolved check gives no load knots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from prsm_health.core.check_phases import CheckPhases, PhaseSpan
from prsm_health.core.errors import ParameterError, require, require_known_keys, require_range
from prsm_health.core.quantities import ForceSpec, parse_force
from prsm_health.core.tomlfile import read_toml

PHASE_MOTIONS = ("constant", "reversing", "rest")
REVERSAL_SHAPES = ("linear", "cosine")
#: Pieces of a raised cosine (ramps, cosine reversals): within 0.5 % of its amplitude, as the
#: reversing load of OperatingProfile.load_knots.
_COSINE_PIECES = 16
#: Largest speed a phase may command [rad/s]: OperatingProfile.speed's bound.
MAX_SPEED = 2000.0


@dataclass(frozen=True)
class CheckPhase:
    """One commanded condition of a health check (module docstring: timeline, load sign).

    Parameters
    ----------
    name : str
        What the phase is called in recordings (Parquet metadata, MCAP topic, figures).
    motion : {"constant", "reversing", "rest"}
        constant: the screw held at ``speed``; reversing: a slow reversal, the speed swinging
        ±``speed`` with period ``reversal_period`` (starting at +``speed``); rest: screw held
        still (``speed`` ignored, 0).
    speed : float [rad/s]
        Screw speed (constant; negative retracts the nut) or speed amplitude (reversing).
    load : float [N] or str
        Axial load resisting the motion (module docstring): newtons, ``"4.4 kN"``, or a share of
        the design's ratings (``"20 % C_a"``, ``"5 % C_0a"``) kept as written until
        :meth:`HealthCheck.resolved`.
    duration : float [s]
        The settled part, after the ramp.
    ramp_time : float [s]
        Transition from the previous phase (or rest) to this phase's speed and load, a raised
        cosine (no acceleration step).
    reversal_shape : {"cosine", "linear"}
        Speed over one reversal period: a cosine, or a triangle (constant acceleration).
    reversal_period : float [s]
        Period of the reversing motion (two reversals).
    """

    name: str
    motion: str = "constant"
    speed: float = 0.0
    load: float | str = 0.0
    duration: float = 0.2
    ramp_time: float = 0.05
    reversal_shape: str = "cosine"
    reversal_period: float = 0.25

    def __post_init__(self) -> None:
        where = f'check.phases "{self.name}"' if isinstance(self.name, str) else "check.phases"
        require(
            isinstance(self.name, str) and self.name.strip() != "",
            f"{where}.name",
            self.name,
            "must be a non-empty string",
        )
        require(
            self.motion in PHASE_MOTIONS,
            f"{where}.motion",
            self.motion,
            f"must be one of {', '.join(PHASE_MOTIONS)}",
        )
        require(
            self.reversal_shape in REVERSAL_SHAPES,
            f"{where}.reversal_shape",
            self.reversal_shape,
            f"must be one of {', '.join(REVERSAL_SHAPES)}",
        )
        for key, low, high, unit in (
            ("speed", -MAX_SPEED, MAX_SPEED, "rad/s"),
            ("duration", 1e-4, 3600.0, "s"),
            ("ramp_time", 1e-4, 10.0, "s"),
            ("reversal_period", 1e-3, 100.0, "s"),
        ):
            value = getattr(self, key)
            require(
                isinstance(value, (int, float)) and not isinstance(value, bool),
                f"{where}.{key}",
                value,
                f"must be a number [{unit}]",
            )
            require_range(f"{where}.{key}", value, low, high, unit=unit)
        spec = parse_force(self.load, f"{where}.load")
        if spec.of is None:
            require_range(f"{where}.load", spec.value, -1e6, 1e6, unit="N")
        # canonical form: newtons as a float, a share as its written text ("25 % C_a")
        object.__setattr__(self, "load", spec.value if spec.of is None else spec.text())
        object.__setattr__(self, "speed", float(self.speed))
        if self.motion == "rest":
            object.__setattr__(self, "speed", 0.0)

    @property
    def force(self) -> ForceSpec:
        """The load as a :class:`~prsm_health.core.quantities.ForceSpec`."""
        return parse_force(self.load)

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


PHASE_KEYS = tuple(f.name for f in fields(CheckPhase))


@dataclass(frozen=True)
class HealthCheck:
    """A named sequence of :class:`CheckPhase` (module docstring).

    Parameters
    ----------
    name : str
    phases : tuple of CheckPhase
        At least one; dicts with the phase keys are converted (errors name the phase and key).
    """

    name: str
    phases: tuple = ()

    def __post_init__(self) -> None:
        require(
            isinstance(self.name, str) and self.name.strip() != "",
            "check.name",
            self.name,
            "must be a non-empty string",
        )
        require(
            isinstance(self.phases, (list, tuple)) and len(self.phases) > 0,
            "check.phases",
            self.phases if isinstance(self.phases, (list, tuple)) else type(self.phases).__name__,
            "a health check needs at least one phase ([[check.phases]] tables)",
        )
        object.__setattr__(self, "phases", tuple(_phase(p, k) for k, p in enumerate(self.phases)))
        names = [p.name for p in self.phases]
        dup = next((n for n in names if names.count(n) > 1), None)
        require(dup is None, "check.phases.name", dup, "phase names must be unique in a check")

    # ------------------------------------------------------------------ loads
    @property
    def is_resolved(self) -> bool:
        """True when every load is in newtons (no share of a rating left)."""
        return all(isinstance(p.load, float) for p in self.phases)

    def resolved(self, ratings: dict[str, float] | None) -> HealthCheck:
        """The check with every load in newtons: shares resolved with ``ratings``
        (``{"C_a": …, "C_0a": …}`` [N]); a load above the static rating C_0a is refused (it
        would dent the threads: ISO 76's limit, :mod:`prsm_health.physics.load_rating`)."""
        phases = []
        for k, p in enumerate(self.phases):
            field = f'check.phases[{k}] "{p.name}".load'
            newtons = p.force.newtons(ratings, field)
            if ratings and "C_0a" in ratings:
                c0 = float(ratings["C_0a"])
                require(
                    abs(newtons) <= c0,
                    field,
                    p.load,
                    f"{newtons:.4g} N is above the design's static load rating "
                    f"C_0a = {c0:.4g} N (|load| ≤ C_0a)",
                )
            phases.append(replace(p, load=float(newtons)))
        return replace(self, phases=tuple(phases))

    # ------------------------------------------------------------------ timeline
    @property
    def duration(self) -> float:
        """Whole check [s]: Σ(ramp_time + duration) and the last ramp back to rest."""
        return float(sum(p.ramp_time + p.duration for p in self.phases)) + float(
            self.phases[-1].ramp_time
        )

    def recorded(self) -> CheckPhases:
        """What a recording of the check carries: its name and every phase's ``index``,
        ``name``, ``start`` and ``end`` [s] (the settled part; the ramp before ``start`` belongs
        to no phase) with its commanded condition: ``motion``, ``speed`` [rad/s] and, once the
        check is :meth:`resolved`, ``load`` [N] (resisting the motion; None before). The
        controller commands them, so a hardware recording has them too; the diagnosis reads a
        phase by its condition, not its name."""
        out, t = [], 0.0
        for k, p in enumerate(self.phases):
            start = t + p.ramp_time
            end = start + p.duration
            load = float(p.load) if isinstance(p.load, (int, float)) else None
            out.append(PhaseSpan(k, p.name, start, end, p.motion, float(p.speed), load))
            t = end
        return CheckPhases(self.name, tuple(out))

    def phase_at(self, times) -> np.ndarray:
        """Phase index of each time [s] (start ≤ t < end), −1 outside any phase (ramps, after
        the end); int16."""
        return self.recorded().of_samples(times)

    # ------------------------------------------------------------------ knots
    def _speed_knots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(times, speeds, load factors): the load of each knot is load·factor [kernel sign]."""
        cos = 0.5 - 0.5 * np.cos(np.pi * np.linspace(0.0, 1.0, _COSINE_PIECES + 1))
        times, speeds, loads = [0.0], [0.0], [0.0]
        t = 0.0
        for p in self.phases:
            # ramp from the previous end to this phase's start (raised cosine)
            w0, f0 = speeds[-1], loads[-1]
            w1, f1 = self._start(p)
            times += list(t + p.ramp_time * cos[1:])
            speeds += list(w0 + (w1 - w0) * cos[1:])
            loads += list(f0 + (f1 - f0) * cos[1:])
            t += p.ramp_time
            if p.motion != "reversing":
                times.append(t + p.duration)
                speeds.append(w1)
                loads.append(f1)
            else:
                u, shape = self._reversal(p)
                keep = u > 0
                times += list(t + u[keep])
                speeds += list(p.speed * shape[keep])
                loads += list(_value(p.load) * np.sign(p.speed) * shape[keep])
            t += p.duration
        # back to rest over the last phase's ramp time
        w0, f0, ramp = speeds[-1], loads[-1], self.phases[-1].ramp_time
        times += list(t + ramp * cos[1:])
        speeds += list(w0 * (1.0 - cos[1:]))
        loads += list(f0 * (1.0 - cos[1:]))
        return np.asarray(times), np.asarray(speeds), np.asarray(loads)

    @staticmethod
    def _start(p: CheckPhase) -> tuple[float, float]:
        """Speed [rad/s] and load [N, kernel sign] at the start of a phase's settled part."""
        load = _value(p.load)
        if p.motion == "rest":
            return 0.0, load
        return p.speed, load * (1.0 if p.speed >= 0 else -1.0)

    @staticmethod
    def _reversal(p: CheckPhase) -> tuple[np.ndarray, np.ndarray]:
        """Times [s] from the phase start and the speed shape (+1 at the start, −1 half a
        period later) of a reversing phase: a cosine in pieces, or a triangle; cut at the
        phase's duration."""
        period = p.reversal_period
        pieces = 2 if p.reversal_shape == "linear" else 2 * _COSINE_PIECES
        u = np.arange(0.0, p.duration, period / pieces)
        u = np.append(u[u < p.duration - 1e-9], p.duration)
        if p.reversal_shape == "linear":
            shape = 4.0 * np.abs((u / period) % 1.0 - 0.5) - 1.0
        else:
            shape = np.cos(2 * np.pi * u / period)
        return u, shape

    def motion_knots(self) -> np.ndarray:
        """Piecewise-linear screw speed as a (3, K) array: times [s], speeds [rad/s], angles
        [rad] (the trapezoidal integral of the speed, exact for the piecewise-linear speed the
        kernel interpolates) — the format of OperatingProfile.motion_knots."""
        times, speeds, _ = self._speed_knots()
        from scipy.integrate import cumulative_trapezoid  # here: the CLI's --help loads no scipy

        angles = cumulative_trapezoid(speeds, times, initial=0.0)
        return np.vstack([times, speeds, angles])

    def load_knots(self) -> tuple[np.ndarray, float, float]:
        """Axial load as (2, K) knots [s, N] (kernel sign), no sinusoid (0, 0) — the format of
        OperatingProfile.load_knots. Refused while a load is a share of a rating."""
        if not self.is_resolved:
            shares = [p.name for p in self.phases if not isinstance(p.load, float)]
            raise ParameterError(
                "check.phases.load",
                ", ".join(f'"{n}"' for n in shares),
                f"health check {self.name!r} has loads given as shares of a rating: resolve "
                "them with the design's ratings first (HealthCheck.resolved, or give the "
                "scenario its design)",
            )
        times, _, loads = self._speed_knots()
        return np.vstack([times, loads]), 0.0, 0.0

    def travel(self, lead: float) -> tuple[float, float]:
        """Lowest and highest nut displacement [m] over the check for a screw ``lead`` [m/rev]
        (nut travel = lead × screw revolutions), from the start position."""
        angles = self.motion_knots()[2]
        return (
            float(np.min(angles)) * lead / (2 * math.pi),
            float(np.max(angles)) * lead / (2 * math.pi),
        )

    # ------------------------------------------------------------------ dict / TOML
    def as_dict(self) -> dict:
        return {"name": self.name, "phases": [p.as_dict() for p in self.phases]}

    @classmethod
    def from_dict(cls, data: dict) -> HealthCheck:
        """From ``{"name": …, "phases": [ … ]}`` or a file's tables ``{"check": {…}}``."""
        require(isinstance(data, dict), "check", data, "must be a table with name and phases")
        if set(data) == {"check"}:
            data = data["check"]
            require(isinstance(data, dict), "check", data, "must be a [check] table")
        require_known_keys("check", data, ["name", "phases"], required=["name", "phases"])
        phases = data["phases"]
        require(
            isinstance(phases, (list, tuple)),
            "check.phases",
            phases,
            "must be a list of [[check.phases]] tables",
        )
        return cls(name=data["name"], phases=tuple(phases))


def _value(load) -> float:
    """A phase's load in newtons, 0 for a share (only the load knots need it resolved)."""
    return load if isinstance(load, float) else 0.0


def _phase(value, index: int) -> CheckPhase:
    """A phase from a CheckPhase or its table; errors name the phase (index and name) and key."""
    if isinstance(value, CheckPhase):
        return value
    where = f"check.phases[{index}]"
    require(isinstance(value, dict), where, value, "must be a table of phase keys")
    named = f'{where} "{value["name"]}"' if isinstance(value.get("name"), str) else where
    require_known_keys(named, value, PHASE_KEYS, required=["name"])
    try:
        return CheckPhase(**value)
    except ParameterError as exc:  # name the phase by its place too
        field = exc.field.replace("check.phases", where, 1)
        raise ParameterError(field, exc.value, exc.allowed) from None


def load_check(source) -> HealthCheck:
    """A health check from a :class:`HealthCheck`, a built-in name (:data:`BUILT_IN`), a dict
    (:meth:`HealthCheck.from_dict`) or a TOML file with a ``[check]`` table."""
    if isinstance(source, HealthCheck):
        return source
    if isinstance(source, dict):
        return HealthCheck.from_dict(source)
    if isinstance(source, str) and source in BUILT_IN:
        return BUILT_IN[source]
    if isinstance(source, (str, Path)):
        path = Path(source)
        if path.suffix.lower() != ".toml" and not path.exists():
            raise ParameterError(
                "check",
                str(source),
                f"must be a built-in check ({', '.join(BUILT_IN)}) or a check TOML file",
            )
        return HealthCheck.from_dict(read_toml(path, "health check file"))
    raise ParameterError(
        "check", source, "must be a check name, a TOML file, a table or a HealthCheck"
    )


# ---------------------------------------------------------------------------- built-in check
# Numbers below are for the paper-01 PRSM (lead 10 mm, carrier/screw speed ratio 0.375) and hold
# for designs of similar size; loads are shares of the design's C_a, so they scale with it.
# Nut travel (lead × revolutions): the strokes alternate in direction and the whole check stays
# within ±46 mm of the start for a 10 mm lead (tests/actuator/test_health_check.py), the
# stroke of a flight-control EMA (engineering estimate: primary-surface EMAs have ±40–75 mm).
# Ramps: 50 ms raised cosines — 100 rad/s in 50 ms is a peak of 3 100 rad/s² on the screw, well
# inside what a servo drive gives, and short against the settled parts.
_RAMP = 0.05
BUILT_IN: dict[str, HealthCheck] = {
    "health-check": HealthCheck(
        name="health-check",
        phases=(
            # Preload: the nut's no-load axial resonance (spectral centroid of the axial
            # acceleration, 200–3000 Hz band; docs/faults.md). No load, so the preload alone
            # stiffens the flanks. 50 rad/s: the thread and gear passing excite the nut
            # broadly without the inertial loads of the fast strokes; 0.2 s is 4 000 samples at
            # 20 kHz, ~15 Welch segments of 512 (≈ 40 Hz bins against a 400–1200 Hz mode).
            CheckPhase(
                "no-load stroke", "constant", speed=50.0, load=0.0, duration=0.2, ramp_time=_RAMP
            ),
            # Lubricant: drive torque at a low and a high speed under one load (the ratio needs
            # neither a load cell nor k_t). 10 % C_a: a mid-duty load where friction is a
            # sizeable, measurable part of the torque. 10 rad/s for 0.4 s: 0.64 screw turns
            # (the torque mean is then within the ripple of one turn; mixed/boundary film at
            # this entrainment speed). Retracting: brings the nut back after the first stroke.
            CheckPhase(
                "low-speed stroke",
                "constant",
                speed=-10.0,
                load="10 % C_a",
                duration=0.4,
                ramp_time=_RAMP,
            ),
            # 100 rad/s (the spall measurements, nearer full film) for 0.15 s:
            # 2.4 screw turns, so the mean torque averages whole turns of lead-error ripple.
            CheckPhase(
                "high-speed stroke",
                "constant",
                speed=100.0,
                load="10 % C_a",
                duration=0.15,
                ramp_time=_RAMP,
            ),
            # Lost motion: a slow reversal against a known load, ±25 % C_a (≈ ±2.6 kN on
            # paper 01, the issue's ±3 kN where lost motion reads 62.6 → 87.0 µm over the
            # preload lost; ±300 N read nothing). ±10 rad/s cosine over 0.25 s: the nut swings
            # ±0.4 mm, crosses the play four times in 0.5 s at 250 rad/s² (slow: the flanks
            # change over without an impact).
            CheckPhase(
                "slow reversal",
                "reversing",
                speed=10.0,
                load="25 % C_a",
                duration=0.5,
                ramp_time=_RAMP,
                reversal_shape="cosine",
                reversal_period=0.25,
            ),
            # Spalls: synchronous averages over the carrier (nut-pass) period need ≥ 3 carrier
            # turns: 3/0.375 = 8 screw turns = 0.503 s at 100 rad/s; 0.52 s. 25 % C_a: the
            # highest load of the duty (EMAs run at 10–40 % of C_a; the issue measured nut
            # spalls at SNR 4–61 at 2.2–6.6 kN), far below C_0a (≈ 1.9 C_a on paper 01).
            # Retracting: 82 mm back, the longest stroke, centred on the start — with the load
            # aiding the motion (negative), so it presses the same flanks as a resisting load on
            # an extending stroke: the flanks that carry the service load, where spalls form
            # (faults.Spall, flank "loaded").
            CheckPhase(
                "high-load stroke",
                "constant",
                speed=-100.0,
                load="-25 % C_a",
                duration=0.52,
                ramp_time=_RAMP,
            ),
            # Clearance by physics: the slow reversal again at a lighter load, ±10 % C_a, so
            # the lost motion extrapolates to zero load and the unit's own stiffnesses drop out
            # of the reading (prsm_health.diagnostics.clearance_gauge: the reading's spread
            # over the documented bearing, coupling and lubricant ranges falls from ≈ 4 to
            # ≈ 0.2 µm of b). 10 % rather than 5 %: the extrapolation's weights grow the noise
            # ×2 at 10 %, and at 5 % the light reversal's own error doubled (measured,
            # tools/studies/clearance_gauge.py). Last, so the phases before it are the check
            # as it was (the models trained on them read the same phases).
            CheckPhase(
                "light reversal",
                "reversing",
                speed=10.0,
                load="10 % C_a",
                duration=0.5,
                ramp_time=_RAMP,
                reversal_shape="cosine",
                reversal_period=0.25,
            ),
        ),
    ),
    # The recirculating PRSM's (paper 03): its model turns forward only (a phase turning back
    # is refused), so no reversal — the clearance is read from the service's load reversals
    # instead — and no torque pair (the model has no friction). Numbers for the paper03 preset
    # (lead 1 mm: 0.6 s of check moves the nut ≈ 7 mm).
    "recirculating-check": HealthCheck(
        name="recirculating-check",
        phases=(
            # The nut's axial resonance on its threads without load, as the standard check's.
            CheckPhase(
                "no-load stroke", "constant", speed=60.0, load=0.0, duration=0.15, ramp_time=_RAMP
            ),
            # The reset comb at a commanded load, the phase the unit's baseline is compared in
            # (docs/faults.md: one recording at one load cannot place a spall's strike against
            # the resets' as well as the same unit at the same load can): paper 03's 40π rad/s,
            # 40 % C_a, 0.3 s = 29 roller passages (N·f_c = 97 Hz), above the 8 the comb needs.
            CheckPhase(
                "high-load stroke",
                "constant",
                speed=40 * math.pi,
                load="40 % C_a",
                duration=0.3,
                ramp_time=_RAMP,
            ),
        ),
    ),
}
