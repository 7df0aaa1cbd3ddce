"""Sensor models: what each sensor of an instrumentation profile makes of a truth signal.

One class per kind of sensor (:data:`SENSOR_CLASSES`: each measured channel's); its fields are
datasheet figures (SI, or the unit aliases of ``ALIASES``), its ``measure`` turns the truth at the
integration rate into the channel at the sample rate (order: :mod:`.instrumentation`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import ClassVar

import numpy as np
from scipy import signal

from prsm_health.core.errors import (
    ParameterError,
    UnknownKeyError,
    require,
    require_range,
)

from .decimation import decimate

#: Standard gravity [m/s²] (datasheets state accelerations in g).
STANDARD_GRAVITY = 9.80665
ARCMIN = math.pi / (180.0 * 60.0)
#: Filters whose corner is above this fraction of the rate they run at are left out: their
#: effect lies beyond the band that rate resolves (the response is flat where it is logged).
_MAX_CORNER = 0.45
#: The two nut accelerations spanning the plane across each accelerometer axis (transverse
#: sensitivity). The sensor sits on the nut housing where the radial direction is x; a
#: radial_y sensor sits 90° away, where the x translation is its tangential direction.
TRANSVERSE = {
    "axial": ("tangential", "radial_x"),
    "tangential": ("axial", "radial_x"),
    "radial_x": ("axial", "tangential"),
    "radial_y": ("axial", "radial_x"),
}


# ----------------------------------------------------------------------------- signal blocks
def _lowpass_sos(corner: float, rate: float) -> np.ndarray | None:
    """The first-order low-pass at ``corner`` [Hz] run at ``rate``, None where it is left out."""
    if corner <= 0 or corner >= _MAX_CORNER * rate:
        return None
    return signal.butter(1, corner, btype="low", fs=rate, output="sos")


def _lowpass(x: np.ndarray, corner: float, rate: float) -> np.ndarray:
    """First-order causal low-pass at ``corner`` [Hz], started in steady state at x[0]."""
    sos = _lowpass_sos(corner, rate)
    if sos is None:
        return x
    return signal.sosfilt(sos, x, zi=signal.sosfilt_zi(sos) * x[0])[0]


def _group_delay(sos: np.ndarray | None, frequency: float, rate: float) -> float:
    """Group delay [s] at ``frequency`` of a filter run at ``rate`` (0 for no filter)."""
    if sos is None:
        return 0.0
    _, samples = signal.group_delay(signal.sos2tf(sos), w=[frequency], fs=rate)
    return float(samples[0]) / rate


def _highpass(x: np.ndarray, corner: float, rate: float) -> np.ndarray:
    """First-order causal high-pass (an AC-coupled sensor), settled on x[0] (output 0)."""
    if corner <= 0 or corner >= _MAX_CORNER * rate:
        return x
    sos = signal.butter(1, corner, btype="high", fs=rate, output="sos")
    return signal.sosfilt(sos, x, zi=signal.sosfilt_zi(sos) * x[0])[0]


def _resonance(x: np.ndarray, frequency: float, q: float, rate: float) -> np.ndarray:
    """Mounted-sensor resonance: ω²/(s² + s·ω/Q + ω²), unit gain at DC, peak ≈ Q at ``frequency``.

    Bilinear transform prewarped at the resonance, so the peak sits at the right frequency.
    """
    if frequency <= 0 or frequency >= _MAX_CORNER * rate:
        return x
    w = 2 * rate * math.tan(math.pi * frequency / rate)
    b, a = signal.bilinear([w * w], [1.0, w / q, w * w], fs=rate)
    sos = signal.tf2sos(b, a)
    return signal.sosfilt(sos, x, zi=signal.sosfilt_zi(sos) * x[0])[0]


def _s_curve(x: np.ndarray, span: float) -> np.ndarray:
    """Smooth odd S-shaped error shape, zero at mid-span and both ends, extreme ±1 inside.

    u = x / (span/2) clipped to ±1; e = (3√3/2)·(u − u³) peaks at ±1 for u = ±1/√3. Beyond the
    span the error stays 0 (the end-point straight line), documented as a simplification.
    """
    u = np.clip(x / (0.5 * span), -1.0, 1.0)
    return 1.5 * math.sqrt(3.0) * (u - u**3)


def _quantise(x: np.ndarray, step: float) -> np.ndarray:
    return np.round(x / step) * step if step > 0 else x


def _harmonics(angle: np.ndarray, orders, amplitudes, phases) -> np.ndarray:
    return sum(a * np.sin(k * angle + p) for k, a, p in zip(orders, amplitudes, phases))


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _truth(truth: dict, name: str, channel: str) -> np.ndarray:
    try:
        return np.asarray(truth[name], dtype=float)
    except KeyError:
        raise ValueError(
            f"{channel} reads the truth signal {name!r}, which the simulation did not provide "
            f"(got {', '.join(truth)})"
        ) from None


# ----------------------------------------------------------------------------- sensors
@dataclass(frozen=True)
class Sensor:
    """Common parts of a sensor spec: validation helpers, dict/TOML form, unit aliases.

    ``UNITS`` gives every field's unit; ``ALIASES`` the accepted datasheet-unit spellings
    (alias → (field, factor to SI, alias unit)).
    """

    KIND: ClassVar[str] = ""
    UNITS: ClassVar[dict[str, str]] = {}
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = {}

    device: str = ""

    def _validate(self) -> None:
        require(isinstance(self.device, str), "device", self.device, "must be a string")

    def _range(self, name: str, low: float, high: float) -> None:
        require_range(name, getattr(self, name), low, high, unit=self.UNITS.get(name, ""))

    def _integer(self, name: str, low: int, high: int) -> None:
        value = getattr(self, name)
        require(
            _is_int(value) and low <= value <= high,
            name,
            value,
            f"must be an integer in [{low}, {high}]",
        )

    def _harmonic_pairs(self, orders_name: str, amplitudes_name: str, high: float) -> None:
        """Two equally long lists (stored as tuples): integer orders ≥ 1, amplitudes in [0, high]."""
        for name in (orders_name, amplitudes_name):
            value = getattr(self, name)
            require(isinstance(value, (list, tuple)), name, value, "must be a list (TOML array)")
            object.__setattr__(self, name, tuple(value))
        orders, amplitudes = getattr(self, orders_name), getattr(self, amplitudes_name)
        unit = self.UNITS.get(amplitudes_name, "")
        require(
            all(_is_int(k) and k >= 1 for k in orders),
            orders_name,
            list(orders),
            "must be integers ≥ 1",
        )
        require(
            all(_is_number(a) and 0 <= a <= high for a in amplitudes),
            amplitudes_name,
            list(amplitudes),
            f"must be numbers in [0, {high:g}] {unit}".rstrip(),
        )
        require(
            len(orders) == len(amplitudes),
            amplitudes_name,
            list(amplitudes),
            f"needs one amplitude per entry of {orders_name} ({len(orders)})",
        )

    def group_delay(self, frequency: float, rate: float, factor: int) -> float:
        """The delay [s] the sensor's filters give a signal at ``frequency`` [Hz] (the truth at
        the integration ``rate``, logged every ``factor``-th sample), beyond the logger's
        anti-alias decimation (linear phase, no delay, common to every channel). Only the
        sensors that read a motion or a drive quantity model it."""
        raise ParameterError(
            "channel", self.KIND, "has no group-delay model (angle, speed, position, load, torque)"
        )

    def to_dict(self) -> dict:
        """Fields under their names, SI, tuples as lists."""
        return {
            f.name: list(getattr(self, f.name))
            if isinstance(getattr(self, f.name), tuple)
            else getattr(self, f.name)
            for f in fields(self)
        }

    def rows(self) -> list[tuple[str, object, str]]:
        """(field, value, unit) of every field."""
        return [(k, v, self.UNITS.get(k, "")) for k, v in self.to_dict().items()]

    @classmethod
    def allowed_keys(cls) -> list[str]:
        return [f.name for f in fields(cls)] + list(cls.ALIASES)

    @classmethod
    def from_table(cls, table: dict, where: str, start: Sensor | None = None) -> Sensor:
        """A spec from a TOML table (aliases converted) over ``start``'s fields (overrides).

        Errors name ``where.field`` and, for an unknown key, list the allowed keys.
        """
        known = {f.name for f in fields(cls)}
        values = start.to_dict() if start is not None else {}
        given_as: dict[str, str] = {}
        for key, value in table.items():
            if key in cls.ALIASES:
                name, factor, _ = cls.ALIASES[key]
                require(
                    name not in table,
                    f"{where}.{key}",
                    value,
                    f"give either {key} or {name}, not both",
                )
                if isinstance(value, list):
                    ok = all(_is_number(v) for v in value)
                    converted = [v * factor for v in value] if ok else value
                else:
                    ok = _is_number(value)
                    converted = value * factor if ok else value
                require(ok, f"{where}.{key}", value, "must be a number (or a list of numbers)")
                values[name] = converted
                given_as[name] = key
            elif key in known:
                values[key] = value
            else:
                raise UnknownKeyError(where, key, value, [*cls.allowed_keys(), "fitted"])
        try:
            return cls(**values)
        except ParameterError as exc:
            if exc.field in given_as:
                alias = given_as[exc.field]
                raise ParameterError(
                    f"{where}.{alias}",
                    table[alias],
                    f"{exc.allowed} after conversion to {exc.field} [{cls.UNITS.get(exc.field, '')}]",
                ) from None
            raise ParameterError(f"{where}.{exc.field}", exc.value, exc.allowed) from None


@dataclass(frozen=True)
class _ReportsOutput(Sensor):
    """A drive sensor that reports the reduction's output: its ``gear_ratio`` field is the drive
    train's (one declaration, bound by ``bind_drive_train``), neither a profile key nor written
    back."""

    @classmethod
    def allowed_keys(cls) -> list[str]:
        return [k for k in super().allowed_keys() if k != "gear_ratio"]

    @classmethod
    def from_table(cls, table: dict, where: str, start=None):
        if "gear_ratio" in table:
            raise UnknownKeyError(where, "gear_ratio", table["gear_ratio"], cls.allowed_keys())
        return super().from_table(table, where, start)

    def to_dict(self) -> dict:
        return {k: v for k, v in super().to_dict().items() if k != "gear_ratio"}


@dataclass(frozen=True)
class AngleSensor(_ReportsOutput):
    """Motor encoder or resolver with its converter → ``screw_angle`` (from ``motor_angle``).

    measured = [θ + Σ_k e_k·sin(k·p·θ + φ_k) + n, quantised to 2π/counts_per_rev] / N, read at
    f_s. The sensor sits on the motor, as in a real EMA; the drive reports the output angle, the
    reading divided by the reduction N (``gear_ratio``, bound from the drive train by
    :func:`bind_drive_train`, 1 for a direct drive), so every error of the sensor is N times
    finer on the screw and its harmonics sit at orders of the motor's turn (N× the screw's).
    θ: motor angle; p: ``pole_pairs`` (speed of the resolver, 1X = 1; encoders 1), so the
    ``harmonic_orders`` are orders of its electrical angle p·θ; φ_k uniform per run (a unit's
    own error pattern); n: white noise. Resolver errors are mainly the 1st (offsets) and 2nd
    (amplitude imbalance, quadrature) harmonics; an encoder's are once per turn (eccentricity)
    and its line count (interpolation).

    Parameters
    ----------
    counts_per_rev : int
        Output counts per mechanical revolution (0: not quantised).
    pole_pairs : int
    harmonic_orders : list of int
    harmonic_error : list of float [rad]
        Amplitude of each harmonic (alias ``harmonic_error_arcmin``).
    noise : float [rad]
        RMS white noise (alias ``noise_arcmin``).
    gear_ratio : float [-]
        Motor turns per screw turn; not a profile key: the drive train's, bound at run time.
    """

    KIND: ClassVar[str] = "angle sensor"
    UNITS: ClassVar[dict[str, str]] = {
        "counts_per_rev": "counts/rev",
        "harmonic_error": "rad",
        "noise": "rad",
    }
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = {
        "harmonic_error_arcmin": ("harmonic_error", ARCMIN, "arcmin"),
        "noise_arcmin": ("noise", ARCMIN, "arcmin"),
    }
    SOURCE: ClassVar[str] = "motor_angle"

    counts_per_rev: int = 0
    pole_pairs: int = 1
    harmonic_orders: tuple[int, ...] = ()
    harmonic_error: tuple[float, ...] = ()
    noise: float = 0.0
    gear_ratio: float = 1.0

    def __post_init__(self):
        self._validate()
        self._integer("counts_per_rev", 0, 2**40)
        self._integer("pole_pairs", 1, 64)
        self._harmonic_pairs("harmonic_orders", "harmonic_error", 0.1)
        self._range("noise", 0.0, 0.1)
        self._range("gear_ratio", 1.0, 1000.0)

    def group_delay(self, frequency: float, rate: float, factor: int) -> float:
        """0: the angle is read as it is (errors, noise, quantisation; no filter)."""
        return 0.0

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        theta = decimate(_truth(truth, self.SOURCE, channel), factor)
        phases = rng.uniform(0.0, 2 * np.pi, len(self.harmonic_orders))
        if self.harmonic_orders:
            theta = theta + _harmonics(
                self.pole_pairs * theta, self.harmonic_orders, self.harmonic_error, phases
            )
        if self.noise:
            theta = theta + rng.normal(0.0, self.noise, theta.shape)
        counts = _quantise(theta, 2 * np.pi / self.counts_per_rev if self.counts_per_rev else 0.0)
        return counts / self.gear_ratio if self.gear_ratio != 1.0 else counts


@dataclass(frozen=True)
class SpeedEstimate(_ReportsOutput):
    """The drive's speed estimate → ``screw_speed``, from the *measured* ``screw_angle``.

    As a servo drive computes it: backward difference of the sampled angle (ω[n] = (θ[n] −
    θ[n−1])·f_s), then a first-order low-pass at ``bandwidth`` (the velocity feedback filter),
    which smooths the quantisation and harmonic errors of the angle and delays the estimate.

    Parameters
    ----------
    bandwidth : float [Hz]
        Velocity filter corner (0: the raw difference).
    exact : bool
        The truth motor speed / N, decimated, instead of an estimate (the ``ideal`` profile
        only: no drive has it).
    gear_ratio : float [-]
        Motor turns per screw turn (the drive reports the output speed); bound from the drive
        train like :class:`AngleSensor`'s, not a profile key.
    """

    KIND: ClassVar[str] = "speed estimate"
    UNITS: ClassVar[dict[str, str]] = {"bandwidth": "Hz"}
    SOURCE: ClassVar[str] = "motor_speed"

    bandwidth: float = 0.0
    exact: bool = False
    gear_ratio: float = 1.0

    def __post_init__(self):
        self._validate()
        self._range("bandwidth", 0.0, 1e6)
        require(isinstance(self.exact, bool), "exact", self.exact, "must be true or false")
        self._range("gear_ratio", 1.0, 1000.0)

    def group_delay(self, frequency: float, rate: float, factor: int) -> float:
        """The backward difference's half sample plus the velocity filter's delay, both at the
        sample rate (0 when ``exact``)."""
        if self.exact:
            return 0.0
        sample_rate = rate / factor
        lowpass = _lowpass_sos(self.bandwidth, sample_rate)
        return 0.5 / sample_rate + _group_delay(lowpass, frequency, sample_rate)

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        if self.exact:
            speed = decimate(_truth(truth, self.SOURCE, channel), factor)
            return speed / self.gear_ratio if self.gear_ratio != 1.0 else speed
        angle = measured["screw_angle"]
        sample_rate = rate / factor
        speed = np.empty_like(angle)
        speed[1:] = np.diff(angle) * sample_rate
        speed[0] = speed[1] if len(speed) > 1 else 0.0
        return _lowpass(speed, self.bandwidth, sample_rate)


@dataclass(frozen=True)
class TorqueEstimate(Sensor):
    """Phase current × nominal torque constant → ``drive_torque`` (from ``motor_torque``).

    The MOTOR torque k_t·i, as a drive reports it: behind a reduction the screw gets N·η times
    it when the motor drives (N/η when the load drives back), less the reduction's dynamics.

    measured = g·LP(τ) + τ_r(θ) + n, where g = k_t,nominal / k_t,actual = 1 + N(0, gain_sigma)
    per run (torque-constant tolerance: the drive scales the current with the nameplate k_t);
    LP: first-order low-pass at ``bandwidth`` (the current loop: the real current lags the
    torque the simulated drive commands); τ_r = rated_torque·Σ_k r_k·sin(k·p·θ + φ_k), the
    cogging and torque ripple at orders of the electrical angle p·θ, which the shaft feels but
    the current does not show (the simulated motor has none, so here it is an error of the
    estimate; φ_k uniform per run); n: RMS current-sensor noise as torque.

    Parameters
    ----------
    gain_sigma : float [-]
        Standard deviation of g (alias ``gain_sigma_percent``).
    noise : float [N·m]
    bandwidth : float [Hz]
        Current-loop bandwidth (0: none).
    rated_torque : float [N·m] or None
        Reference of the ripple amplitudes. None (the built-in profiles): the drive train's
        motor's continuous torque, bound at run time (:func:`bind_drive_train`); a value given
        here wins (a recording whose motor is not the simulated one).
    pole_pairs : int or None
        Motor pole pairs; None: the drive train's motor's, bound at run time; a value wins.
    ripple_orders : list of int
    ripple : list of float [-]
        Fractions of ``rated_torque`` (alias ``ripple_percent``).
    """

    KIND: ClassVar[str] = "torque estimate"
    UNITS: ClassVar[dict[str, str]] = {
        "gain_sigma": "-",
        "noise": "N*m",
        "bandwidth": "Hz",
        "rated_torque": "N*m",
        "ripple": "-",
    }
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = {
        "gain_sigma_percent": ("gain_sigma", 0.01, "%"),
        "ripple_percent": ("ripple", 0.01, "% of rated_torque"),
    }
    SOURCE: ClassVar[str] = "motor_torque"

    gain_sigma: float = 0.0
    noise: float = 0.0
    bandwidth: float = 0.0
    rated_torque: float | None = None
    pole_pairs: int | None = None
    ripple_orders: tuple[int, ...] = ()
    ripple: tuple[float, ...] = ()

    #: Motor figures used while no drive train is bound (the direct drive's ~1 N·m, 4 pole pairs
    #: motor: prsm_health.actuator.drive_train.DriveTrain.direct).
    UNBOUND_RATED_TORQUE: ClassVar[float] = 1.0
    UNBOUND_POLE_PAIRS: ClassVar[int] = 4

    def __post_init__(self):
        self._validate()
        self._range("gain_sigma", 0.0, 0.5)
        self._range("noise", 0.0, 1e3)
        self._range("bandwidth", 0.0, 1e6)
        if self.rated_torque is not None:
            self._range("rated_torque", 0.0, 1e5)
            require(
                self.rated_torque > 0 or not any(self.ripple),
                "rated_torque",
                self.rated_torque,
                "must be > 0 when ripple is given (the ripple is a fraction of it)",
            )
        if self.pole_pairs is not None:
            self._integer("pole_pairs", 1, 64)
        self._harmonic_pairs("ripple_orders", "ripple", 0.5)

    def to_dict(self) -> dict:
        # None (= the drive train's motor) has no TOML form: such keys are left out.
        return {k: v for k, v in super().to_dict().items() if v is not None}

    def group_delay(self, frequency: float, rate: float, factor: int) -> float:
        """The current loop's low-pass, run at the integration rate."""
        return _group_delay(_lowpass_sos(self.bandwidth, rate), frequency, rate)

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        gain = 1.0 + rng.normal(0.0, self.gain_sigma)
        phases = rng.uniform(0.0, 2 * np.pi, len(self.ripple_orders))
        x = gain * _lowpass(_truth(truth, self.SOURCE, channel), self.bandwidth, rate)
        if self.ripple_orders:
            rated = (
                self.rated_torque if self.rated_torque is not None else self.UNBOUND_RATED_TORQUE
            )
            pairs = self.pole_pairs if self.pole_pairs is not None else self.UNBOUND_POLE_PAIRS
            electrical = pairs * _truth(truth, "motor_angle", channel)
            x = x + rated * _harmonics(electrical, self.ripple_orders, self.ripple, phases)
        y = decimate(x, factor)
        if self.noise:
            y = y + rng.normal(0.0, self.noise, y.shape)
        return y


