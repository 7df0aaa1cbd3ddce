"""The actuator around the roller screw: motor, coupling, thrust bearing, anti-rotation guide,
linkage and payload.

A PRSM is never driven by an ideal angle nor loaded by an ideal force: an electromechanical
actuator (EMA) turns it with a servo motor through a coupling, holds the screw axially in a
thrust bearing, keeps the nut from turning with a guide, and pushes a payload (a control surface,
a robot link, a machine table) through a rod and its attachment. Each element adds compliance
and mass between the mechanism and the sensors, which decides what a sensor can see
(docs/validation.md, the actuator as it is measured).

Defaults describe a flight-control EMA of the paper-01 screw's size (Ø19.5 mm screw, 10 mm
lead). Where a figure comes from a datasheet it is cited; the rest are engineering estimates
marked as such — replace them with your actuator's values.

* Motor: rotor inertia 3e-5 kg·m² and torque constant 0.5 N·m/A for a ~1–2 N·m servo motor
  (engineering estimate in the range of Kollmorgen AKM2x/3x catalogue motors; the AKM manual
  states ±10 % tolerance on its data, which the instrumentation's torque-constant error uses);
  4 pole pairs (sets the torque-ripple harmonics of the current sensor).
* Coupling: metal bellows coupling, RINGFEDER GWB DKN size 20 (tech paper 08.2019): dynamic
  torsional stiffness 1.5e3 N·m/rad; damping ratio 0.02 (metal bellows: structural damping,
  engineering estimate).
* Thrust bearing + screw: a preloaded angular-contact pair ~1e8–5e8 N/m axial rigidity
  (engineering estimate for a 15–20 mm bore) in series with the screw between bearing and nut,
  E·A/L = 2.1e11 × π(8.5 mm)² / 0.1 m ≈ 4.8e8 N/m: 1.5e8 N/m in all; play 0 (preloaded) by
  default, ``thrust_bearing_play`` for a worn or unloaded bearing.
* Anti-rotation guide: torsional stiffness 1e5 N·m/rad (the former nut_torsional_stiffness).
* Linkage and payload: rod end, attachment and horn stiffness 5e7 N/m (EMA attachment stiffness
  of the order of 50 N/µm, engineering estimate), damping ratio 0.05, payload 10 kg reflected
  mass at the rod. ``load_application = "nut"`` applies the load profile as an ideal force on the
  nut, as paper 01 does (no payload, no linkage) — for the paper's own case.
* ``coupled = False`` drives the screw directly by the motor angle (rigid coupling), and
  ``rigid_thrust_bearing = True`` holds the screw axially fixed, as paper 01 does;
  :meth:`DriveTrain.paper01` sets both and the ideal force on the nut.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from pathlib import Path

from prsm_health.core.errors import ParameterError, require, require_known_keys, require_range

LOAD_APPLICATIONS = ("payload", "nut")
#: Named drive trains: the default flight-control actuator, and paper 01's idealisation.
NAMED = ("actuator", "paper01")


@dataclass(frozen=True)
class DriveTrain:
    """Motor, coupling, thrust bearing, guide, linkage and payload of the actuator (SI).

    Parameters
    ----------
    motor_inertia : float [kg·m²]
        Rotor inertia of the motor (plus its half of the coupling).
    torque_constant : float [N·m/A]
        Nominal torque constant k_t (the phase-current sensor's torque estimate uses it).
    pole_pairs : int
        Motor pole pairs (torque ripple and resolver harmonics follow the electrical angle).
    coupled : bool
        True: the motor drives the screw through a torsional spring–damper; False: rigidly.
    coupling_stiffness : float [N·m/rad]
    coupling_damping_ratio : float [-]
        Of the motor–screw torsional mode.
    thrust_bearing_stiffness : float [N/m]
        Axial stiffness of thrust bearing and screw in series, screw to housing.
    thrust_bearing_play : float [m]
        Half of the axial play of the thrust bearing (0: preloaded).
    thrust_bearing_damping_ratio : float [-]
        Of the screw's axial mode on the bearing.
    rigid_thrust_bearing : bool
        Hold the screw axially fixed (paper 01) instead of on the bearing.
    anti_rotation_stiffness : float [N·m/rad]
        Torsional stiffness of the nut's anti-rotation guide.
    load_application : {"payload", "nut"}
        ``payload``: the load profile acts on a payload mass linked to the nut by a
        spring–damper; ``nut``: an ideal force on the nut (paper 01).
    payload_mass : float [kg]
        Payload mass reflected to the rod.
    linkage_stiffness : float [N/m]
    linkage_damping_ratio : float [-]
        Of the payload on the linkage (nut held).
    """

    motor_inertia: float = 3e-5
    torque_constant: float = 0.5
    pole_pairs: int = 4
    coupled: bool = True
    coupling_stiffness: float = 1.5e3
    coupling_damping_ratio: float = 0.02
    thrust_bearing_stiffness: float = 1.5e8
    thrust_bearing_play: float = 0.0
    thrust_bearing_damping_ratio: float = 0.05
    rigid_thrust_bearing: bool = False
    anti_rotation_stiffness: float = 1e5
    load_application: str = "payload"
    payload_mass: float = 10.0
    linkage_stiffness: float = 5e7
    linkage_damping_ratio: float = 0.05

    def __post_init__(self):
        require_range("drive_train.motor_inertia", self.motor_inertia, 1e-7, 1.0, unit="kg·m²")
        require_range(
            "drive_train.torque_constant", self.torque_constant, 1e-3, 100.0, unit="N·m/A"
        )
        require(
            isinstance(self.pole_pairs, int) and 1 <= self.pole_pairs <= 64,
            "drive_train.pole_pairs",
            self.pole_pairs,
            "must be an integer in [1, 64]",
        )
        for name in ("coupled", "rigid_thrust_bearing"):
            value = getattr(self, name)
            require(isinstance(value, bool), f"drive_train.{name}", value, "must be true or false")
        require_range(
            "drive_train.coupling_stiffness", self.coupling_stiffness, 10.0, 1e7, unit="N·m/rad"
        )
        require_range(
            "drive_train.thrust_bearing_stiffness",
            self.thrust_bearing_stiffness,
            1e6,
            1e10,
            unit="N/m",
        )
        require_range(
            "drive_train.thrust_bearing_play", self.thrust_bearing_play, 0.0, 200e-6, unit="m"
        )
        require_range(
            "drive_train.anti_rotation_stiffness",
            self.anti_rotation_stiffness,
            10.0,
            1e8,
            unit="N·m/rad",
        )
        require(
            self.load_application in LOAD_APPLICATIONS,
            "drive_train.load_application",
            self.load_application,
            f"must be one of {', '.join(LOAD_APPLICATIONS)}",
        )
        require_range("drive_train.payload_mass", self.payload_mass, 0.01, 1e5, unit="kg")
        require_range(
            "drive_train.linkage_stiffness", self.linkage_stiffness, 1e4, 1e10, unit="N/m"
        )
        for name in (
            "coupling_damping_ratio",
            "thrust_bearing_damping_ratio",
            "linkage_damping_ratio",
        ):
            require_range(f"drive_train.{name}", getattr(self, name), 0.0, 1.0)

    @classmethod
    def paper01(cls) -> DriveTrain:
        """Paper 01's idealisation: rigid motor–screw, ideal force on the nut."""
        return cls(coupled=False, rigid_thrust_bearing=True, load_application="nut")

    def as_dict(self) -> dict:
        return asdict(self)


def load_drive_train(source: str | Path | dict | DriveTrain) -> DriveTrain:
    """A drive train from a name (:data:`NAMED`), a TOML file of :class:`DriveTrain` fields
    (SI, as named in the dataclass), or their dict; unknown keys are named."""
    if isinstance(source, DriveTrain):
        return source
    if isinstance(source, str) and source in NAMED:
        return DriveTrain.paper01() if source == "paper01" else DriveTrain()
    if isinstance(source, (str, Path)):
        from prsm_health.core.tomlfile import read_toml

        path = Path(source)
        if path.suffix != ".toml":
            raise ParameterError(
                "drive_train", str(source), f"must be one of {', '.join(NAMED)} or a .toml file"
            )
        source = read_toml(path, "drive-train file")
    allowed = [f.name for f in fields(DriveTrain)]
    require_known_keys("drive_train", source, allowed)
    return DriveTrain(**source)
