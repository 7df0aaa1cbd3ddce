"""Faults of a health state, and the fault taxonomy of run labels.

A :class:`~prsm_health.actuator.states.HealthState` holds its clearances and lubricant state plus a list
of faults, each a mechanism the dynamics model makes (docs/faults.md): a flank :class:`Spall`,
gear tooth damage, :class:`PreloadLoss`, and the recirculating PRSM's own
(:class:`CamWear`, :class:`PlatformLoss`, :class:`ReentryEdgeDamage`). Every kind has a ``kind`` name, a ``location`` where it
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

import numpy as np

from prsm_health.core.errors import require, require_known_keys, require_range

SPALL_LOCATIONS = ("screw", "nut", "roller")
SPALL_FLANKS = ("loaded", "unloaded", "both")
#: A roller spall's ``roller`` that lets fatigue choose the roller (:class:`Spall`).
FATIGUE = "fatigue"


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
        depth; for a short one, ≈ ℓ²/8R with R the mating profile radius). Once deeper than the
        turn's contact deflection (a few µm) the turn unloads completely, so depth saturates.
    length : float [m]
        Extent along the contact path (around the part): how long the turn stays unloaded, the
        severity (spalls grow in length).
    angle : float [rad]
        Angular position of its entry on the part (screw or nut surface; the roller's own spin
        angle for a roller spall).
    roller : int or "fatigue"
        Which roller carries a roller spall (0-based), or ``"fatigue"`` (the default): drawn
        with the run's seed, each roller with probability ∝ its static load cubed. Rolling-
        contact fatigue life goes as (C/P)^p with p = 3 for point contacts (Lundberg & Palmgren
        1947; ISO 281:2007 eq. 1), so a spall forms where the load is: manufacturing scatter
        spreads the rollers' shares of the load (0–0.24 over 7 rollers measured on fresh
        units, docs/faults.md), and a spall on a roller that carries none would be one no
        fatigue made and no check could see.
    position : float [m]
        Axial position. Screw: along the screw from where the nut's centre is at t = 0, within
        ± half the screw's threaded length (``design.screw_free_length``); the spall is met
        only while the roller threads span it. Nut or roller: which thread turn, from the
        middle of the engaged length (± n_t·pitch/2); every turn is alike in the model.
    flank : {"loaded", "unloaded", "both"}
        The thread flank it is on: the one that carries a positive (resisting) axial load, the
        other one, or both. A roller spall is on both (its two flanks face screw and nut).

    The depression is on one of the engagement's n_t thread turns: that turn's share 1/n_t of
    the contact stiffness closes ``depth`` less while the contact crosses it.
    """

    kind: ClassVar[str] = "spall"
    severity_field: ClassVar[str] = "length"
    locations: ClassVar[tuple[str, ...]] = SPALL_LOCATIONS
    #: The design variants whose model makes this fault (the recirculating one: a nut spall).
    variants: ClassVar[tuple[str, ...]] = ("standard", "recirculating")

    location: str = "screw"
    depth: float = 20e-6
    length: float = 1.5e-3
    angle: float = 0.0
    roller: int | str = FATIGUE
    position: float = 0.0
    flank: str = "loaded"

    def __post_init__(self):
        _require_location(self)
        require(
            self.flank in SPALL_FLANKS,
            "faults.flank",
            self.flank,
            f"must be one of {', '.join(SPALL_FLANKS)}",
        )
        require_range("faults.position", self.position, -10.0, 10.0, unit="m")
        require_range("faults.depth", self.depth, 0.0, 200e-6, unit="m")
        require_range("faults.length", self.length, 1e-5, 10e-3, unit="m")
        require_range("faults.angle", self.angle, -2 * math.pi, 2 * math.pi, unit="rad")
        if self.roller != FATIGUE:
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
    variants: ClassVar[tuple[str, ...]] = ("standard",)
    severity_field: ClassVar[str] = "fraction"
    locations: ClassVar[tuple[str, ...]] = ("nut",)

    location: str = "nut"
    fraction: float = 0.5

    def __post_init__(self):
        _require_location(self)
        require_range("faults.fraction", self.fraction, 0.0, 1.0)


GEAR_LOCATIONS = ("ring_gear", "roller_gear")


@dataclass(frozen=True)
class ToothCrack:
    """A root crack on one tooth of the ring gear or of one roller's gear: the tooth loses
    section (the mechanics: :mod:`prsm_health.physics.stiffness.tooth_damage`, Tian 2004; Wu, Zuo &
    Parey 2008), so the
    mesh softens each time that tooth carries load — once per pass of a roller for a ring
    tooth, once per roller spin for a roller tooth.

    Parameters
    ----------
    location : {"ring_gear", "roller_gear"}
    depth : float [m]
        Crack length q from the root (the severity); q·sin(angle) must stay below the root
        half-thickness (the crack does not cross the tooth centreline).
    angle : float [rad]
        Crack angle ν to the root surface (45° in both papers).
    tooth : int
        Which tooth of that gear (0-based; its position in the mesh cycle).
    roller : int
        Which roller's gear, for ``roller_gear``.
    """

    kind: ClassVar[str] = "tooth_crack"
    variants: ClassVar[tuple[str, ...]] = ("standard",)
    severity_field: ClassVar[str] = "depth"
    locations: ClassVar[tuple[str, ...]] = GEAR_LOCATIONS

    location: str = "ring_gear"
    depth: float = 0.4e-3
    angle: float = math.radians(45.0)
    tooth: int = 0
    roller: int = 0

    def __post_init__(self):
        _require_location(self)
        require_range("faults.depth", self.depth, 0.0, 5e-3, unit="m")
        require_range("faults.angle", self.angle, math.radians(5), math.radians(85), unit="rad")
        _require_index("faults.tooth", self.tooth)
        _require_index("faults.roller", self.roller)