@dataclass(frozen=True)
class _LinearTransducer(Sensor):
    """A transducer with a static characteristic: position sensor, load cell.

    measured = Q(LP(g·x + s·nonlinearity·full_scale·S(x) + d·t) + n), where g = 1 + N(0,
    gain_sigma) per run (sensitivity tolerance); S: the smooth odd S-shaped error of
    :func:`_s_curve` over ``full_scale`` (the span, centred on truth 0), sign s = ±1 per run;
    d = N(0, drift_sigma) per run (thermal zero drift, linear over the run); LP: first-order
    low-pass at ``bandwidth`` (the conditioning electronics); n: RMS white noise; Q:
    quantisation to ``resolution``.
    """

    SOURCE: ClassVar[str] = ""

    full_scale: float = 0.0
    nonlinearity: float = 0.0
    gain_sigma: float = 0.0
    drift_sigma: float = 0.0
    bandwidth: float = 0.0
    noise: float = 0.0
    resolution: float = 0.0

    def __post_init__(self):
        self._validate()
        self._range("full_scale", 0.0, 1e7)
        self._range("nonlinearity", 0.0, 0.2)
        self._range("gain_sigma", 0.0, 0.5)
        self._range("drift_sigma", 0.0, 1e3)
        self._range("bandwidth", 0.0, 1e6)
        self._range("noise", 0.0, 1e6)
        self._range("resolution", 0.0, 1e6)
        require(
            self.full_scale > 0 or self.nonlinearity == 0,
            "full_scale",
            self.full_scale,
            "must be > 0 when nonlinearity is given (it is a fraction of the full scale)",
        )

    def group_delay(self, frequency: float, rate: float, factor: int) -> float:
        """The conditioning electronics' low-pass, run at the integration rate."""
        return _group_delay(_lowpass_sos(self.bandwidth, rate), frequency, rate)

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        gain = 1.0 + rng.normal(0.0, self.gain_sigma)
        sign = 1.0 if rng.random() < 0.5 else -1.0
        drift = rng.normal(0.0, self.drift_sigma)
        truth_x = _truth(truth, self.SOURCE, channel)
        x = gain * truth_x
        if self.nonlinearity:
            x = x + sign * self.nonlinearity * self.full_scale * _s_curve(truth_x, self.full_scale)
        if self.drift_sigma:
            x = x + drift * np.arange(len(x)) / rate
        y = decimate(_lowpass(x, self.bandwidth, rate), factor)
        if self.noise:
            y = y + rng.normal(0.0, self.noise, y.shape)
        return _quantise(y, self.resolution)


