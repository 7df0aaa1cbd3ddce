"""Instrumentation profiles: the sensors an actuator carries, and what each makes of the truth.

The simulator gives *truth* signals at its integration rate f_int (motor_angle, motor_speed,
motor_torque, nut_position, nut_*_accel, axial_load, …: the channel contract). An
:class:`Instrumentation` fits at most one sensor per measured channel and turns the truth into
the fitted channels at its sample rate f_s = f_int / m (m an integer):

- ``screw_angle``: :class:`AngleSensor` (motor encoder or resolver) reads motor_angle;
- ``screw_speed``: :class:`SpeedEstimate`, the drive's estimate from the measured screw_angle;
- ``nut_position``: :class:`PositionSensor` (LVDT or linear scale) reads nut_position;
- ``nut_*_accel``: :class:`Accelerometer` reads the nut acceleration of its axis (and, through
  its transverse sensitivity, the two across it);
- ``drive_torque``: :class:`TorqueEstimate` (phase current × nominal k_t) reads motor_torque;
- ``axial_load``: :class:`LoadCell` reads axial_load;
- ``housing_temperature``: :class:`TemperatureSensor` (an RTD on the nut housing) reads the truth
  housing_temperature (prsm_health.simulation.thermal: the contact temperature less the
  contact-to-housing rise).

Order of operations inside every sensor: what the sensor does to the continuous signal —
gain error, cross-axis coupling, nonlinearity, drift, bandwidth, mounting resonance,
saturation — acts on the integration-rate signal; the logger then decimates with its
anti-alias filter (:func:`prsm_health.simulation.decimation.decimate`); white noise and quantisation come
last, at f_s. Digital position sensors (encoder, resolver-to-digital converter) are read at f_s,
so their periodic angle error is evaluated at the sample instants and aliases as in a drive.

Every random per-run quantity (a gain error, the phase of an error harmonic, a drift rate) and
every noise sample comes from the generator handed to :meth:`Instrumentation.measure`, through
one child stream per measured channel: a seed gives a bit-identical run, and fitting or
removing one sensor leaves the others' draws unchanged.

Profiles are TOML files; the built-ins (:func:`list_profiles`) ship in
``prsm_health/simulation/instrumentation_profiles/`` with every figure's source (docs/instrumentation.md).
Fields are SI; a few datasheet units are accepted as aliases whose name says the unit
(``noise_density_ug`` in µg/√Hz, ``range_g`` in g, ``harmonic_error_arcmin``, ``*_percent``)
and converted at load.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from prsm_health.core.errors import (
    ParameterError,
    a_or_an,
    require,
    require_known_keys,
    require_range,
)
from prsm_health.core.tomlfile import read_toml, toml_value

from .sensors import (
    SENSOR_CLASSES,
    Accelerometer,
    AngleSensor,
    LoadCell,
    PositionSensor,
    Sensor,
    SpeedEstimate,
    TemperatureSensor,
    TorqueEstimate,
)

#: Built-in profile files, and the profile used wherever none is named.
PROFILE_DIR = Path(__file__).with_name("instrumentation_profiles")
DEFAULT_PROFILE = "flight-ema"
DEFAULT_SAMPLE_RATE = 20_000.0


def sensor_rng(sensors_seed: int) -> np.random.Generator:
    """The random stream every sensor of a run draws from (its own child per channel, in
    :meth:`Instrumentation.measure`): the run's sensor seed and the tag "SENS"."""
    return np.random.default_rng([sensors_seed, 0x53454E53])


def bind_drive_train(instrumentation, drive_train):
    """The instrumentation with its drive sensors bound to ``drive_train`` (one declaration of
    the motor and the reduction): the angle sensor and the speed estimate report the output
    (reading / N); the torque estimate takes its ripple reference (the motor's continuous
    torque, or :attr:`TorqueEstimate.UNBOUND_RATED_TORQUE` if the drive train gives none) and
    pole pairs from the motor, unless the profile gives them. Unfitted sensors stay unfitted.
    """
    from dataclasses import replace

    changes = {}
    ratio = float(drive_train.gear_ratio)
    for channel in ("screw_angle", "screw_speed"):
        spec = getattr(instrumentation, channel, None)
        if spec is not None:
            changes[channel] = replace(spec, gear_ratio=ratio)
    torque = getattr(instrumentation, "drive_torque", None)
    if torque is not None:
        rated = torque.rated_torque
        if rated is None:
            rated = drive_train.continuous_torque or TorqueEstimate.UNBOUND_RATED_TORQUE
        pairs = torque.pole_pairs if torque.pole_pairs is not None else drive_train.pole_pairs
        changes["drive_torque"] = replace(torque, rated_torque=rated, pole_pairs=pairs)
    return replace(instrumentation, **changes) if changes else instrumentation


_TOP_KEYS = ("name", "description", "sample_rate")


