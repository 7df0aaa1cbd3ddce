"""The signal-channel contract, declared once: every signal's name, unit, meaning and sensor,
whether a sensor makes it (*measured*) or only the simulator knows it (*truth*), and where it
lives in files (Parquet/CSV column, MCAP topic and message field).

Two tables:

- :data:`CHANNELS`, the **measured** channels: what the sensors of an instrumentation profile
  make from the physics. A recording holds the subset its sensors give, in
  :attr:`Run.channels <prsm_health.core.run.Run.channels>`; features, models and the service read
  only these.
- :data:`TRUTH_CHANNELS`, the **truth** signals: physical quantities of the simulated model
  (anti-alias decimated, no sensor error), in :attr:`Run.truth <prsm_health.core.run.Run.truth>`,
  written beside the measurements under the column names ``truth_<name>``
  (:func:`truth_column`) and on the MCAP topic :data:`TOPIC_TRUTH`. Several share a name with
  a measured channel (``screw_angle``, ``nut_position``, ``axial_load`` …): the truth is the
  true value, the channel what a sensor reads of it.

Every reader and writer (:class:`~prsm_health.core.run.Run`, Parquet datasets, MCAP, CSV, the HTTP
service, the feature extractor) takes names, units and topics from here; docs/formats.md
documents the same tables for users (printed by tools/release/make_formats_tables.py).

:data:`TRUTH_CHANNELS` is in the order the simulator produces the truth signals.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import PRSMHealthError

MEASURED, TRUTH = "measured", "truth"

TOPIC_NUT_ACCEL = "/prsm/nut_accel"
TOPIC_DRIVE = "/prsm/drive"
TOPIC_TRUTH = "/prsm/truth"
TOPIC_DIAGNOSIS = "/prsm/diagnosis"

#: Prefix of a truth signal's column name in Parquet and CSV files.
TRUTH_PREFIX = "truth_"

#: Column of the health-check phase of every sample (:mod:`prsm_health.actuator.health_check`):
#: the index of the phase the drive was commanding, −1 outside any phase (the ramps between
#: phases, a run that is no check). Measured side: the controller knows what it commands, so
#: it is not a truth signal; it is not a sensor channel either (no features read it as one).
CHECK_PHASE = "check_phase"
#: MCAP topic of the check phase: one message per phase change, ``{"index": int, "name": str}``.
TOPIC_CHECK_PHASE = "/health_check/phase"
#: Name of the check's record (check name, phase names and boundaries) in file metadata: the
#: MCAP Metadata record, and ``prsm_health.health_check`` in Parquet schema metadata.
CHECK_METADATA = "health_check"


@dataclass(frozen=True)
class Channel:
    """One contract signal.

    Attributes
    ----------
    name : str
        Key in :attr:`Run.channels` (measured) or :attr:`Run.truth` (truth). The Parquet/CSV
        column is the name itself for a measured channel, ``truth_<name>`` for truth.
    unit : str
        SI unit, as written into file metadata.
    meaning : str
        One line for people (schema descriptions, docs).
    kind : {"measured", "truth"}
        ``measured``: a sensor on a real actuator gives it; ``truth``: the simulator's true
        value (recorded for research, never a measurement).
    sensor : str
        The sensor that gives a measured channel; for truth, why no sensor gives it, or which
        measured channel is its sensor reading.
    topic, field : str
        MCAP topic and message field.
    """

    name: str
    unit: str
    meaning: str
    kind: str
    sensor: str
    topic: str
    field: str


def _measured(name, unit, meaning, sensor, topic, field=None) -> Channel:
    return Channel(name, unit, meaning, MEASURED, sensor, topic, field or name)


def _truth(name, unit, meaning, sensor) -> Channel:
    return Channel(name, unit, meaning, TRUTH, sensor, TOPIC_TRUTH, name)


#: The measured channels (what sensors give), in contract order.
CHANNELS: tuple[Channel, ...] = (
    _measured(
        "screw_angle",
        "rad",
        "gearbox output angle as the drive reports it: the motor sensor's reading / N",
        "motor encoder or resolver (on the motor: its errors are N times finer on the screw)",
        TOPIC_DRIVE,
    ),
    _measured(
        "screw_speed",
        "rad/s",
        "drive speed estimate from the motor angle sensor",
        "derived from the motor angle sensor",
        TOPIC_DRIVE,
    ),
    _measured(
        "nut_position",
        "m",
        "nut axial position relative to the actuator housing",
        "LVDT on the rod or linear scale, where fitted",
        TOPIC_DRIVE,
    ),
    _measured(
        "nut_axial_accel",
        "m/s^2",
        "nut acceleration along the screw axis",
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "axial",
    ),
    _measured(
        "nut_tangential_accel",
        "m/s^2",
        "nut circumferential acceleration at the nut pitch radius",
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "tangential",
    ),
    _measured(
        "nut_radial_x_accel",
        "m/s^2",
        "nut lateral acceleration, x",
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "radial_x",
    ),
    _measured(
        "nut_radial_y_accel",
        "m/s^2",
        "nut lateral acceleration, y",
        "accelerometer on the nut housing",
        TOPIC_NUT_ACCEL,
        "radial_y",
    ),
    _measured(
        "drive_torque",
        "N*m",
        "MOTOR torque k_t·i as the drive reports it (screw torque ≈ N·η times it when driving)",
        "phase current times the nominal torque constant",
        TOPIC_DRIVE,
    ),
    _measured(
        "axial_load",
        "N",
        "force of the linkage on the nut (positive resisting)",
        "load cell in the linkage, where fitted",
        TOPIC_DRIVE,
    ),
    # slow (the probe's time constant), logged at the signals' rate with the drive's signals
    _measured(
        "housing_temperature",
        "K",
        "actuator housing temperature at the nut",
        "platinum RTD (Pt100/Pt1000) on the nut housing, where fitted",
        TOPIC_DRIVE,
    ),
)

#: The truth signals (only the simulator knows them), in the simulator's order.
TRUTH_CHANNELS: tuple[Channel, ...] = (
    _truth(
        "motor_angle",
        "rad",
        "motor rotor angle",
        "true value; measured channel screw_angle is its sensor reading",
    ),
    _truth(
        "motor_speed",
        "rad/s",
        "motor rotor speed",
        "true value; measured channel screw_speed is the drive's estimate of it",
    ),
    _truth(
        "motor_torque",
        "N*m",
        "electromagnetic torque the motor produces",
        "true value; measured channel drive_torque is its sensor reading",
    ),
    _truth(
        "screw_angle",
        "rad",
        "screw angle (load side of the motor–screw coupling)",
        "no sensor on the screw itself: the drive measures the motor side",
    ),
    _truth(
        "screw_speed",
        "rad/s",
        "screw speed",
        "no sensor on the screw itself: the drive measures the motor side",
    ),
    _truth(
        "carrier_speed",
        "rad/s",
        "carrier (roller revolution) speed",
        "inside the nut: no sensor reaches the carrier",
    ),
    _truth(
        "nut_position",
        "m",
        "nut axial position relative to the actuator housing",
        "true value; measured channel nut_position is its sensor reading",
    ),
    _truth(
        "nut_axial_accel",
        "m/s^2",
        "nut acceleration along the screw axis",
        "true value; measured channel nut_axial_accel is its sensor reading",
    ),
    _truth(
        "nut_tangential_accel",
        "m/s^2",
        "nut circumferential acceleration at the nut pitch radius",
        "true value; measured channel nut_tangential_accel is its sensor reading",
    ),
    _truth(
        "nut_radial_x_accel",
        "m/s^2",
        "nut lateral acceleration x",
        "true value; measured channel nut_radial_x_accel is its sensor reading",
    ),
    _truth(
        "nut_radial_y_accel",
        "m/s^2",
        "nut lateral acceleration y",
        "true value; measured channel nut_radial_y_accel is its sensor reading",
    ),
    _truth(
        "friction_torque",
        "N*m",
        "friction part of the screw torque",
        "not separable from the drive torque by any sensor",
    ),
    _truth(
        "axial_load",
        "N",
        "force of the linkage on the nut (resisting positive)",
        "true value; measured channel axial_load is its sensor reading",
    ),
    _truth(
        "payload_position",
        "m",
        "payload axial position",
        "beyond the linkage: the actuator's sensors stop at the rod",
    ),
    _truth(
        "screw_axial_position",
        "m",
        "screw axial displacement in its thrust bearing",
        "micrometre motion inside the bearing housing: no sensor fitted",
    ),
    _truth(
        "load_force",
        "N",
        "external force applied to the payload (the load profile)",
        "acts on the payload, not in the linkage: the load cell reads axial_load",
    ),
    # Not a kernel record column: the simulator derives it from the profile's contact
    # temperature and the run's friction power (prsm_health.simulation.thermal), after them.
    _truth(
        "housing_temperature",
        "K",
        "housing temperature at the probe: the thread-contact lubricant temperature less the "
        "steady contact-to-housing rise of the run's friction power",
        "true value; measured channel housing_temperature is its sensor reading",
    ),
    # The recirculating PRSM's own (paper 03): absent from a standard PRSM's runs.
    _truth(
        "cam_force",
        "N",
        "recirculating PRSM: the cam rings' axial force on the rollers, summed — the largest "
        "within each sample's interval (the ≈ 20 µs reset pulse kept, not filtered away)",
        "inside the nut: no sensor reaches the cam ring",
    ),
    _truth(
        "reset_count",
        "1",
        "recirculating PRSM: crossings of the threadless area the rollers completed so far",
        "inside the nut: no sensor counts the resets",
    ),
)

#: Measured channel names in contract order (the keys a :class:`Run`'s channels may have).
CHANNEL_NAMES: tuple[str, ...] = tuple(c.name for c in CHANNELS)
#: The same tuple, under the name of its kind.
MEASURED_NAMES: tuple[str, ...] = CHANNEL_NAMES
#: Truth signal names in the simulator's order (the keys a :class:`Run`'s truth may have).
TRUTH_NAMES: tuple[str, ...] = tuple(c.name for c in TRUTH_CHANNELS)
#: The truth only the recirculating PRSM's model gives (no cam ring, no resets elsewhere).
RECIRCULATING_TRUTH: tuple[str, ...] = ("cam_force", "reset_count")
#: The truth of a standard PRSM's run: every other signal, in the simulator's order.
STANDARD_TRUTH_NAMES: tuple[str, ...] = tuple(
    n for n in TRUTH_NAMES if n not in RECIRCULATING_TRUTH
)


def truth_column(name: str) -> str:
    """Parquet/CSV column name of the truth signal ``name``: ``truth_<name>``."""
    return TRUTH_PREFIX + name


#: SI unit of every file column: ``time``, the measured channels, the check phase, and the
#: truth signals under their column names ``truth_<name>`` (a truth signal and the measured channel of the same
#: name are different columns).
UNITS: dict[str, str] = {
    "time": "s",
    **{c.name: c.unit for c in CHANNELS},
    CHECK_PHASE: "1",  # a phase index: dimensionless
    **{truth_column(c.name): c.unit for c in TRUTH_CHANNELS},
}
#: Nut housing accelerometer channels.
VIBRATION: tuple[str, ...] = tuple(c.name for c in CHANNELS if c.topic == TOPIC_NUT_ACCEL)
#: MCAP topics of the measured channels.
MEASURED_TOPICS: tuple[str, ...] = (TOPIC_NUT_ACCEL, TOPIC_DRIVE)
#: Signal topics of an MCAP recording and their (field, name) pairs in contract order: the
#: measured topics (name = measured channel) and :data:`TOPIC_TRUTH` (name = truth signal).
TOPIC_FIELDS: dict[str, tuple[tuple[str, str], ...]] = {
    **{
        topic: tuple((c.field, c.name) for c in CHANNELS if c.topic == topic)
        for topic in MEASURED_TOPICS
    },
    TOPIC_TRUTH: tuple((c.field, c.name) for c in TRUTH_CHANNELS),
}

_BY_NAME = {c.name: c for c in CHANNELS}
_TRUTH_BY_NAME = {c.name: c for c in TRUTH_CHANNELS}


def channel(name: str) -> Channel:
    """The contract entry of the measured channel ``name``; an unknown name is a user error
    listing the known ones (and saying so when ``name`` is truth)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        hint = ""
        if name in _TRUTH_BY_NAME or name.startswith(TRUTH_PREFIX):
            hint = " (truth signals are not measured channels: see Run.truth)"
        raise PRSMHealthError(
            f"unknown channel {name!r}{hint}; contract channels: {', '.join(CHANNEL_NAMES)}"
        ) from None


def truth_channel(name: str) -> Channel:
    """The contract entry of the truth signal ``name`` (without the ``truth_`` prefix)."""
    try:
        return _TRUTH_BY_NAME[name]
    except KeyError:
        raise PRSMHealthError(
            f"unknown truth signal {name!r}; truth signals: {', '.join(TRUTH_NAMES)}"
        ) from None
