"""Faults of a health state, and the fault taxonomy of run labels.

A :class:`~prsm_health.states.HealthState` holds its clearances and lubricant state plus a list
of faults, each a mechanism the dynamics model makes (docs/faults.md): a flank :class:`Spall`,
gear tooth damage, :class:`PreloadLoss`. Every kind has a ``kind`` name, a ``location`` where it
applies, and one **severity** field (its SI size, e.g. a spall's depth) that recipes scale when
they sweep severities.

In a health file (TOML), faults are ``[[faults]]`` tables (``[[health.faults]]`` inside a
scenario)::

    clearance = 12e-6
    [[faults]]
    kind = "spall"
    location = "screw"
    depth = 20e-6

:class:`FaultThresholds` turns a health state into the primary class of the run label
``fault_class``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import ClassVar

from .errors import require, require_known_keys, require_range

SPALL_LOCATIONS = ("screw", "nut", "roller")


@dataclass(frozen=True)
class Spall:
    """A localised flank defect (pit or spall) on a thread flank of the screw, the nut or one
    roller: a profile depression that a rolling contact crossing it follows down and climbs out
    of at its exit edge (Sawalhi & Randall, MSSP 22, 2008, Part I: the spall as a depression in
    the contact path with a gradual entry and an abrupt exit).

    Parameters
    ----------
    location : {"screw", "nut", "roller"}
    depth : float [m]
        Depth of the depression the contact follows (for a spall longer than the contact, its
        depth; for a short one, ≈ ℓ²/8R with R the mating profile radius). The severity.
    length : float [m]
        Extent along the contact path (around the part).
    angle : float [rad]
        Angular position of its entry on the part (screw or nut surface; the roller's own spin
        angle for a roller spall).
    roller : int
        Which roller carries a roller spall (0-based).

    The depression acts on both flanks of that engagement (the loaded one makes the signature)
    and lies within the nut's engaged threads throughout a run (a run shorter than the stroke
    across it).
    """

    kind: ClassVar[str] = "spall"
    severity_field: ClassVar[str] = "depth"
    locations: ClassVar[tuple[str, ...]] = SPALL_LOCATIONS

    location: str = "screw"
    depth: float = 20e-6
    length: float = 1.5e-3
    angle: float = 0.0
    roller: int = 0

    def __post_init__(self):
        _require_location(self)
        require_range("faults.depth", self.depth, 0.0, 200e-6, unit="m")
        require_range("faults.length", self.length, 1e-5, 10e-3, unit="m")
        require_range("faults.angle", self.angle, -2 * math.pi, 2 * math.pi, unit="rad")
        _require_index("faults.roller", self.roller)


@dataclass(frozen=True)
class PreloadLoss:
    """Loss of a preloaded nut's preload (relaxation, wear of the spacer or of the oversize
    rollers' flanks): the interference left is ``(1 − fraction)·HealthState.preload``.

    Parameters
    ----------
    fraction : float [-]
        Share of the installed preload lost, 0 … 1 (1: play returns once the clearance is
        worn). The severity.
    """

    kind: ClassVar[str] = "preload_loss"
    severity_field: ClassVar[str] = "fraction"
    locations: ClassVar[tuple[str, ...]] = ("nut",)

    location: str = "nut"
    fraction: float = 0.5

    def __post_init__(self):
        _require_location(self)
        require_range("faults.fraction", self.fraction, 0.0, 1.0)


#: Fault kinds by name (``kind`` of a ``[[faults]]`` table).
FAULT_KINDS: dict[str, type] = {cls.kind: cls for cls in (Spall, PreloadLoss)}


def _require_location(fault) -> None:
    require(
        fault.location in fault.locations,
        "faults.location",
        fault.location,
        f"must be one of {', '.join(fault.locations)} for a {fault.kind}",
    )


def _require_index(name: str, value) -> None:
    require(
        isinstance(value, int) and not isinstance(value, bool) and value >= 0,
        name,
        value,
        "must be an integer ≥ 0",
    )


def fault_from_dict(value) -> object:
    """A fault from its table (``kind`` plus that kind's fields); errors name the field."""
    if isinstance(value, tuple(FAULT_KINDS.values())):
        return value
    require(isinstance(value, dict), "faults", value, "must be a list of tables")
    values = dict(value)
    kind = values.pop("kind", None)
    require(
        kind in FAULT_KINDS,
        "faults.kind",
        kind,
        f"must be one of {', '.join(FAULT_KINDS)}",
    )
    cls = FAULT_KINDS[kind]
    require_known_keys("faults", values, ["kind", *(f.name for f in fields(cls))])
    return cls(**values)


def fault_as_dict(fault) -> dict:
    """The table form of a fault: ``kind`` first, then its fields."""
    return {"kind": fault.kind, **asdict(fault)}


def severity(fault) -> float:
    """A fault's severity: the value of its kind's severity field (SI)."""
    return float(getattr(fault, fault.severity_field))


def scaled(fault, factor: float):
    """The fault with its severity multiplied by ``factor`` (validated: a scaled value outside
    the field's range names it)."""
    return replace(fault, **{fault.severity_field: severity(fault) * factor})


# ------------------------------------------------------------------------------ taxonomy
#: Fault classes of the taxonomy (run label ``fault_class``), in no particular order.
FAULT_CLASSES = ("healthy", "wear", "severe_wear", "lubrication", "spall", "preload_loss")


@dataclass(frozen=True)
class FaultThresholds:
    """Fault taxonomy thresholds (recipe ``[faults]``).

    A run's class, in this order of precedence: ``spall`` when it has a spall deeper than
    ``spall`` [m]; ``severe_wear`` when its largest thread clearance ≥ ``severe_wear`` [m];
    ``wear`` when ≥ ``wear`` [m]; ``preload_loss`` when it has lost a share ≥ ``preload_loss``
    of a preload; ``lubrication`` when its friction scale ≥ ``lubrication`` [-]; else
    ``healthy``. Localised damage comes first because it grows to the end of the unit fastest
    and has a signature of its own; wear before preload loss and lubricant because it is
    irreversible and what maintenance acts on.
    """

    wear: float = 15e-6
    severe_wear: float = 30e-6
    lubrication: float = 1.8
    spall: float = 0.0
    preload_loss: float = 0.5

    def classify(self, health) -> str:
        """The primary class of a :class:`~prsm_health.states.HealthState`."""
        by_kind: dict[str, float] = {}
        for fault in health.faults:
            by_kind[fault.kind] = max(by_kind.get(fault.kind, 0.0), severity(fault))
        clearance = max(health.clearance_screw, health.clearance_nut)
        if by_kind.get("spall", 0.0) > self.spall:
            return "spall"
        if clearance >= self.severe_wear:
            return "severe_wear"
        if clearance >= self.wear:
            return "wear"
        if health.preload > 0 and by_kind.get("preload_loss", 0.0) >= self.preload_loss:
            return "preload_loss"
        if health.friction_scale >= self.lubrication:
            return "lubrication"
        return "healthy"

    def as_dict(self) -> dict:
        return asdict(self)
