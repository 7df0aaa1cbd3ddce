"""Column maps (MAP.toml, docs/import.md): how a rig's table files name and scale the channels.

A map says which of a file's columns is which contract channel (:mod:`prsm_health.core.channels`,
plus ``time`` and ``motor_current``), in which unit, and where the time axis comes from (a
``time`` column or ``sample_rate``). :func:`load_column_map` reads and checks one;
:func:`apply_column_map` turns a table (CSV or Parquet, as a pandas DataFrame) into a
:class:`~prsm_health.core.run.Run` in SI. The one reader, :func:`prsm_health.io.read_recording`,
applies a map when given one; the importer, ``diagnose`` and the service all read through it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRESETS, PRSMDesign, require_metres
from prsm_health.actuator.design_files import design_fingerprint, design_reference, load_design
from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.errors import (
    ParameterError,
    PRSMHealthError,
    a_or_an,
    nearest_key,
    unknown_key_message,
)
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.core.tomlfile import read_toml, tomllib

from .frames import frame_column

#: Lowest sample rate a map's ``sample_rate`` may give [Hz].
MIN_RATE = 10.0
#: Quantity of each contract channel (and of ``time``, ``motor_current``).
QUANTITY = {
    "time": "time",
    "screw_angle": "angle",
    "screw_speed": "angular speed",
    "nut_position": "length",
    "nut_axial_accel": "acceleration",
    "nut_tangential_accel": "acceleration",
    "nut_radial_x_accel": "acceleration",
    "nut_radial_y_accel": "acceleration",
    "drive_torque": "torque",
    "axial_load": "force",
    "housing_temperature": "temperature",
    "motor_current": "current",
}
_G = 9.80665
#: Unit spelling → (quantity, factor to SI). Declared once; docs/import.md prints it.
UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0),
    "ms": ("time", 1e-3),
    "us": ("time", 1e-6),
    "m": ("length", 1.0),
    "mm": ("length", 1e-3),
    "um": ("length", 1e-6),
    "µm": ("length", 1e-6),
    "in": ("length", 0.0254),
    "rad": ("angle", 1.0),
    "deg": ("angle", math.pi / 180),
    "rev": ("angle", 2 * math.pi),
    "rad/s": ("angular speed", 1.0),
    "deg/s": ("angular speed", math.pi / 180),
    "rpm": ("angular speed", 2 * math.pi / 60),
    "N*m": ("torque", 1.0),
    "N·m": ("torque", 1.0),
    "Nm": ("torque", 1.0),
    "N*mm": ("torque", 1e-3),
    "N·mm": ("torque", 1e-3),
    "Nmm": ("torque", 1e-3),
    "A": ("current", 1.0),
    "mA": ("current", 1e-3),
    "N": ("force", 1.0),
    "kN": ("force", 1e3),
    "kgf": ("force", _G),
    "lbf": ("force", 4.4482216152605),
    "m/s^2": ("acceleration", 1.0),
    "m/s²": ("acceleration", 1.0),
    "mm/s^2": ("acceleration", 1e-3),
    "mm/s²": ("acceleration", 1e-3),
    "g": ("acceleration", _G),
    "K": ("temperature", 1.0),
    "degC": ("temperature", 1.0),
    "°C": ("temperature", 1.0),
}
#: Unit spelling → offset added after the factor (temperatures in Celsius → kelvin).
OFFSETS = {"degC": 273.15, "°C": 273.15}


def unit_slips(declared: str) -> dict[float, str]:
    """What a column declared in ``declared`` becomes if it is really in another unit of the
    same quantity: factor (SI values ÷ their true size) → that unit's first spelling; for the
    unit checks (:mod:`prsm_health.signals.unit_checks`) to name the likely unit."""
    quantity, scale = UNITS[declared]
    slips: dict[float, str] = {}
    for unit, (q, factor) in UNITS.items():
        if q == quantity and factor != scale:
            slips.setdefault(scale / factor, unit)
    return slips


MAP_KEYS = ("columns", "units", "sample_rate", "design", "lead", "torque_constant")
#: Largest accepted deviation of a time step from the median step (a fraction of it).
UNIFORM_TOLERANCE = 0.01


@dataclass(frozen=True)
class ColumnMap:
    """A parsed, checked column map.

    Attributes
    ----------
    columns : dict
        Channel name (or ``time``, ``motor_current``) → the file's column name.
    units : dict
        The file's column name → unit spelling (:data:`UNITS`); ``time`` defaults to ``s``.
    sample_rate : float or None [Hz]
        When the files have no time column.
    design : str, dict or None
        The rig's design: a preset name, or the full dict form
        (:meth:`~prsm_health.actuator.design.PRSMDesign.to_dict`) of the map's design file or
        inline ``[design]`` table — as a dataset recipe holds it. None: the rig is not a PRSM
        (design-dependent indicators NaN).
    lead : float or None [m/rev]
        Lead of a rig without a design (lost motion needs it).
    torque_constant : float or None [N·m/A]
        Turns a mapped ``motor_current`` into ``drive_torque``.
    source : dict
        The map's tables as read (stored in an imported dataset's manifest).
    """

    columns: dict[str, str]
    units: dict[str, str] = field(default_factory=dict)
    sample_rate: float | None = None
    design: str | dict | None = None
    lead: float | None = None
    torque_constant: float | None = None
    source: dict = field(default_factory=dict)

    @property
    def prsm_design(self) -> PRSMDesign | None:
        """The rig's design (None: not a PRSM)."""
        return None if self.design is None else load_design(self.design)

    def operating(self) -> OperatingPoint:
        """What a mapped run's operating point holds: the design's name and fingerprint for
        a PRSM, the ``lead`` when given."""
        design = self.prsm_design
        return OperatingPoint(
            design=None if design is None else design.name,
            design_fingerprint=None if design is None else design_fingerprint(design),
            lead=self.lead,
        )

    def scenario(self) -> dict:
        """What a mapped run's ``scenario`` holds: the design as a simulated run's scenario
        holds it (a preset name or the dict form), so
        :func:`~prsm_health.actuator.design_files.design_of` and the indicators find the full
        design; empty for a rig that is not a PRSM."""
        return {} if self.design is None else {"design": self.design}


