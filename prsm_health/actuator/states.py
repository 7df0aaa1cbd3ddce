"""Health states, operating profiles and manufacturing variation of a simulated PRSM.

Frozen dataclasses grouped by lifetime: a :class:`HealthState` is what wears (clearances,
lubricant), an :class:`OperatingProfile` what the actuator is asked to do (screw motion, axial
load), :class:`ManufacturingVariation` the as-built scatter between rollers. All SI.

Sign convention for the axial load: ``load`` is the *resisting* force on the nut, positive when
it opposes the nut motion produced by a positive screw speed (a compressive load on an
extending actuator). Reversing load profiles swing it through zero.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from prsm_health.core.errors import (
    ParameterError,
    require,
    require_known_keys,
    require_positive,
    require_range,
)
from prsm_health.core.quantities import ForceSpec, parse_force
from prsm_health.core.tomlfile import read_toml

from .faults import fault_as_dict, fault_from_dict
from .health_check import HealthCheck, load_check

MOTIONS = ("constant", "ramp", "trapezoid", "reversing")
LOADS = ("constant", "sinusoidal", "reversing")
DRIVES = ("prescribed", "speed_loop", "position_loop")
RAMP_SHAPES = ("linear", "cosine")

#: The mean axial load of a run when none is given: 20 % of the design's basic dynamic axial
#: load rating C_a. Engineering estimate: electromechanical actuators run at roughly 10–40 % of
#: C_a (docs/formats.md → Loads; the ratings: docs/load-ratings.md), and a PRSM sized so that
#: its mean cubic load is 20 % of C_a has an L10 of (C_a/F_m)³·10⁶ = 1.25·10⁸ screw revolutions
#: (ISO 3408-5:2006 §5.2, the life law of ISO 281), ≈ 2200 h in motion at 100 rad/s — the order
#: of a flight-control EMA's life between overhauls. Light loads (1–3 % C_a) are run by giving
#: them.
DEFAULT_LOAD_SHARE = 0.2
#: :data:`DEFAULT_LOAD_SHARE` as the force the profile holds until a design resolves it.
DEFAULT_LOAD = ForceSpec(DEFAULT_LOAD_SHARE, "C_a")
#: The screw speed of an :class:`OperatingProfile` not told otherwise [rad/s].
DEFAULT_SPEED = 100.0
#: A share of a rating is at most this many times the rating (the scenario refuses anything
#: above the static rating C_0a anyway; this only catches a percentage written as a fraction).
_MAX_SHARE = 100.0


@dataclass(frozen=True)
class HealthState:
    """Wear and lubrication state.

    Parameters
    ----------
    clearance_screw, clearance_nut, clearance_gear : float [m]
        Half-clearance b on each flank of the screw–roller thread, roller–nut thread and roller
        gear mesh (paper 01's backlash function f(δ, b), total play 2b). Paper 01 §3.3 uses
        b_s = b_N = 10, 20, 30 µm.
    wear_spread : float [-]
        Uneven wear between rollers: roller i's thread clearances are scaled by
        (1 + wear_spread·u_i), u_i in [−1, 1] drawn from the run seed with mean zero over the
        rollers (:class:`~prsm_health.actuator.assembly.RollerDraws`: the unit's mean clearance
        stays ``clearance_*``). 0 = even wear.
    friction_scale : float [-]
        Multiplies the thread friction coefficients (1: as the lubrication model gives them).
    lubricant_degradation : float [-]
        0 (new) … 1: additive depletion raises boundary friction towards unprotected steel's,
        and the viscosity falls (:mod:`prsm_health.physics.lubrication`).
    lubricant_starvation : float [-]
        0 (fully flooded) … 1: the inlet is no longer replenished and the film thins to
        (1 − s) of the flooded one.
    preload : float [m]
        Installed axial interference on each flank of every roller's screw and nut threads
        (oversize rollers or a double nut): the realised half-clearance is b − preload, so with
        b = 0 and a preload both flanks touch at rest and there is no play while the preload
        holds. A :class:`~prsm_health.actuator.faults.PreloadLoss` fault takes a share of it away
        (:attr:`effective_preload`). Range 0–50 µm.
    faults : tuple
        Faults of :mod:`prsm_health.actuator.faults` (spalls, preload loss, …), default none; dicts
        with a ``kind`` key are converted.
    """

    clearance_screw: float = 10e-6
    clearance_nut: float = 10e-6
    clearance_gear: float = 10e-6
    wear_spread: float = 0.0
    friction_scale: float = 1.0
    lubricant_degradation: float = 0.0
    lubricant_starvation: float = 0.0
    preload: float = 0.0
    faults: tuple = ()

    def __post_init__(self):
        require(
            isinstance(self.faults, (list, tuple)),
            "health.faults",
            self.faults,
            "must be a list of fault tables",
        )
        object.__setattr__(self, "faults", tuple(fault_from_dict(f) for f in self.faults))
        for name in ("clearance_screw", "clearance_nut", "clearance_gear"):
            require_range(f"health.{name}", getattr(self, name), 0.0, 500e-6, unit="m")
        require_range("health.wear_spread", self.wear_spread, 0.0, 1.0)
        require_range("health.friction_scale", self.friction_scale, 0.0, 20.0)
        require_range("health.lubricant_degradation", self.lubricant_degradation, 0.0, 1.0)
        require_range("health.lubricant_starvation", self.lubricant_starvation, 0.0, 1.0)
        require_range("health.preload", self.preload, 0.0, 50e-6, unit="m")
        require(
            self.preload > 0 or not self.of_kind("preload_loss"),
            "faults.kind",
            "preload_loss",
            "needs a preload: set health.preload (the installed interference) > 0",
        )

    @classmethod
    def from_dict(
        cls, values: dict, table: str = "health", *, base: dict | HealthState | None = None
    ) -> HealthState:
        """From a health table: the fields, ``clearance`` as shorthand for screw, nut and gear,
        and ``faults`` as a list of tables (``[[faults]]``); unknown keys name the table.

        ``base`` (a health table read by the same rules, or a state) is what ``values`` is laid
        over: a key of ``values`` replaces the same key of ``base`` — its ``clearance``
        shorthand is first expanded to the keys it stands for, so ``clearance`` replaces every
        clearance of ``base`` unless ``values`` gives one of them too — and what ``values``
        does not name is kept. That is how ``prsm-health simulate``'s flags overlay a health
        file.
        """
        if isinstance(values, cls) and base is None:
            return values
        layered = cls._fields_of(values, table)
        if base is not None:
            layered = cls._fields_of(base, table) | layered
        return cls(**layered)

    @classmethod
    def _fields_of(cls, values, table: str) -> dict:
        """A health table (or state) as field → value: ``clearance`` expanded to the screw, nut
        and gear clearances the table does not give, unknown keys refused."""
        if isinstance(values, cls):
            return {f.name: getattr(values, f.name) for f in fields(cls)}
        require(isinstance(values, dict), table, values, "must be a table of parameters")
        values = dict(values)
        if "clearance" in values:
            clearance = values.pop("clearance")
            for key in ("clearance_screw", "clearance_nut", "clearance_gear"):
                values.setdefault(key, clearance)
        require_known_keys(table, values, ["clearance", *(f.name for f in fields(cls))])
        return values

    @classmethod
    def from_toml(cls, path) -> HealthState:
        """Read a health file: the :meth:`from_dict` table at the top level (docs/faults.md)."""
        return cls.from_dict(read_toml(path, "health file"))

    def of_kind(self, kind: str) -> tuple:
        """The faults of one kind (``"spall"``, ``"preload_loss"``, …)."""
        return tuple(f for f in self.faults if f.kind == kind)

    @property
    def spalls(self) -> tuple:
        return self.of_kind("spall")

    @property
    def effective_preload(self) -> float:
        """Interference left after preload loss [m]."""
        kept = 1.0
        for fault in self.of_kind("preload_loss"):
            kept *= 1.0 - fault.fraction
        return self.preload * kept

    @classmethod
    def uniform(cls, clearance: float, **kw) -> HealthState:
        """The same clearance on screw, nut and gear engagements [m]."""
        return cls(
            clearance_screw=clearance, clearance_nut=clearance, clearance_gear=clearance, **kw
        )

    def as_dict(self) -> dict:
        return {**asdict(self), "faults": [fault_as_dict(f) for f in self.faults]}


@dataclass(frozen=True)
class OperatingProfile:
    """Screw motion and axial load over a run.

    Parameters
    ----------
    duration : float [s]
    motion : {"constant", "ramp", "trapezoid", "reversing"}
        constant: ω from t = 0; ramp: 0 → ω over ``accel_time`` then constant; trapezoid:
        ramp up, hold, ramp down to rest at ``duration``; reversing: ±ω alternating every
        half ``motion_period`` with ``accel_time`` ramps through zero.
    speed : float [rad/s]
        Screw speed magnitude ω.
    accel_time : float [s]
    motion_period : float [s]
        Period of the reversing motion.
    load_profile : {"constant", "sinusoidal", "reversing"}
    load : float [N], str or ForceSpec
        Mean resisting axial load on the nut (see module docstring for the sign), in any form
        of :mod:`prsm_health.core.quantities`: newtons (``4400``), a unit (``"4.4 kN"``) or a
        share of the design's load rating (``"20 % C_a"``, ``"0.05 C_0a"``). Newtons are kept
        as a float; a share is kept as a :class:`~prsm_health.core.quantities.ForceSpec` until
        :meth:`resolved` turns it into newtons with the design's ratings (the
        :class:`~prsm_health.simulation.scenario.Scenario` does that on construction).
        Default :data:`DEFAULT_LOAD`, 20 % of C_a: an ``OperatingProfile()`` alone holds no
        design, so its default load is that share, resolved when a design is given.
    load_amplitude : float [N], str or ForceSpec
        Sinusoidal: amplitude around ``load``; reversing: the load swings ±``load_amplitude``
        around ``load`` as a trapezoidal wave with ``accel_time`` transitions. The same forms
        as ``load``; ≥ 0.
    load_frequency : float [Hz]
        Frequency of the sinusoidal or reversing load.
    load_ramp_time : float or None [s]
        Duration of each reversal of the reversing load; None: ``accel_time``.
    load_ramp_shape : {"linear", "cosine"}
        Shape of those reversals: a straight ramp, or a raised cosine (smooth, no jerk step).
    drive : {"prescribed", "speed_loop", "position_loop"}
        Prescribed motor angle (ideal servo); a PI speed loop on the motor speed; or a
        position loop (P, ``position_loop_gain``) cascaded on that speed loop, following the
        motion's angle — motion reversals as a position-controlled actuator makes them.
    speed_loop_bandwidth : float [Hz]
        Closed-loop bandwidth of the speed loop (sets the PI gains from motor + screw inertia).
    position_loop_gain : float [1/s]
        Proportional gain of the position loop (speed command per angle error).
    torque_limit : float [N·m]
        Motor torque limit of the speed loop.
    temperature : float [K]
        Lubricant temperature at the thread contacts (sets its viscosity; 223–473 K).
    check : HealthCheck, str, dict or None
        A health check (:mod:`prsm_health.actuator.health_check`): a built-in name
        (``"health-check"``), a check TOML file, its table or a HealthCheck. When given, the
        motion and the load are the check's (``motion``, ``speed``, ``load*`` … are not used
        for the knots) and ``duration`` is the check's (another explicit duration is refused).
    """

    duration: float = 0.2
    motion: str = "constant"
    speed: float = DEFAULT_SPEED
    accel_time: float = 0.02
    motion_period: float = 0.1
    load_profile: str = "constant"
    load: float | str | ForceSpec = DEFAULT_LOAD
    load_amplitude: float | str | ForceSpec = 0.0
    load_frequency: float = 20.0
    load_ramp_time: float | None = None
    load_ramp_shape: str = "linear"
    drive: str = "prescribed"
    speed_loop_bandwidth: float = 50.0
    position_loop_gain: float = 60.0
    torque_limit: float = 50.0
    temperature: float = 313.15
    check: HealthCheck | None = None

    def __post_init__(self):
        self._set_check()
        require_range("profile.duration", self.duration, 1e-4, 3600.0, unit="s")
        require(
            self.motion in MOTIONS,
            "profile.motion",
            self.motion,
            f"must be one of {', '.join(MOTIONS)}",
        )
        require(
            self.load_profile in LOADS,
            "profile.load_profile",
            self.load_profile,
            f"must be one of {', '.join(LOADS)}",
        )
        require(
            self.drive in DRIVES, "profile.drive", self.drive, f"must be one of {', '.join(DRIVES)}"
        )
        require_range("profile.speed", self.speed, 0.0, 2000.0, unit="rad/s")
        require_range("profile.accel_time", self.accel_time, 0.0, 10.0, unit="s")
        require_positive("profile.motion_period", self.motion_period)
        if self.motion == "reversing":
            require(
                0 < self.accel_time < self.motion_period / 2,
                "profile.accel_time",
                self.accel_time,
                f"must lie in (0, motion_period/2 = {self.motion_period / 2:g}) s for a "
                "reversing motion (the screw ramps through zero speed)",
            )
        if self.motion == "trapezoid":
            require(
                2 * self.accel_time < self.duration,
                "profile.accel_time",
                self.accel_time,
                f"must be < duration/2 = {self.duration / 2:g} s for a trapezoid",
            )
        self._set_force("load", low=-1e6)
        self._set_force("load_amplitude", low=0.0)
        require_range("profile.load_frequency", self.load_frequency, 0.0, 1e4, unit="Hz")
        require_positive("profile.speed_loop_bandwidth", self.speed_loop_bandwidth)
        require_range("profile.position_loop_gain", self.position_loop_gain, 0.0, 1e4, unit="1/s")
        if self.load_ramp_time is not None:
            require_range("profile.load_ramp_time", self.load_ramp_time, 0.0, 10.0, unit="s")
        require(
            self.load_ramp_shape in RAMP_SHAPES,
            "profile.load_ramp_shape",
            self.load_ramp_shape,
            f"must be one of {', '.join(RAMP_SHAPES)}",
        )
        require_positive("profile.torque_limit", self.torque_limit)
        require_range("profile.temperature", self.temperature, 223.15, 473.15, unit="K")

    def _set_check(self) -> None:
        """Convert ``check`` (name, file, table) to a HealthCheck and take its duration: the
        default duration is replaced, another one refused."""
        if self.check is None:
            return
        check = load_check(self.check)
        object.__setattr__(self, "check", check)
        default = next(f.default for f in fields(self) if f.name == "duration")
        require(
            self.duration in (default, check.duration)
            or math.isclose(self.duration, check.duration, rel_tol=1e-9),
            "profile.duration",
            self.duration,
            f"must be the health check's own ({check.duration:g} s for {check.name!r}) or "
            "left out: a check lasts as long as its phases",
        )
        object.__setattr__(self, "duration", check.duration)

    def _set_force(self, name: str, *, low: float) -> None:
        """Parse a load field (any form of :mod:`prsm_health.core.quantities`): newtons are
        kept as a float in [low, 1e6] N, a share of a rating as its ForceSpec."""
        field = f"profile.{name}"
        spec = parse_force(getattr(self, name), field)
        if spec.of is None:
            require_range(field, spec.value, low, 1e6, unit="N")
            object.__setattr__(self, name, spec.value)
            return
        lowest = -_MAX_SHARE if low < 0 else 0.0
        require(
            lowest <= spec.value <= _MAX_SHARE,
            field,
            spec.text(),
            f"a share of {spec.of} must lie in [{lowest:g}, {_MAX_SHARE:g}] × {spec.of}",
        )
        object.__setattr__(self, name, spec)

    # ------------------------------------------------------------------ loads against a design
    @property
    def is_resolved(self) -> bool:
        """True when ``load`` and ``load_amplitude`` are newtons (no share of a rating left)."""
        return not isinstance(self.load, ForceSpec) and not isinstance(
            self.load_amplitude, ForceSpec
        )

    def resolved(self, ratings) -> OperatingProfile:
        """This profile with ``load`` and ``load_amplitude`` in newtons.

        Parameters
        ----------
        ratings : dict or LoadRatings
            ``{"C_a": …, "C_0a": …}`` [N], or the
            :class:`~prsm_health.physics.load_rating.LoadRatings` of the design
            (``dynamic`` = C_a, ``static`` = C_0a).
        """
        ratings = rating_table(ratings)
        out = replace(
            self,
            load=parse_force(self.load, "profile.load").newtons(ratings, "profile.load"),
            load_amplitude=parse_force(self.load_amplitude, "profile.load_amplitude").newtons(
                ratings, "profile.load_amplitude"
            ),
        )
        check = getattr(out, "check", None)
        if check is not None:  # a health check's phases may give their loads as shares too
            out = replace(out, check=check.resolved(ratings))
        return out

    @property
    def peak_load(self) -> float:
        """Largest |axial load| of the run [N], from the load the kernel is given: |load|, plus
        the amplitude where the load swings (sinusoidal or reversing); a health check's
        highest phase load."""
        knots, amplitude, _ = self.load_knots()
        return float(np.max(np.abs(knots[1]))) + amplitude

    @property
    def top_speed(self) -> float:
        """Largest |screw speed| of the run [rad/s] (a health check's fastest phase)."""
        return float(np.max(np.abs(self.motion_knots()[1])))

    @property
    def rms_load(self) -> float:
        """RMS axial load over the run [N] (the knots sampled finely, plus a sinusoid's
        amplitude/√2): what heats a motor, against its continuous torque."""
        knots, amplitude, _ = self.load_knots()
        times = np.linspace(knots[0, 0], knots[0, -1], 4096)
        values = np.interp(times, knots[0], knots[1])
        return float(np.sqrt(np.mean(values**2) + 0.5 * amplitude**2))

    def _require_resolved(self, what: str) -> None:
        if self.is_resolved:
            return
        given = self.load if isinstance(self.load, ForceSpec) else self.load_amplitude
        name = "profile.load" if isinstance(self.load, ForceSpec) else "profile.load_amplitude"
        raise ParameterError(
            name,
            given.text(),
            f"a share of {given.of} needs the design's load ratings before the profile gives "
            f"its {what}: call profile.resolved(ratings), or build a Scenario (it resolves the "
            "profile against its design)",
        )

    # ------------------------------------------------------------------ knots for the kernel
    def motion_knots(self) -> np.ndarray:
        """Piecewise-linear screw speed as a (3, K) array: times [s], speeds [rad/s], angles [rad]."""
        if self.check is not None:
            return self.check.motion_knots()
        w, ta, T = self.speed, self.accel_time, self.duration
        if self.motion == "constant" or (self.motion == "ramp" and ta == 0):
            times, speeds = [0.0, T], [w, w]
        elif self.motion == "ramp":
            times, speeds = [0.0, ta, max(T, ta * 1.000001)], [0.0, w, w]
        elif self.motion == "trapezoid":
            times, speeds = [0.0, ta, T - ta, T], [0.0, w, w, 0.0]
        else:  # reversing: +ω, ramp through zero to −ω every half period
            half = self.motion_period / 2
            times, speeds = [0.0], [w]
            k = 1
            while k * half - ta / 2 < T:
                sign = 1.0 if k % 2 == 0 else -1.0
                times += [k * half - ta / 2, k * half + ta / 2]
                speeds += [-sign * w, sign * w]
                k += 1
            times.append(max(T, times[-1] + 1e-6))
            speeds.append(speeds[-1])
        times = np.asarray(times, dtype=float)
        speeds = np.asarray(speeds, dtype=float)
        # the angle: the speed's exact integral (trapezoids: the speed is linear between knots)
        from scipy.integrate import cumulative_trapezoid  # here: the CLI's --help loads no scipy

        angles = cumulative_trapezoid(speeds, times, initial=0.0)
        return np.vstack([times, speeds, angles])

    def load_knots(self) -> tuple[np.ndarray, float, float]:
        """Axial load as (2, K) knots [s, N] plus sinusoid amplitude [N] and frequency [Hz]
        (a resolved profile only: :meth:`resolved`)."""
        if self.check is not None:
            return self.check.load_knots()
        self._require_resolved("load knots")
        T, F = self.duration, self.load
        if self.load_profile == "constant":
            return np.array([[0.0, T], [F, F]]), 0.0, 0.0
        if self.load_profile == "sinusoidal":
            return np.array([[0.0, T], [F, F]]), self.load_amplitude, self.load_frequency
        # reversing: trapezoidal wave F ± A with linear or raised-cosine reversals
        A = self.load_amplitude
        half = 0.5 / self.load_frequency if self.load_frequency > 0 else T
        ramp_time = self.accel_time if self.load_ramp_time is None else self.load_ramp_time
        ramp = min(ramp_time, 0.5 * half) or 1e-6
        # a raised cosine as 16 linear pieces: within 0.5 % of the amplitude
        shape = np.linspace(0.0, 1.0, 2 if self.load_ramp_shape == "linear" else 17)
        if self.load_ramp_shape == "cosine":
            shape = 0.5 - 0.5 * np.cos(np.pi * shape)
        pieces = np.linspace(-0.5, 0.5, len(shape)) * ramp
        times, values = [0.0], [F + A]
        k = 1
        while k * half - ramp / 2 < T:
            start = F + A if k % 2 else F - A
            end = F - A if k % 2 else F + A
            times += list(k * half + pieces)
            values += list(start + (end - start) * shape)
            k += 1
        times.append(max(T, times[-1] + 1e-6))
        values.append(values[-1])
        return np.vstack([np.asarray(times), np.asarray(values)]), 0.0, 0.0

    @property
    def has_reversals(self) -> bool:
        """True when the motion or the load changes sign during the run."""
        if self.motion == "reversing":
            return True
        self._require_resolved("reversals")
        return self.load_profile in ("sinusoidal", "reversing") and self.load_amplitude > abs(
            self.load
        )

    def as_dict(self) -> dict:
        """The fields as plain values; a load still given as a share is its text
        (``"20 % C_a"``), which :class:`OperatingProfile` reads back."""
        out = asdict(self)
        for name in ("load", "load_amplitude"):
            value = getattr(self, name)
            if isinstance(value, ForceSpec):
                out[name] = value.text()
        if self.check is not None:
            out["check"] = self.check.as_dict()
        return out


def rating_table(ratings) -> dict[str, float]:
    """``{"C_a": …, "C_0a": …}`` [N] from such a dict or from a
    :class:`~prsm_health.physics.load_rating.LoadRatings` (``dynamic``, ``static``)."""
    if isinstance(ratings, dict):
        return ratings
    dynamic, static = getattr(ratings, "dynamic", None), getattr(ratings, "static", None)
    require(
        dynamic is not None and static is not None,
        "ratings",
        type(ratings).__name__,
        'must be {"C_a": …, "C_0a": …} [N] or the design\'s LoadRatings',
    )
    return {"C_a": float(dynamic), "C_0a": float(static)}


#: ISO 3408-3 lead-deviation tolerances by grade: (v_300p, v_2πp) [m] — travel variation within
#: 300 mm and within one revolution (grade 7 has no v_2πp in the standard: engineering value).
LEAD_GRADES = {1: (6e-6, 4e-6), 3: (12e-6, 6e-6), 5: (23e-6, 8e-6), 7: (52e-6, 10e-6)}


@dataclass(frozen=True)
class ManufacturingVariation:
    """As-built geometry errors, drawn per run from its seed (standard deviations or amplitudes).

    The papers give no tolerances. Defaults: a precision PRSM at ISO 3408-3 grade 5 (lead) with
    ground threads and ISO 1328-1 grade-6-class gears; :meth:`grade` gives the lead figures of
    other grades. They make the rollers share load unequally, break the perfect mesh-phase
    cancellation, and excite the threads along the screw, so steady running vibrates as on real
    hardware (docs/validation.md, excitation along the screw).

    Parameters
    ----------
    pitch_error : float [m]
        Axial position error of each roller's thread against screw and nut (σ).
    position_error : float [rad]
        Angular position error of each carrier pocket (σ).
    eccentricity : float [m]
        Radial position error of each pocket (σ).
    mesh_stiffness_spread : float [-]
        Relative scatter of each roller's gear mesh stiffness (σ).
    transmission_error : float [m]
        Static transmission-error offset of each roller gear along the line of action (σ).
    lead_error_cumulative : float [m]
        ISO 3408-3 v_300p: screw travel deviation accumulated over 300 mm; the run's lead
        deviation is drawn as N(0, (v_300p/2)²) per 300 mm (grade 5: 23 µm).
    lead_error_periodic : float [m]
        ISO 3408-3 v_2πp: peak-to-peak travel variation within one screw revolution (grade 5:
        8 µm), split over the 1st–3rd harmonics of the screw angle, random phases.
    screw_runout : float [m]
        Radial runout of the screw thread about the bearing axis (1st harmonic).
    roller_runout : float [m]
        Radial runout of each roller's thread about its spin axis (amplitude scale per roller).
    gear_pitch_error : float [m]
        Cumulative pitch deviation F_p of the ring gear (once per turn of a roller around it).
    gear_profile_error : float [m]
        Profile form deviation f_fα: transmission-error harmonics 1 and 2 of the mesh.
    flank_waviness : float [m]
        RMS waviness of the screw and nut flanks along the contact path, wavelengths 0.3–3 mm
        (shorter waves are averaged out by the contact ellipse), 6 components per flank.
    rolling_radius_error : float [m]
        Deviation of each roller's thread pitch (rolling) radius from the radius its gear's
        tooth count implies (σ, per roller), and of the nut thread's from its ring gear's (σ,
        one draw per unit). With its gear in mesh a roller rolling on the nut is
        over-constrained: the relative mismatch, ≈ Δr_nut/r_nut − Δr_roller/r_roller, loads the
        gears or makes the roller slip on the nut (Jones & Velinsky, J. Mech. Des. 134(6)
        061006, 2012). Engineering estimate: the rollers of one nut are ground and matched as a
        set, as the balls of a bearing are sorted (ISO 3290-1:2014 grade G16 allows 0.8 µm lot
        diameter variation), so 1 µm on the radius — ε ≈ 3·10⁻⁴ on a 3.25 mm roller.
    """

    pitch_error: float = 2e-6
    position_error: float = math.radians(0.02)
    eccentricity: float = 2e-6
    mesh_stiffness_spread: float = 0.03
    transmission_error: float = 1e-6
    lead_error_cumulative: float = LEAD_GRADES[5][0]
    lead_error_periodic: float = LEAD_GRADES[5][1]
    screw_runout: float = 5e-6
    roller_runout: float = 2e-6
    gear_pitch_error: float = 11e-6
    gear_profile_error: float = 5e-6
    flank_waviness: float = 0.25e-6
    rolling_radius_error: float = 1e-6

    def __post_init__(self):
        for name, high in (
            ("pitch_error", 1e-4),
            ("position_error", 0.05),
            ("eccentricity", 1e-4),
            ("mesh_stiffness_spread", 0.5),
            ("transmission_error", 1e-4),
            ("lead_error_cumulative", 1e-3),
            ("lead_error_periodic", 1e-4),
            ("screw_runout", 1e-4),
            ("roller_runout", 1e-4),
            ("gear_pitch_error", 1e-4),
            ("gear_profile_error", 1e-4),
            ("flank_waviness", 1e-5),
            ("rolling_radius_error", 1e-4),
        ):
            require_range(f"variation.{name}", getattr(self, name), 0.0, high)

    @classmethod
    def ideal(cls) -> ManufacturingVariation:
        """No scatter and no geometric error: every roller identical and exactly placed."""
        return cls(**{f.name: 0.0 for f in fields(cls)})

    @classmethod
    def grade(cls, grade: int, **overrides) -> ManufacturingVariation:
        """Lead errors of ISO 3408-3 tolerance grade 1, 3, 5 or 7; other fields as given."""
        require(
            grade in LEAD_GRADES, "variation.grade", grade, f"must be one of {sorted(LEAD_GRADES)}"
        )
        v_300p, v_2pi = LEAD_GRADES[grade]
        return cls(**{"lead_error_cumulative": v_300p, "lead_error_periodic": v_2pi, **overrides})

    @property
    def is_ideal(self) -> bool:
        return not any(asdict(self).values())

    def as_dict(self) -> dict:
        return asdict(self)