def _linear_units(unit: str) -> dict[str, str]:
    """A linear transducer's parameter units when it measures in ``unit``."""
    return {
        "full_scale": unit,
        "nonlinearity": "-",
        "gain_sigma": "-",
        "drift_sigma": f"{unit}/s",
        "bandwidth": "Hz",
        "noise": unit,
        "resolution": unit,
    }


_LINEAR_ALIASES = {
    "nonlinearity_percent": ("nonlinearity", 0.01, "% of full_scale"),
    "gain_sigma_percent": ("gain_sigma", 0.01, "%"),
}


@dataclass(frozen=True)
class PositionSensor(_LinearTransducer):
    """LVDT on the rod or linear scale → ``nut_position`` (see :class:`_LinearTransducer`).

    Parameters
    ----------
    full_scale : float [m]
        Measuring span (stroke), centred on truth position 0.
    nonlinearity : float [-]
        Largest S-curve error as a fraction of ``full_scale`` (alias ``nonlinearity_percent``).
    gain_sigma : float [-]
    drift_sigma : float [m/s]
        Thermal zero drift rate, standard deviation over runs.
    bandwidth : float [Hz]
    noise : float [m]
    resolution : float [m]
    """

    KIND: ClassVar[str] = "position sensor"
    UNITS: ClassVar[dict[str, str]] = _linear_units("m")
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = _LINEAR_ALIASES
    SOURCE: ClassVar[str] = "nut_position"