@dataclass(frozen=True)
class Instrumentation:
    """The sensors of an actuator and the logger's sample rate.

    One attribute per measured channel: its sensor spec, or None where no sensor is fitted.
    Build from a profile with :func:`load_instrumentation`.

    Parameters
    ----------
    name, description : str
    sample_rate : float [Hz]
        Output rate f_s; the integration rate is an integer multiple of it.
    screw_angle : AngleSensor or None
    screw_speed : SpeedEstimate or None
    nut_position : PositionSensor or None
    nut_axial_accel, nut_tangential_accel, nut_radial_x_accel, nut_radial_y_accel :
        Accelerometer or None
    drive_torque : TorqueEstimate or None
    axial_load : LoadCell or None
    housing_temperature : TemperatureSensor or None
    """

    name: str = "custom"
    description: str = ""
    sample_rate: float = DEFAULT_SAMPLE_RATE
    screw_angle: AngleSensor | None = None
    screw_speed: SpeedEstimate | None = None
    nut_position: PositionSensor | None = None
    nut_axial_accel: Accelerometer | None = None
    nut_tangential_accel: Accelerometer | None = None
    nut_radial_x_accel: Accelerometer | None = None
    nut_radial_y_accel: Accelerometer | None = None
    drive_torque: TorqueEstimate | None = None
    axial_load: LoadCell | None = None
    housing_temperature: TemperatureSensor | None = None

    def __post_init__(self):
        require(
            isinstance(self.name, str) and self.name != "",
            "instrumentation.name",
            self.name,
            "must be a non-empty string",
        )
        require(
            isinstance(self.description, str),
            "instrumentation.description",
            self.description,
            "must be a string",
        )
        require_range("instrumentation.sample_rate", self.sample_rate, 100.0, 1e6, unit="Hz")
        for channel, kind in SENSOR_CLASSES.items():
            spec = getattr(self, channel)
            require(
                spec is None or isinstance(spec, kind),
                f"instrumentation.{channel}",
                type(spec).__name__,
                f"must be {a_or_an(kind.__name__)} or None",
            )
        require(
            bool(self.fitted),
            "instrumentation",
            self.name,
            f"fits no sensor; fit at least one of {', '.join(SENSOR_CLASSES)}",
        )
        speed = self.screw_speed
        require(
            speed is None or speed.exact or self.screw_angle is not None,
            "instrumentation.screw_speed",
            "fitted",
            "is estimated from the measured screw_angle: fit screw_angle too",
        )

    @property
    def fitted(self) -> tuple[str, ...]:
        """Names of the measured channels this profile gives, in measuring order."""
        return tuple(ch for ch in SENSOR_CLASSES if getattr(self, ch) is not None)

    def sensors(self) -> dict:
        """Fitted channel → sensor spec."""
        return {ch: getattr(self, ch) for ch in self.fitted}

    def measure(
        self, truth_raw: dict[str, np.ndarray], integration_rate: float, rng
    ) -> dict[str, np.ndarray]:
        """The fitted measured channels at :attr:`sample_rate` from truth at ``integration_rate``.

        Parameters
        ----------
        truth_raw : dict of name → ndarray [SI]
            Truth signals at the integration rate (the names each fitted sensor reads).
        integration_rate : float [Hz]
            An integer multiple of :attr:`sample_rate`.
        rng : numpy.random.Generator
            Source of every random quantity (one child stream per measured channel).

        Returns
        -------
        dict of fitted channel → float64 ndarray at :attr:`sample_rate`
        """
        factor = int(round(integration_rate / self.sample_rate))
        require(
            factor >= 1
            and abs(factor * self.sample_rate - integration_rate) < 1e-6 * integration_rate,
            "instrumentation.sample_rate",
            self.sample_rate,
            f"must divide the integration rate {integration_rate:g} Hz",
        )
        streams = rng.integers(0, 2**63 - 1, size=len(SENSOR_CLASSES))
        out: dict[str, np.ndarray] = {}
        for (channel, _), seed in zip(SENSOR_CLASSES.items(), streams):
            spec = getattr(self, channel)
            if spec is not None:
                child = np.random.default_rng(int(seed))
                out[channel] = spec.measure(
                    channel, truth_raw, integration_rate, factor, child, out
                )
        return out

    # ------------------------------------------------------------------ dict / TOML / display
    def to_dict(self) -> dict:
        """Complete dict form (no ``profile`` key): :func:`load_instrumentation` reads it back."""
        out = {"name": self.name, "description": self.description, "sample_rate": self.sample_rate}
        out.update({ch: spec.to_dict() for ch, spec in self.sensors().items()})
        return out

    def toml_tables(self, prefix: str | None = None) -> list[str]:
        """The complete form as TOML lines (under ``[prefix]`` if given, e.g. in a scenario)."""
        data = self.to_dict()
        lines = [f"[{prefix}]"] if prefix else []
        lines += [f"{k} = {toml_value(data.pop(k))}" for k in _TOP_KEYS]
        for channel, values in data.items():
            table = f"{prefix}.{channel}" if prefix else channel
            lines += ["", f"[{table}]"] + [f"{k} = {toml_value(v)}" for k, v in values.items()]
        return lines

    def describe(self) -> dict:
        """Everything a person needs: each fitted sensor with its kind, what it reads, and every
        parameter with its unit (``prsm-health instrumentation show``)."""
        return {
            "name": self.name,
            "description": self.description,
            "sample_rate": self.sample_rate,
            "sensors": {
                channel: {
                    "kind": spec.KIND,
                    "reads": _reads(channel, spec),
                    "parameters": [{"name": k, "value": v, "unit": u} for k, v, u in spec.rows()],
                }
                for channel, spec in self.sensors().items()
            },
        }


