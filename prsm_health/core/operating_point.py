"""What a recording is of and how it ran, beside its samples: the actuator's design, its
reduction, and the nominal conditions (speed, load, swing, temperature) — :class:`OperatingPoint`,
carried by :attr:`Run.operating <prsm_health.core.run.Run.operating>`.

The diagnosis reads these (which design's model applies, the reduction the efficiency needs);
a dataset's ground truth (clearances, fault class, seed) stays in ``Run.labels``, which the
diagnosis never reads. The simulator fills the operating point from its scenario, the file
readers from the file's ``operating`` record — or, in files written before it, from the labels
that carried the same keys (:meth:`OperatingPoint.from_labels`) —, the service from its
request fields.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

from .errors import require
from .jsonable import as_finite

#: The design of a recording from a rig that is not a PRSM: the indicators that need a PRSM's
#: kinematics are NaN (an imported rig's labels say ``design = None``).
NO_DESIGN = "none"


#: Each number field of :class:`OperatingPoint`: (its lowest value or None for any, whether
#: that value is allowed, its unit).
_NUMBERS = {
    "gear_ratio": (0.0, False, "–"),
    "lead": (0.0, False, "m"),
    "screw_speed": (None, True, "rad/s"),
    "axial_load": (None, True, "N"),
    "load_amplitude": (0.0, True, "N"),
    "temperature": (0.0, False, "K"),
}


def _usable(name: str, value) -> float | None:
    """``value`` as a float when it is a valid ``name`` (a finite number in its range; numpy
    scalars too), else None (absent, None, NaN read back from a table, text, a bool)."""
    number = None if isinstance(value, str) else as_finite(value)
    low, inclusive, _ = _NUMBERS[name]
    if number is None or (low is not None and not (number >= low if inclusive else number > low)):
        return None
    return number


def _allowed(name: str) -> str:
    low, inclusive, unit = _NUMBERS[name]
    bound = "" if low is None else f" {'≥' if inclusive else '>'} {low:g}"
    return f"must be a finite number{bound} [{unit}]"


@dataclass(frozen=True)
class OperatingPoint:
    """The actuator a recording is of and the nominal conditions it ran at (SI).

    Every field may be unknown (None), as for a bare CSV recording; the readers then fall back
    as each field says.

    Parameters
    ----------
    design : str or None
        The design's name (a preset, or a design file's ``name``): for people, and for a
        recording that carries no design of its own, the preset it names. :data:`NO_DESIGN`:
        a rig that is not a PRSM. None: not said (the indicators take paper01).
    design_fingerprint : str or None
        Which design the recording is of (16 hex digits,
        :func:`~prsm_health.actuator.design_files.design_fingerprint`): a model refuses a
        recording whose fingerprint is not its design's. None: not said (compared by name).
    gear_ratio : float [–]
        Reduction N between the motor and the screw, > 0: ``drive_torque`` is the motor's
        torque, so the efficiency's input power is drive_torque × N × screw_speed. 1 when not
        said (direct drive, or a recording whose torque is taken as the screw's).
    lead : float or None [m per revolution of screw_angle]
        A rig without a PRSM design: the lead the lost-motion indicator needs. None: from the
        design.
    screw_speed : float or None [rad/s]
        Nominal screw speed (a health check: its top speed).
    axial_load : float or None [N]
        Nominal mean axial load, positive resisting (a health check: its peak load).
    load_amplitude : float or None [N]
        Nominal load swing, ≥ 0 (0 for a constant load and a health check).
    temperature : float or None [K]
        Lubricant temperature at the thread contacts, > 0.

    Raises
    ------
    ParameterError
        A field that is not a finite number in its range, naming it.
    """

    design: str | None = None
    design_fingerprint: str | None = None
    gear_ratio: float = 1.0
    lead: float | None = None
    screw_speed: float | None = None
    axial_load: float | None = None
    load_amplitude: float | None = None
    temperature: float | None = None

    def __post_init__(self) -> None:
        for name in ("design", "design_fingerprint"):
            value = getattr(self, name)
            require(
                value is None or isinstance(value, str),
                f"operating.{name}",
                value,
                "must be a string or None",
            )
        for name in _NUMBERS:
            value = getattr(self, name)
            if value is None and name != "gear_ratio":  # unknown; the gear ratio defaults to 1
                continue
            number = _usable(name, value)
            require(number is not None, f"operating.{name}", value, _allowed(name))
            object.__setattr__(self, name, number)

    def as_dict(self) -> dict:
        """The fields that are known (None left out): the ``operating`` record of files."""
        return {
            f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None
        }

    @classmethod
    def from_labels(cls, labels: Mapping) -> OperatingPoint:
        """The operating point a mapping with these field names gives — a file's ``operating``
        record, or the labels of a file written before it (which carried the same keys) —,
        read leniently: a value that is not usable (NaN read back from a table, text where a
        number belongs, a gear ratio ≤ 0) is taken as not said. A ``design`` key whose value
        is None or NaN is :data:`NO_DESIGN` (an imported rig that is not a PRSM)."""
        out: dict = {}
        if "design" in labels:
            name = labels["design"]
            out["design"] = name if isinstance(name, str) else NO_DESIGN
        fingerprint = labels.get("design_fingerprint")
        if isinstance(fingerprint, str):
            out["design_fingerprint"] = fingerprint
        for name in _NUMBERS:
            number = _usable(name, labels.get(name))
            if number is not None:
                out[name] = number
        return cls(**out)


#: Name of the operating point's record in file metadata: the MCAP Metadata record, and
#: ``prsm_health.operating`` in Parquet and Arrow schema metadata (JSON of
#: :meth:`OperatingPoint.as_dict`).
OPERATING_METADATA = "operating"