@dataclass(frozen=True)
class LoadCell(_LinearTransducer):
    """Strain-gauge load cell in the linkage → ``axial_load`` (see :class:`_LinearTransducer`).

    Parameters
    ----------
    full_scale : float [N]
        Span: twice the rated capacity of a tension/compression cell.
    nonlinearity, gain_sigma : float [-]
    drift_sigma : float [N/s]
    bandwidth : float [Hz]
    noise, resolution : float [N]
    """

    KIND: ClassVar[str] = "load cell"
    UNITS: ClassVar[dict[str, str]] = _linear_units("N")
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = _LINEAR_ALIASES
    SOURCE: ClassVar[str] = "axial_load"


@dataclass(frozen=True)
class Accelerometer(Sensor):
    """Accelerometer on the nut housing → one ``nut_<axis>_accel`` channel (its axis).

    measured = clip(HP(LP(R(g·(a + t·(cos φ·a₁ + sin φ·a₂))))) → decimate → + n, then clip.
    a: truth acceleration of the sensor's axis; a₁, a₂: the two nut accelerations across it
    (:data:`TRANSVERSE`); t: ``transverse_sensitivity``, its direction φ uniform per run;
    g = 1 + N(0, gain_sigma) per run; R: mounted resonance (``resonance_frequency``,
    ``resonance_q``); LP, HP: first-order electrical low-/high-pass (``bandwidth``, ``highpass``:
    an AC-coupled piezo sensor); clip: ±``range`` (the sensor saturates, and the logger's input
    range is the sensor's); n: white noise of density ``noise_density`` over the logged band
    0…f_s/2 (RMS = density·√(f_s/2)), low-passed like the signal when ``bandwidth`` < f_s/2.

    Parameters
    ----------
    noise_density : float [m/s²/√Hz]
        (alias ``noise_density_ug`` in µg/√Hz)
    transverse_sensitivity : float [-]
        (alias ``transverse_sensitivity_percent``)
    resonance_frequency : float [Hz]
        Mounted resonance (0: none).
    resonance_q : float [-]
    bandwidth, highpass : float [Hz]
        0: none.
    gain_sigma : float [-]
        (alias ``gain_sigma_percent``)
    range : float [m/s²]
        Measuring range ± (0: unlimited; alias ``range_g``).
    """

    KIND: ClassVar[str] = "accelerometer"
    UNITS: ClassVar[dict[str, str]] = {
        "noise_density": "m/s^2/sqrt(Hz)",
        "transverse_sensitivity": "-",
        "resonance_frequency": "Hz",
        "resonance_q": "-",
        "bandwidth": "Hz",
        "highpass": "Hz",
        "gain_sigma": "-",
        "range": "m/s^2",
    }
    ALIASES: ClassVar[dict[str, tuple[str, float, str]]] = {
        "noise_density_ug": ("noise_density", 1e-6 * STANDARD_GRAVITY, "µg/√Hz"),
        "range_g": ("range", STANDARD_GRAVITY, "g"),
        "transverse_sensitivity_percent": ("transverse_sensitivity", 0.01, "%"),
        "gain_sigma_percent": ("gain_sigma", 0.01, "%"),
    }

    noise_density: float = 0.0
    transverse_sensitivity: float = 0.0
    resonance_frequency: float = 0.0
    resonance_q: float = 10.0
    bandwidth: float = 0.0
    highpass: float = 0.0
    gain_sigma: float = 0.0
    range: float = 0.0

    def __post_init__(self):
        self._validate()
        self._range("noise_density", 0.0, 1.0)
        self._range("transverse_sensitivity", 0.0, 0.5)
        self._range("resonance_frequency", 0.0, 1e7)
        self._range("resonance_q", 0.5, 1e4)
        self._range("bandwidth", 0.0, 1e7)
        self._range("highpass", 0.0, 1e3)
        self._range("gain_sigma", 0.0, 0.5)
        self._range("range", 0.0, 1e7)

    @staticmethod
    def axis(channel: str) -> str:
        """``nut_radial_x_accel`` → ``radial_x``."""
        return channel.removeprefix("nut_").removesuffix("_accel")

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        gain = 1.0 + rng.normal(0.0, self.gain_sigma)
        direction = rng.uniform(0.0, 2 * np.pi)
        x = _truth(truth, channel, channel)
        if self.transverse_sensitivity:
            first, second = (f"nut_{a}_accel" for a in TRANSVERSE[self.axis(channel)])
            x = x + self.transverse_sensitivity * (
                math.cos(direction) * _truth(truth, first, channel)
                + math.sin(direction) * _truth(truth, second, channel)
            )
        x = gain * x
        x = _resonance(x, self.resonance_frequency, self.resonance_q, rate)
        x = _highpass(_lowpass(x, self.bandwidth, rate), self.highpass, rate)
        if self.range:
            x = np.clip(x, -self.range, self.range)
        y = decimate(x, factor)
        sample_rate = rate / factor
        if self.noise_density:
            noise = rng.normal(0.0, self.noise_density * math.sqrt(0.5 * sample_rate), y.shape)
            y = y + _lowpass(noise, self.bandwidth, sample_rate)
        if self.range:
            y = np.clip(y, -self.range, self.range)
        return y