def _reads(channel: str, spec: Sensor) -> str:
    if isinstance(spec, Accelerometer):
        return channel
    if isinstance(spec, SpeedEstimate) and not spec.exact:
        return "screw_angle (measured)"
    return spec.SOURCE


# ----------------------------------------------------------------------------- loading
def list_profiles() -> tuple[str, ...]:
    """Names of the built-in profiles."""
    return tuple(sorted(p.stem for p in PROFILE_DIR.glob("*.toml")))


@functools.cache
def _builtin(name: str) -> Instrumentation:
    path = PROFILE_DIR / f"{name}.toml"
    return _from_table(read_toml(path, "instrumentation profile"), path.parent, name)


def load_instrumentation(
    source: str | Path | dict | Instrumentation, base: Path | None = None
) -> Instrumentation:
    """An instrumentation from a built-in name, a profile TOML file, a dict, or as is.

    Parameters
    ----------
    source : str, Path, dict or Instrumentation
        A built-in name (:func:`list_profiles`); a path to a profile TOML file (relative to
        ``base``, else the working directory); or the dict form. A dict or file either is
        complete (``name``, ``description``, ``sample_rate`` and one table per fitted channel)
        or starts from another profile: ``profile = "flight-ema"`` (or a file) plus overrides —
        ``sample_rate``, ``name``, ``description``, and per-channel tables whose keys replace
        the sensor's fields (``[nut_axial_accel] noise_density_ug = 40``), fit a sensor the
        profile lacks, or remove one (``fitted = false``).
    base : Path, optional

    Raises
    ------
    ParameterError
        An unknown profile name (the message lists the built-ins), an unknown key (the message
        names the table and lists the allowed keys) or a value out of range.
    """
    if isinstance(source, Instrumentation):
        return source
    if isinstance(source, dict):
        return _from_table(source, base, "custom")
    if isinstance(source, str) and source in list_profiles():
        return _builtin(source)
    if not isinstance(source, (str, Path)) or not str(source):
        raise ParameterError(
            "instrumentation", source, "must be a profile name, a profile TOML file or a table"
        )
    path = Path(source)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    if path.suffix != ".toml" and not path.exists():
        raise ParameterError(
            "instrumentation",
            str(source),
            f"unknown profile; built-in profiles: {', '.join(list_profiles())} "
            "(or a profile TOML file, *.toml)",
        )
    return _from_table(read_toml(path, "instrumentation profile"), path.parent, path.stem)


def _from_table(data: dict, base: Path | None, default_name: str) -> Instrumentation:
    """A profile from its dict form: complete, or ``profile = …`` plus overrides."""
    data = dict(data)
    allowed = ["profile", *_TOP_KEYS, *SENSOR_CLASSES]
    require_known_keys("instrumentation", data, allowed)
    if "profile" in data:
        ref = data.pop("profile")
        require(
            isinstance(ref, (str, Path)),
            "instrumentation.profile",
            ref,
            f"must be a profile name ({', '.join(list_profiles())}) or a profile TOML file",
        )
        start = load_instrumentation(ref, base)
        values = {f.name: getattr(start, f.name) for f in fields(start)}
    else:
        values = {"name": default_name}
    values.update({k: data.pop(k) for k in _TOP_KEYS if k in data})
    for channel, table in data.items():
        where = f"instrumentation.{channel}"
        require(
            isinstance(table, dict),
            where,
            table,
            "must be a table of sensor parameters (or fitted = false)",
        )
        table = dict(table)
        fitted = table.pop("fitted", True)
        require(isinstance(fitted, bool), f"{where}.fitted", fitted, "must be true or false")
        if not fitted:
            require(not table, where, sorted(table), "fitted = false takes no other key")
            values[channel] = None
            continue
        kind = SENSOR_CLASSES[channel]
        values[channel] = kind.from_table(table, where, values.get(channel))
    return Instrumentation(**values)


def instrumentation_ref(instrumentation: Instrumentation) -> str | dict:
    """The built-in name if ``instrumentation`` is an unmodified built-in, else its full dict."""
    name = instrumentation.name
    if name in list_profiles() and instrumentation == _builtin(name):
        return name
    return instrumentation.to_dict()


__all__ = [
    "DEFAULT_PROFILE",
    "Instrumentation",
    "instrumentation_ref",
    "list_profiles",
    "load_instrumentation",
]