def load_column_map(path: str | Path) -> ColumnMap:
    """Read and check a MAP.toml; errors name the file and the key. A ``design`` file is
    read relative to the map's folder."""
    path = Path(path)
    return parse_column_map(read_toml(path, "column map"), str(path), base=path.parent)


def column_map_from_text(text: str | bytes, name: str = "map") -> ColumnMap:
    """Parse and check a column map given as TOML text (an upload); ``name`` names it.

    Such a map has no folder: its ``design`` is a preset or an inline ``[design]`` table, never
    a file (an upload must not name a file of the server)."""
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError:
            raise PRSMHealthError(
                f"{name}: not a text file (expected a column map in TOML)"
            ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise PRSMHealthError(f"{name}: not valid TOML ({exc})") from None
    return parse_column_map(data, name)


def parse_column_map(data: dict, where: str = "map", *, base: Path | None = None) -> ColumnMap:
    """Check a column map's tables; errors start with ``where`` (the file) and name the key.

    ``base`` is the folder a ``design`` file's relative path is read against; None (a map
    given as text) refuses a design file."""
    unknown = sorted(set(data) - set(MAP_KEYS))
    if unknown:  # named as design files name theirs: the nearest key, the allowed ones
        key = unknown[0]
        raise PRSMHealthError(f"{where}: {unknown_key_message('map', key, data[key], MAP_KEYS)}")
    columns = data.get("columns")
    if not isinstance(columns, dict) or not columns:
        raise PRSMHealthError(
            f"{where}: [columns] must map channel names to your files' column names"
        )
    for name, column in columns.items():
        if name not in QUANTITY:
            nearest = nearest_key(name, QUANTITY)
            hint = "" if nearest is None else f" (did you mean {nearest!r}?)"
            raise PRSMHealthError(
                f"{where}: [columns] {name!r} is not a channel{hint}; use time, motor_current or "
                f"one of {', '.join(CHANNEL_NAMES)}"
            )
        if not isinstance(column, str) or not column:
            raise PRSMHealthError(f"{where}: [columns] {name} = {column!r} must be a column name")
    units = data.get("units", {})
    if not isinstance(units, dict):
        raise PRSMHealthError(f"{where}: [units] must map column names to units")
    for name, column in columns.items():
        unit = units.get(column, "s" if name == "time" else None)
        if unit is None:
            raise PRSMHealthError(f"{where}: [units] gives no unit for column {column!r} ({name})")
        if unit not in UNITS:
            raise PRSMHealthError(
                f"{where}: unit {unit!r} of column {column!r} is not understood; accepted: "
                f"{', '.join(UNITS)}"
            )
        if UNITS[unit][0] != QUANTITY[name]:
            accepted = [u for u, (q, _) in UNITS.items() if q == QUANTITY[name]]
            raise PRSMHealthError(
                f"{where}: column {column!r} ({name}) is {a_or_an(QUANTITY[name])}, but its "
                f"unit {unit!r} is {a_or_an(UNITS[unit][0])}; use one of {', '.join(accepted)}"
            )
    stray = sorted(set(units) - set(columns.values()))
    if stray:
        raise PRSMHealthError(
            f"{where}: [units] names column(s) {', '.join(stray)} that [columns] does not map"
        )
    rate = data.get("sample_rate")
    if ("time" in columns) == (rate is not None):
        raise PRSMHealthError(
            f"{where}: give either a time column ([columns] time = …) or sample_rate [Hz], "
            "not both or neither"
        )
    if rate is not None and not (
        isinstance(rate, (int, float)) and not isinstance(rate, bool) and rate >= MIN_RATE
    ):
        raise PRSMHealthError(f"{where}: sample_rate = {rate!r} must be a number ≥ {MIN_RATE:g} Hz")
    for key in ("lead", "torque_constant"):
        value = data.get(key)
        if value is not None and not (isinstance(value, (int, float)) and value > 0):
            raise PRSMHealthError(f"{where}: {key} = {value!r} must be a positive number")
    try:
        require_metres("lead", data.get("lead"))
    except ParameterError as exc:
        raise PRSMHealthError(f"{where}: {exc}") from None
    if "motor_current" in columns:
        if data.get("torque_constant") is None:
            raise PRSMHealthError(
                f"{where}: motor_current needs torque_constant [N·m/A] to become drive_torque"
            )
        if "drive_torque" in columns:
            raise PRSMHealthError(f"{where}: map motor_current or drive_torque, not both")
    return ColumnMap(
        columns=dict(columns),
        units=dict(units),
        sample_rate=None if rate is None else float(rate),
        design=_map_design(data.get("design"), where, base),
        lead=data.get("lead"),
        torque_constant=data.get("torque_constant"),
        source=data,
    )


def _map_design(design, where: str, base: Path | None) -> str | dict | None:
    """A map's ``design`` as a recipe holds it: a preset name as is, a design file (relative to
    ``base``) or an inline ``[design]`` table as the checked design's dict form."""
    if design is None or (isinstance(design, str) and design in PRESETS):
        return design
    usage = (
        f"a preset ({', '.join(sorted(PRESETS))}), a design TOML file (relative to the map) or "
        "an inline [design] table; leave it out for a rig that is not a PRSM"
    )
    if isinstance(design, dict):
        design = dict(design)
        # the map's stem names an inline design that does not name itself
        design.setdefault("name", Path(where).stem or "design")
    elif not isinstance(design, str):
        raise PRSMHealthError(f"{where}: design = {design!r} must be {usage}")
    elif base is None:
        raise PRSMHealthError(
            f"{where}: design = {design!r} names a file, which a map given as text cannot "
            f"read; use a preset ({', '.join(sorted(PRESETS))}) or an inline [design] table"
        )
    elif not design.endswith(".toml"):
        raise PRSMHealthError(f"{where}: design = {design!r} must be {usage}")
    try:
        return design_reference(design, base=base)
    except PRSMHealthError as exc:
        raise PRSMHealthError(f"{where}: design: {exc}") from None


def apply_column_map(frame, spec: ColumnMap, where: str) -> Run:
    """A table (pandas DataFrame of a CSV or Parquet file) through ``spec``, as a Run in SI.

    Time starts at 0 (a logger's clock may be wall time); the run's operating point is the
    map's (:meth:`ColumnMap.operating`), its scenario holds the map's design
    (:meth:`ColumnMap.scenario`); no labels (a recording has no ground truth).
    Errors name ``where`` (the file), the column and, for a cell
    that is not a number, its data row.
    """
    missing = [c for c in spec.columns.values() if c not in frame.columns]
    if missing:
        raise PRSMHealthError(
            f"{where}: no column(s) {', '.join(map(repr, missing))} (the map's [columns]); the "
            f"file has {', '.join(map(str, list(frame.columns)[:10]))}"
        )
    values = {}
    for name, column in spec.columns.items():
        unit = spec.units.get(column, "s")
        values[name] = frame_column(frame, column, where) * UNITS[unit][1] + OFFSETS.get(unit, 0.0)
    n = len(frame)
    if "time" in values:
        time = values.pop("time")
        steps = np.diff(time)
        if n < 2 or not np.all(steps > 0):
            raise PRSMHealthError(f"{where}: time must increase strictly")
        rate = 1.0 / float(np.median(steps))
        if np.max(np.abs(steps - 1 / rate)) > UNIFORM_TOLERANCE / rate:
            raise PRSMHealthError(
                f"{where}: time is not uniformly sampled (steps vary by > {UNIFORM_TOLERANCE:.0%})"
            )
        time = time - time[0]
    else:
        rate = spec.sample_rate
        time = np.arange(n) / rate
    if "motor_current" in values:
        values["drive_torque"] = values.pop("motor_current") * spec.torque_constant
    return Run(time, values, rate, scenario=spec.scenario(), operating=spec.operating())