@dataclass(frozen=True)
class TemperatureSensor(Sensor):
    """Platinum RTD (Pt100/Pt1000) on the nut housing with its converter → ``housing_temperature``.

    measured = Q(H(L(T) + e_cal) + n): T the truth housing temperature, decimated; L a
    first-order lag of ``time_constant`` τ (the probe's thermal response: a probe in a bore of
    the housing follows it in seconds to minutes, whatever the logging rate), exact for the
    sampled signal (y[n] = y[n−1] + (1 − e^(−Δt/τ))·(x[n] − y[n−1])), started in steady state
    at the first sample; e_cal the per-run calibration error, uniform in ±(``tolerance`` +
    ``tolerance_slope``·|t|) with t the first truth sample in °C (the IEC 60751 class limit of
    the element: a class is an acceptance bound, uniform spreads the units over it) plus
    uniform in ±``converter_error`` (the conditioner's stated accuracy); H the converter's
    sample-and-hold: one conversion every ``update_interval`` (first at a uniform random phase)
    held until the next, each with its own noise n (RMS ``noise``); Q quantisation to
    ``resolution``. A simulated run is short against τ and its housing temperature is constant,
    so in a run the lag leaves the reading unchanged; it acts on a truth that changes.

    Parameters
    ----------
    tolerance : float [K]
        Constant term of the element's tolerance class (IEC 60751: 0.15 class A, 0.3 class B).
    tolerance_slope : float [-]
        Coefficient of |t| [°C] in the class limit (0.002 class A, 0.005 class B).
    converter_error : float [K]
        Bound of the conditioner/ADC error (0: calibrated with the element).
    time_constant : float [s]
        First-order thermal time constant of the mounted probe (0: none).
    noise : float [K]
        RMS noise of one conversion.
    resolution : float [K]
        Converter LSB (0: not quantised).
    update_interval : float [s]
        Time between conversions (0: a new value at every logged sample).
    """

    KIND: ClassVar[str] = "temperature sensor"
    UNITS: ClassVar[dict[str, str]] = {
        "tolerance": "K",
        "tolerance_slope": "-",
        "converter_error": "K",
        "time_constant": "s",
        "noise": "K",
        "resolution": "K",
        "update_interval": "s",
    }
    SOURCE: ClassVar[str] = "housing_temperature"
    #: 0 °C [K]: the class limit is a function of the Celsius temperature.
    ZERO_CELSIUS: ClassVar[float] = 273.15

    tolerance: float = 0.0
    tolerance_slope: float = 0.0
    converter_error: float = 0.0
    time_constant: float = 0.0
    noise: float = 0.0
    resolution: float = 0.0
    update_interval: float = 0.0

    def __post_init__(self):
        self._validate()
        self._range("tolerance", 0.0, 10.0)
        self._range("tolerance_slope", 0.0, 0.05)
        self._range("converter_error", 0.0, 10.0)
        self._range("time_constant", 0.0, 3600.0)
        self._range("noise", 0.0, 10.0)
        self._range("resolution", 0.0, 10.0)
        self._range("update_interval", 0.0, 60.0)

    def limit(self, temperature: float) -> float:
        """The class limit [K] of the element at ``temperature`` [K]."""
        return self.tolerance + self.tolerance_slope * abs(temperature - self.ZERO_CELSIUS)

    def measure(self, channel, truth, rate, factor, rng, measured) -> np.ndarray:
        # every draw is made whatever the fields, so changing one leaves the others' draws
        u_element, u_converter, phase = rng.uniform(-1.0, 1.0, 3)
        x = decimate(_truth(truth, self.SOURCE, channel), factor)
        if x.size == 0:
            return x
        sample_rate = rate / factor
        if self.time_constant > 0:
            # the probe's lag runs at the logged rate: its band (≪ 1 Hz) lies far below the
            # anti-alias filter, so it commutes with the decimation and is better conditioned
            a = math.exp(-1.0 / (sample_rate * self.time_constant))
            x = signal.lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])[0]
        x = x + u_element * self.limit(float(x[0])) + u_converter * self.converter_error
        held = int(round(self.update_interval * sample_rate))
        if held > 1:
            # conversion k covers the samples from start k; the first starts at a random phase
            offset = int((0.5 * (phase + 1.0)) * held) % held
            starts = np.r_[0, np.arange(held - offset if offset else held, x.size, held)]
            values = x[starts] + (rng.normal(0.0, self.noise, starts.size) if self.noise else 0)
            x = np.repeat(values, np.diff(np.r_[starts, x.size]))
        elif self.noise:
            x = x + rng.normal(0.0, self.noise, x.shape)
        return _quantise(x, self.resolution)