@dataclass(frozen=True)
class ToothPit:
    """A pit (spall) on the loaded flank of one tooth of the ring gear or of one roller's gear,
    a radial band of the flank over part of the face width (Chaari et al. 2008; Liang, Zuo &
    Hoseini 2015): less contact line and less section while the contact crosses it.

    Parameters
    ----------
    location : {"ring_gear", "roller_gear"}
    depth : float [m]
        Pit depth (the severity).
    width : float [-]
        Share of the face width it covers, (0, 1).
    length : float [m]
        Radial extent on the flank.
    offset : float [m]
        Centre of the band from the pitch circle, towards the tooth tip (0: on the pitch line,
        where pitting starts).
    tooth, roller : int
        As :class:`ToothCrack`.
    """

    kind: ClassVar[str] = "tooth_pit"
    variants: ClassVar[tuple[str, ...]] = ("standard",)
    severity_field: ClassVar[str] = "depth"
    locations: ClassVar[tuple[str, ...]] = GEAR_LOCATIONS

    location: str = "ring_gear"
    depth: float = 20e-6
    width: float = 0.4
    length: float = 0.2e-3
    offset: float = 0.0
    tooth: int = 0
    roller: int = 0

    def __post_init__(self):
        _require_location(self)
        require_range("faults.depth", self.depth, 0.0, 0.5e-3, unit="m")
        require_range("faults.width", self.width, 0.0, 0.95)
        require_range("faults.length", self.length, 0.0, 5e-3, unit="m")
        require_range("faults.offset", self.offset, -5e-3, 5e-3, unit="m")
        _require_index("faults.tooth", self.tooth)
        _require_index("faults.roller", self.roller)


# ------------------------------------------------------------- the recirculating PRSM's own
@dataclass(frozen=True)
class CamWear:
    """Wear of a recirculating PRSM's cam-ring chamfer (paper 03 §2: the chamfer that pushes
    each roller one lead forward across the threadless area): every reset strikes the chamfer's
    entrance, and the strikes wear it down there, tapering to nothing at the platform's top.
    The chamfer rises by the stroke s (one lead) over the first β of the threadless area
    (eqs. 9–11); worn, its surface is max(0, (s + w)·a/β − w) at the orbital angle a into the
    area: the roller meets it β·w/(s + w) later and climbs it (s + w)/s times faster — the
    reset's entry pulse later in the passage and harder, whatever the load
    (:mod:`prsm_health.simulation.recirculating.model`, which refuses w > s/2 for the design).

    Parameters
    ----------
    depth : float [m]
        Axial depth w worn off at the chamfer's entrance (the severity), ≤ half the reset
        stroke (checked against the design when simulated).
    """

    kind: ClassVar[str] = "cam_wear"
    variants: ClassVar[tuple[str, ...]] = ("recirculating",)
    severity_field: ClassVar[str] = "depth"
    locations: ClassVar[tuple[str, ...]] = ("cam_ring",)

    location: str = "cam_ring"
    depth: float = 0.1e-3

    def __post_init__(self):
        _require_location(self)
        require_range("faults.depth", self.depth, 0.0, 5e-3, unit="m")


@dataclass(frozen=True)
class PlatformLoss:
    """Height lost by a recirculating PRSM's cam-ring platform (wear or plastic flattening of
    the convex top that holds a reset roller): the chamfer pushes the roller L − h instead of
    one lead, and unless the push throws it further the nut thread must push the landing roller
    the rest — an incomplete reset, toward jamming once h reaches half a pitch (refused there).

    Parameters
    ----------
    height : float [m]
        Height lost (the severity), below 0.4 of the thread pitch (checked against the design
        when simulated: :mod:`prsm_health.simulation.recirculating.model`).
    """

    kind: ClassVar[str] = "platform_loss"
    variants: ClassVar[tuple[str, ...]] = ("recirculating",)
    severity_field: ClassVar[str] = "height"
    locations: ClassVar[tuple[str, ...]] = ("cam_ring",)

    location: str = "cam_ring"
    height: float = 0.1e-3

    def __post_init__(self):
        _require_location(self)
        require_range("faults.height", self.height, 0.0, 5e-3, unit="m")


