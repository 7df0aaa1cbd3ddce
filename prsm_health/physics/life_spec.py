"""What a life recipe's ``[life]`` table says (:class:`LifeSpec`): the duty cycle a unit does over
its operating hours (:class:`DutyCycle`), the unit-to-unit scatter of a fleet
(:class:`FleetScatter`), the failure limits — the inputs of the life simulation
(:mod:`prsm_health.physics.life`), each field checked with its name and range."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace

from prsm_health.core.errors import require, require_known_keys, require_positive, require_range
from prsm_health.core.quantities import ForceSpec, parse_force

from .lubrication import DEFAULT_LUBRICANT, lubricant
from .wear import WearParameters

#: The duty cycle's default load spectrum, as shares of the design's basic dynamic axial load
#: rating C_a, and the share of motion time at each. The same duty as the recordings of
#: datasets/fleet.toml and datasets/flight-ema-reference.toml (a reversing load of mean
#: ±5 % C_a swinging by 2–30 % C_a, drawn per recording): the |load| those recordings see,
#: split at its 50th and 85th percentiles, has the cubic means 10.5, 21 and 29 % C_a — so the
#: life model wears and fatigues a unit under the loads it is recorded at (tests/physics/
#: test_life.py checks it). Engineering estimate of a flight EMA's service (10–40 % of C_a,
#: docs/load-ratings.md); its mean cubic load, 19 % C_a, gives an ISO 281 L10 of 1.4·10⁸ screw
#: revolutions.
DEFAULT_DUTY_LOADS = ("10 % C_a", "20 % C_a", "30 % C_a")
DEFAULT_DUTY_SHARES = (0.5, 0.35, 0.15)


def _pair(table: str, name: str, value, lo: float, hi: float, unit: str = "-") -> tuple:
    require(
        isinstance(value, (list, tuple))
        and len(value) == 2
        and all(isinstance(v, (int, float)) for v in value)
        and lo <= value[0] <= value[1] <= hi,
        f"{table}.{name}",
        value,
        f"must be a range [min, max] within [{lo:g}, {hi:g}] {unit}",
    )
    return (float(value[0]), float(value[1]))


@dataclass(frozen=True)
class DutyCycle:
    """What a unit does over its operating hours (SI).

    Parameters
    ----------
    speed : float [rad/s]
        Screw speed while it moves.
    stroke : float [m]
        Travel of the reciprocating stroke (spreads the screw's wear track).
    loads : tuple of float [N] or str
        Axial load spectrum: the loads the unit carries while it moves, in any form of
        :mod:`prsm_health.core.quantities` — newtons, ``"1.5 kN"``, or a share of the
        design's rating (``"20 % C_a"``), resolved against the design by :meth:`resolved`
        (:func:`unit_life` does). Default :data:`DEFAULT_DUTY_LOADS` …
    shares : tuple of float [-]
        … and the share of motion time at each (sum 1).
    motion_fraction : float [-]
        Share of operating hours in motion.
    temperature : float [K]
        Lubricant temperature in service.
    lubricant_life : float [h]
        Operating hours until the lubricant's additives are used up, at 70 °C.
    change_age : float [h] or None
        From this age on the unit works at ``change_load`` × its loads (a new mission, a
        heavier surface); None: the same duty all its life.
    change_load : float [-]
        The loads' factor after ``change_age``.
    """

    speed: float = 100.0
    stroke: float = 0.05
    loads: tuple = DEFAULT_DUTY_LOADS
    shares: tuple = DEFAULT_DUTY_SHARES
    motion_fraction: float = 0.3
    temperature: float = 323.15
    lubricant_life: float = 2000.0
    change_age: float | None = None
    change_load: float = 1.0

    def __post_init__(self):
        require(
            isinstance(self.loads, (list, tuple)),
            "life.duty.loads",
            self.loads,
            "must be a list of loads (N, '1.5 kN' or '20 % C_a')",
        )
        object.__setattr__(self, "loads", tuple(_duty_load(v) for v in self.loads))
        object.__setattr__(self, "shares", tuple(float(v) for v in self.shares))
        require_range("life.duty.speed", self.speed, 1e-3, 2000.0, unit="rad/s")
        require_range("life.duty.stroke", self.stroke, 0.0, 5.0, unit="m")
        require(
            len(self.loads) >= 1 and len(self.loads) == len(self.shares),
            "life.duty.shares",
            list(self.shares),
            f"needs one share per load ({len(self.loads)} loads)",
        )
        for value in self.loads:
            if isinstance(value, ForceSpec):
                require(
                    abs(value.value) <= 100.0,
                    "life.duty.loads",
                    value.text(),
                    f"a share of {value.of} must lie in [-100, 100] × {value.of}",
                )
            else:
                require_range("life.duty.loads", value, -1e6, 1e6, unit="N")
        require(
            all(s >= 0 for s in self.shares) and abs(sum(self.shares) - 1.0) < 1e-6,
            "life.duty.shares",
            list(self.shares),
            "must be ≥ 0 and sum to 1",
        )
        require_range("life.duty.motion_fraction", self.motion_fraction, 1e-4, 1.0)
        require_range("life.duty.temperature", self.temperature, 223.15, 473.15, unit="K")
        require_range("life.duty.lubricant_life", self.lubricant_life, 1.0, 1e7, unit="h")
        if self.change_age is not None:
            require_range("life.duty.change_age", self.change_age, 0.0, 1e7, unit="h")
        require_range("life.duty.change_load", self.change_load, 0.1, 10.0)

    @property
    def is_resolved(self) -> bool:
        """True when every load is in newtons."""
        return not any(isinstance(v, ForceSpec) for v in self.loads)

    def resolved(self, ratings) -> DutyCycle:
        """This duty with its loads in newtons against ``ratings`` (``{"C_a": …, "C_0a": …}``
        [N], or the design's :class:`~prsm_health.physics.load_rating.LoadRatings`); a load
        above the static rating C_0a is refused."""
        if not isinstance(ratings, dict):
            ratings = {"C_a": float(ratings.dynamic), "C_0a": float(ratings.static)}
        loads = tuple(parse_force(v).newtons(ratings, "life.duty.loads") for v in self.loads)
        most = max(1.0, self.change_load if self.change_age is not None else 1.0)
        for given, value in zip(self.loads, loads):
            require(
                "C_0a" not in ratings or abs(value) * most <= ratings["C_0a"],
                "life.duty.loads",
                given.text() if isinstance(given, ForceSpec) else given,
                f"is {value:.4g} N, above the design's static load rating C_0a = "
                f"{ratings['C_0a']:.4g} N (permanent deformation of the threads: ISO 76)",
            )
        return replace(self, loads=loads)

    def as_dict(self) -> dict:
        """The fields as plain values; a load given as a share is its text (``"20 % C_a"``)."""
        out = asdict(self)
        out["loads"] = [v.text() if isinstance(v, ForceSpec) else v for v in self.loads]
        return out


def _duty_load(value):
    """A duty load: newtons as a float, a share of a rating as its ForceSpec."""
    spec = parse_force(value, "life.duty.loads")
    return spec.value if spec.of is None else spec


@dataclass(frozen=True)
class FleetScatter:
    """Unit-to-unit scatter of a fleet: each unit draws its own values.

    Parameters
    ----------
    initial_clearance : (min, max) [m]
        Half-clearance as built (uniform).
    wear_coefficient : float [-]
        σ of ln k: the wear coefficient's lognormal scatter (material, finish).
    load_scale : (min, max) [-]
        Multiplies the duty cycle's loads (each unit's own usage; uniform).
    temperature : (min, max) [K]
        Added to the duty cycle's temperature (uniform).
    lubricant_life : float [-]
        σ of ln T_lube (lognormal).
    wear_spread : (min, max) [-]
        Uneven load sharing between rollers, hence uneven wear (uniform; the health state's
        ``wear_spread`` is this times the share of the clearance that is wear).
    usage : float [-]
        σ of the log of the unit's usage intensity (how hard it works compared with the duty
        cycle: missions, loads, idle spells), which wanders as a mean-reverting
        (Ornstein–Uhlenbeck) process with correlation time ``usage_time``: wear speeds up and
        slows down over a unit's life, so no two units, and no unit's two halves of life, wear
        alike. 0: the duty cycle exactly. Default 0.15: a season's usage of units flying the
        same missions differs by ≈ ±15 % (engineering estimate; docs/prognostics.md shows the
        RUL scores at 0 … 0.3).
    usage_time : float [h]
        Correlation time of the usage intensity (a season of operation).
    """

    initial_clearance: tuple = (3e-6, 8e-6)
    wear_coefficient: float = 0.4
    load_scale: tuple = (0.8, 1.25)
    temperature: tuple = (-10.0, 10.0)
    lubricant_life: float = 0.3
    wear_spread: tuple = (0.0, 0.3)
    usage: float = 0.15
    usage_time: float = 200.0

    def __post_init__(self):
        t = "life.scatter"
        object.__setattr__(
            self,
            "initial_clearance",
            _pair(t, "initial_clearance", self.initial_clearance, 0.0, 100e-6, "m"),
        )
        object.__setattr__(self, "load_scale", _pair(t, "load_scale", self.load_scale, 0.0, 10.0))
        object.__setattr__(
            self, "temperature", _pair(t, "temperature", self.temperature, -100.0, 100.0, "K")
        )
        object.__setattr__(self, "wear_spread", _pair(t, "wear_spread", self.wear_spread, 0.0, 1.0))
        require_range(f"{t}.wear_coefficient", self.wear_coefficient, 0.0, 3.0)
        require_range(f"{t}.lubricant_life", self.lubricant_life, 0.0, 3.0)
        require_range(f"{t}.usage", self.usage, 0.0, 2.0)
        require_range(f"{t}.usage_time", self.usage_time, 1e-3, 1e6, unit="h")


@dataclass(frozen=True)
class LifeSpec:
    """The ``[life]`` table of a fleet recipe: units, duty cycle, snapshots, failure.

    Parameters
    ----------
    units : int
        Units in the fleet.
    snapshots : int
        Ages per unit a recording is made at: k/snapshots of its life (k = 0 … snapshots − 1).
    recordings : int
        Recordings at each of those ages, each with its own recording conditions and sensor
        noise (a monitor's several windows of one inspection); their diagnoses are combined
        into one history row per age (:func:`prsm_health.prognostics.fleet_histories`).
    failure_clearance : float [m]
        The unit fails when its mean thread half-clearance reaches this.
    failure_spall_length : float [m]
        … or when a spall grows this long.
    max_age : float [h]
        A unit that has not failed by then is an error (raise the duty or the wear).
    lubricant : str
        Built-in lubricant (its film sets the asperity load share).
    duty, scatter, wear
        :class:`DutyCycle`, :class:`FleetScatter`, :class:`~prsm_health.physics.wear.WearParameters`.
    """

    units: int = 20
    snapshots: int = 30
    recordings: int = 1
    failure_clearance: float = 30e-6
    failure_spall_length: float = 3e-3
    max_age: float = 2e5
    lubricant: str = DEFAULT_LUBRICANT
    duty: DutyCycle = field(default_factory=DutyCycle)
    scatter: FleetScatter = field(default_factory=FleetScatter)
    wear: WearParameters = field(default_factory=WearParameters)

    def __post_init__(self):
        for name, most in (("units", 100_000), ("snapshots", 100_000), ("recordings", 100)):
            value = getattr(self, name)
            require(
                isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= most,
                f"life.{name}",
                value,
                f"must be an integer in [1, {most}]",
            )
        require_range("life.failure_clearance", self.failure_clearance, 1e-6, 500e-6, unit="m")
        require_range("life.failure_spall_length", self.failure_spall_length, 1e-4, 10e-3, unit="m")
        require_positive("life.max_age", self.max_age)
        lubricant(self.lubricant)  # a known name, or the error naming the choices
        require(
            self.failure_clearance > self.scatter.initial_clearance[1],
            "life.failure_clearance",
            self.failure_clearance,
            f"must exceed the largest initial clearance {self.scatter.initial_clearance[1]:g} m",
        )

    @classmethod
    def from_dict(cls, values: dict) -> LifeSpec:
        """From the recipe's ``[life]`` table (``[life.duty]``, ``[life.scatter]``,
        ``[life.wear]`` nested); unknown keys name the table."""
        require(isinstance(values, dict), "life", values, "must be a table")
        values = dict(values)
        require_known_keys("life", values, [f.name for f in fields(cls)])
        groups = {"duty": DutyCycle, "scatter": FleetScatter}
        for name, kind in groups.items():
            table = values.get(name, {})
            require(isinstance(table, dict), f"life.{name}", table, "must be a table")
            require_known_keys(f"life.{name}", table, [f.name for f in fields(kind)])
            values[name] = kind(**table)
        values["wear"] = WearParameters.from_dict(values.get("wear", {}))
        return cls(**values)

    def as_dict(self) -> dict:
        return {**asdict(self), "duty": self.duty.as_dict()}