# ----------------------------------------------------------------------------- profile
#: Sensor class of every measured channel, in measuring order (the angle before the speed
#: estimate that differentiates it). The channel set is the contract's measured channels.
SENSOR_CLASSES: dict[str, type[Sensor]] = {
    "screw_angle": AngleSensor,
    "screw_speed": SpeedEstimate,
    "nut_position": PositionSensor,
    "nut_axial_accel": Accelerometer,
    "nut_tangential_accel": Accelerometer,
    "nut_radial_x_accel": Accelerometer,
    "nut_radial_y_accel": Accelerometer,
    "drive_torque": TorqueEstimate,
    "axial_load": LoadCell,
    # last: a new entry takes the next child stream, so the others' draws are unchanged
    "housing_temperature": TemperatureSensor,
}


def channel_group_delay(
    instrumentation, channel: str, frequency: float, integration_rate: float
) -> float:
    """The delay [s] the sensor of ``channel`` gives a signal at ``frequency`` [Hz]: its
    filters' group delay (:meth:`Sensor.group_delay`, scipy.signal.group_delay on the filter
    the sensor applies), the anti-alias decimation left out (linear phase, common to all).

    Parameters
    ----------
    instrumentation : Instrumentation
    channel : str
        A fitted channel whose sensor reads a motion or a drive quantity (``screw_angle``,
        ``screw_speed``, ``nut_position``, ``drive_torque``, ``axial_load``).
    frequency : float [Hz]
        Of the motion (a reversal's 1/period); well below a corner the delay barely depends on it.
    integration_rate : float [Hz]
        The rate the sensors' filters run at (a run's 1/``scenario["integration_step"]``); a
        multiple of the instrumentation's sample rate.
    """
    require(channel in SENSOR_CLASSES, "channel", channel, f"must be one of {list(SENSOR_CLASSES)}")
    spec = getattr(instrumentation, channel)
    require(spec is not None, "channel", channel, f"is not fitted in {instrumentation.name!r}")
    require_range("frequency", frequency, 0.0, 0.5 * instrumentation.sample_rate, unit="Hz")
    factor = int(round(integration_rate / instrumentation.sample_rate))
    require(factor >= 1, "integration_rate", integration_rate, "must be ≥ the sample rate")
    return spec.group_delay(frequency, integration_rate, factor)