@dataclass(frozen=True)
class ReentryEdgeDamage:
    """Damage at a recirculating PRSM's nut-thread re-entry edge, where each reset roller lands
    back on the nut thread after the threadless area: material missing from both flanks over
    ``length`` of the rollers' path after the exit, on every engaged turn. The roller takes its
    share of the load back later and harder (a landing strike that grows with the load).

    Parameters
    ----------
    length : float [m]
        Extent along the rollers' path (the severity).
    depth : float [m]
        Material missing from each flank there, up to 0.4 mm (a chipped thread start). Below
        what the reset leaves between the landing roller and its groove (up to p/N: the
        push throws it against the far ring) the flank meets the roller during its lift's
        ramp anyway and the damage barely shows; deeper, the landing waits for the intact
        thread (measured: docs/faults.md).
    """

    kind: ClassVar[str] = "reentry_edge"
    variants: ClassVar[tuple[str, ...]] = ("recirculating",)
    severity_field: ClassVar[str] = "length"
    locations: ClassVar[tuple[str, ...]] = ("nut",)

    location: str = "nut"
    length: float = 1e-3
    depth: float = 0.15e-3

    def __post_init__(self):
        _require_location(self)
        require_range("faults.length", self.length, 1e-5, 10e-3, unit="m")
        require_range("faults.depth", self.depth, 1e-7, 0.4e-3, unit="m")


#: Fault kinds by name (``kind`` of a ``[[faults]]`` table).
FAULT_KINDS: dict[str, type] = {
    cls.kind: cls
    for cls in (Spall, ToothCrack, ToothPit, PreloadLoss, CamWear, PlatformLoss, ReentryEdgeDamage)
}


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
FAULT_CLASSES = (
    "healthy",
    "wear",
    "severe_wear",
    "lubrication",
    "spall",
    "tooth_damage",
    "preload_loss",
    "cam_ring",
    "reentry_edge",
)


#: The fault taxonomy: how :class:`FaultThresholds` names a run's primary class (stored in
#: every dataset's manifest, ``fault_taxonomy.rule``; each threshold is named by its field).
FAULT_RULE = (
    "A run's class, in this order of precedence: spall when it has a spall longer than spall "
    "[m]; tooth_damage when a gear tooth has a crack or pit deeper than tooth_damage [m]; "
    "reentry_edge when a recirculating nut's re-entry edge is damaged over more than "
    "reentry_edge [m]; cam_ring when a recirculating cam ring's chamfer is worn or its "
    "platform lost more than cam_ring [m]; severe_wear when its largest thread clearance ≥ "
    "severe_wear [m]; wear when ≥ wear [m]; "
    "preload_loss when it has lost a share ≥ preload_loss of a preload; lubrication when its "
    "friction scale ≥ lubrication [-] or its lubricant degradation or starvation ≥ lubricant "
    "[-]; else healthy. Localised damage comes first because it grows to the end of the unit "
    "fastest and has a signature of its own; wear before preload loss and lubricant because "
    "it is irreversible and what maintenance acts on."
)


@dataclass(frozen=True)
class FaultThresholds:
    """Fault taxonomy thresholds (recipe ``[faults]``): a run's class follows
    :data:`FAULT_RULE`, each threshold named there by its field (:meth:`classify`)."""

    wear: float = 15e-6
    severe_wear: float = 30e-6
    lubrication: float = 1.8
    spall: float = 0.0
    tooth_damage: float = 0.0
    preload_loss: float = 0.5
    lubricant: float = 0.5
    reentry_edge: float = 0.0
    cam_ring: float = 0.0

    def classify(self, health) -> str:
        """The primary class of a :class:`~prsm_health.actuator.states.HealthState`."""
        by_kind: dict[str, float] = {}
        for fault in health.faults:
            by_kind[fault.kind] = max(by_kind.get(fault.kind, 0.0), severity(fault))
        clearance = max(health.clearance_screw, health.clearance_nut)
        if by_kind.get("spall", 0.0) > self.spall:
            return "spall"
        tooth = max(by_kind.get("tooth_crack", 0.0), by_kind.get("tooth_pit", 0.0))
        if tooth > self.tooth_damage:
            return "tooth_damage"
        if by_kind.get("reentry_edge", 0.0) > self.reentry_edge:
            return "reentry_edge"
        if max(by_kind.get("cam_wear", 0.0), by_kind.get("platform_loss", 0.0)) > self.cam_ring:
            return "cam_ring"
        if clearance >= self.severe_wear:
            return "severe_wear"
        if clearance >= self.wear:
            return "wear"
        if health.preload > 0 and by_kind.get("preload_loss", 0.0) >= self.preload_loss:
            return "preload_loss"
        lubricant = (
            health.friction_scale,
            health.lubricant_degradation,
            health.lubricant_starvation,
        )
        if self.lubricant_degraded(*lubricant):
            return "lubrication"
        return "healthy"

    def lubricant_degraded(self, friction_scale, degradation, starvation):
        """Whether the lubricant is in the ``lubrication`` class's state, whatever class takes
        precedence: friction scale ≥ ``lubrication`` or degradation or starvation ≥
        ``lubricant`` (numbers or arrays, elementwise)."""
        lubricant = np.maximum(degradation, starvation)
        return (np.asarray(friction_scale) >= self.lubrication) | (lubricant >= self.lubricant)

    def as_dict(self) -> dict:
        return asdict(self)
