"""The signal-channel contract, declared once: every channel's name, unit, meaning and sensor,
whether a sensor can give it (*measured*) or only a simulator knows it (*truth*), and where it
lives in an MCAP recording (topic and message field).

Every reader and writer (:class:`~prsm_health.run.Run`, Parquet datasets, MCAP, CSV, the HTTP
service, the feature extractor) takes names, units and topics from here; docs/formats.md
documents the same table for users.

The order of :data:`CHANNELS` is the record order of the dynamics kernel
(:mod:`prsm_health.dynamics.layout` ``C_*`` indices; a test checks they agree).
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import PRSMHealthError

MEASURED, TRUTH = "measured", "truth"

TOPIC_NUT_ACCEL = "/prsm/nut_accel"
TOPIC_DRIVE = "/prsm/drive"
TOPIC_DIAGNOSIS = "/prsm/diagnosis"


@dataclass(frozen=True)
class Channel:
    """One contract channel.

    Attributes
    ----------
    name : str
        Column name in Parquet/CSV and key of :attr:`Run.channels`.
    unit : str
        SI unit, as written into file metadata.
    meaning : str
        One line for people (schema descriptions, docs).
    kind : {"measured", "truth"}
        ``measured``: a sensor on a real actuator can give it; ``truth``: only a simulator knows
        it (recorded for research, never a measurement).
    sensor : str
        The sensor that gives a measured channel, or why it is truth.
    topic, field : str
        MCAP topic and message field of the channel.
    """

    name: str
    unit: str
    meaning: str
    kind: str
    sensor: str
    topic: str
    field: str


#: Every channel, in the dynamics kernel's record order (contract).
CHANNELS: tuple[Channel, ...] = (
    Channel(
        "screw_angle",
        "rad",
        "screw rotation (motor encoder)",
        MEASURED,
        "motor encoder or resolver",
        TOPIC_DRIVE,
        "screw_angle",
    ),
    Channel(
        "screw_speed",
        "rad/s",
        "screw angular speed",
        MEASURED,
        "derived from the motor angle sensor",
        TOPIC_DRIVE,
        "screw_speed",
    ),
    Channel(
        "carrier_speed",
        "rad/s",
        "carrier (roller revolution) angular speed",
        TRUTH,
        "inside the nut: no sensor reaches the carrier",
        TOPIC_DRIVE,
        "carrier_speed",
    ),
    Channel(
        "nut_position",
        "m",
        "nut axial position (linear encoder)",
        MEASURED,
        "LVDT or linear scale on the output, where fitted",
        TOPIC_DRIVE,
        "nut_position",
    ),
    Channel(
        "nut_axial_accel",
        "m/s^2",
        "nut acceleration along the screw axis",
        MEASURED,
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "axial",
    ),
    Channel(
        "nut_tangential_accel",
        "m/s^2",
        "nut circumferential acceleration at the nut pitch radius",
        MEASURED,
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "tangential",
    ),
    Channel(
        "nut_radial_x_accel",
        "m/s^2",
        "nut lateral acceleration, x",
        MEASURED,
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "radial_x",
    ),
    Channel(
        "nut_radial_y_accel",
        "m/s^2",
        "nut lateral acceleration, y",
        MEASURED,
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "radial_y",
    ),
    Channel(
        "drive_torque",
        "N*m",
        "torque the motor applies to the screw",
        MEASURED,
        "phase current times the torque constant",
        TOPIC_DRIVE,
        "drive_torque",
    ),
    Channel(
        "friction_torque",
        "N*m",
        "friction part of the drive torque",
        TRUTH,
        "not separable from the drive torque by any sensor",
        TOPIC_DRIVE,
        "friction_torque",
    ),
    Channel(
        "axial_load",
        "N",
        "external axial load on the nut",
        MEASURED,
        "load cell in the linkage, where fitted",
        TOPIC_DRIVE,
        "axial_load",
    ),
)

#: Channel names in record order.
CHANNEL_NAMES: tuple[str, ...] = tuple(c.name for c in CHANNELS)
#: SI unit of ``time`` and of every channel.
UNITS: dict[str, str] = {"time": "s", **{c.name: c.unit for c in CHANNELS}}
#: Names of the channels a sensor can give, and of those only a simulator knows.
MEASURED_NAMES: tuple[str, ...] = tuple(c.name for c in CHANNELS if c.kind == MEASURED)
TRUTH_NAMES: tuple[str, ...] = tuple(c.name for c in CHANNELS if c.kind == TRUTH)
#: Nut housing accelerometer channels.
VIBRATION: tuple[str, ...] = tuple(c.name for c in CHANNELS if c.topic == TOPIC_NUT_ACCEL)
#: Signal topics of an MCAP recording and their (field, channel) pairs, in record order.
TOPIC_FIELDS: dict[str, tuple[tuple[str, str], ...]] = {
    topic: tuple((c.field, c.name) for c in CHANNELS if c.topic == topic)
    for topic in (TOPIC_NUT_ACCEL, TOPIC_DRIVE)
}

_BY_NAME = {c.name: c for c in CHANNELS}


def channel(name: str) -> Channel:
    """The contract entry of ``name``; an unknown name is a user error listing the known ones."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise PRSMHealthError(
            f"unknown channel {name!r}; contract channels: {', '.join(CHANNEL_NAMES)}"
        ) from None
