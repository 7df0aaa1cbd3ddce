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

* Motor of :meth:`DriveTrain.direct` (the former default): rotor inertia 3e-5 kg·m² and torque
  constant 0.5 N·m/A for a ~1–2 N·m servo motor (engineering estimate in the range of Kollmorgen
  AKM2x/3x catalogue motors; the AKM manual states ±10 % tolerance on its data, which the
  instrumentation's torque-constant error uses); 4 pole pairs. No reduction, no current data:
  the speed loop saturates at the profile's ``torque_limit``.
* Motor and reduction of the defaults (:meth:`DriveTrain.flight_ema`, the ``"actuator"`` name), sized for the
  default duty of the paper-01 screw (20 % of C_a ≈ 2.1 kN mean, peaks to 40 % ≈ 4.2 kN: 3.9 and
  7.9 N·m at the screw for a 10 mm lead at a screw efficiency of 0.85; :func:`duty_check`):

  - motor: the 310 V DC PMSM servo motor tabulated in the Free Dictionary's "torque constant"
    entry (encyclopedia2.thefreedictionary.com/torque+constant, Table: 4600 rpm, 2.2 N·m,
    stall current 4.52 A, 4 poles, K_t 0.49 N·m/A, J_m 1.8 kg·cm²): continuous torque 2.2 N·m,
    k_t 0.49 N·m/A, rotor inertia 1.8e-4 kg·m², 2 pole pairs, speed limit 4600 rpm
    (481.7 rad/s; the tabulated speed, a conservative limit); peak current 2 × I_0 = 9.04 A
    (Kollmorgen "Motor Data Legend": M = I·K_T holds up to I = 2·I_0, and the peak current is
    3–5 × rated), so peak torque 4.43 N·m. No catalogue row of a named AKM motor was readable
    to the author: replace with your motor's datasheet row.
  - reduction: a one-stage planetary gearhead, ratio 3 (APEX Dynamics P series: one-stage
    ratios 3, 4, 5, 7, 9, 10); input-side inertia 0.16 kg·cm² (the size-060 one-stage ratio-3
    row of the TaiBang GB-series "rotary inertia" table, gearing-epicyclic.top); efficiency
    0.97 (a planetary stage loses at most 3 %: Design World, "Miniature gearing and planetary
    gearing in haptic feedback", 2020, on maxon GPX); backlash (lost motion) 3 arcmin and
    torsion 10 arcmin at rated torque, max (Yaskawa SGMMV manual §11.1.1, low-backlash
    gears), so half-backlash 1.5 arcmin and torsional stiffness ≥ 2.2 N·m × 3 × 0.97 /
    10 arcmin = 2.2e3 N·m/rad at the output (the gear's rated output torque is the motor's
    rated torque × N × η, same section); sun pinion 24 teeth (engineering estimate: z_ring =
    48 for ratio 3 = 1 + z_ring/z_sun), so the mesh order on the motor shaft is
    z_sun·(1 − 1/N) = 16; transmission error at that order 5e-5 rad at the output (≈ 10″;
    engineering estimate: ~1 µm tooth-to-tooth error on a ≈ 20 mm ring pitch radius, well inside
    the 6 arcmin once-per-turn transmission accuracy of the same Yaskawa table).

  The loss model of the reduction is the load-dependent mesh loss of ISO/TR 14179-1 (gear
  losses proportional to the transmitted torque, the no-load churning part neglected): the
  motor sees the output torque / (N·η) when it drives and × η/N when the load drives it back,
  so the loss is (1/η − 1) or (1 − η) of the transmitted power, always dissipated.
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
* Reduction in the dynamics (docs/validation.md, the drive train): the gearbox output angle is
  θ_m/N plus the transmission error at the mesh order; it drives the screw through the gear
  mesh (stiffness, backlash) and the coupling in series. No inertia sits between them (the
  catalogue gives the gearbox inertia referred to the input, carried with the motor), so the
  two springs combine into one: k = k_c·k_g/(k_c + k_g), dead band ± the gear's half-backlash.
* ``coupled = False`` drives the screw directly by the motor angle (rigid coupling, and a rigid
  reduction: θ_s = θ_m/N), and
  ``rigid_thrust_bearing = True`` holds the screw axially fixed, as paper 01 does;
  :meth:`DriveTrain.paper01` sets both and the ideal force on the nut.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from prsm_health.core.errors import ParameterError, require, require_known_keys, require_range

LOAD_APPLICATIONS = ("payload", "nut")
GEAR_KINDS = ("planetary", "parallel")
#: Named drive trains: the flight-control actuator sized for the default duty (a motor and a
#: planetary reduction), the former direct drive, and paper 01's idealisation.
NAMED = ("actuator", "paper01", "direct")
#: Efficiency of the roller screw assumed by :func:`duty_check` (screw torque F·L/(2π·η)):
#: engineering estimate, PRSMs run at 0.8–0.9 (the simulated paper-02 friction gives its own).
SCREW_EFFICIENCY = 0.85
ARCMIN = 2.908882086657216e-4  # rad


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
    continuous_torque : float [N·m]
        The motor's continuous (standstill/rated) torque; 0: not given. The drive-torque
        sensor's ripple is a fraction of it; :func:`duty_check` warns above it.
    peak_current : float [A]
        The drive's current limit; the speed loop saturates at k_t·peak_current (physics: the
        motor can give no more). 0: not given, the profile's ``torque_limit`` applies.
    max_speed : float [rad/s]
        The motor's speed limit; 0: not given. :func:`duty_check` refuses a faster duty.
    gear_ratio : float [-]
        Reduction N between motor and screw, motor turns per screw turn; 1: direct drive (the
        gear fields below are then unused).
    gear_kind : {"planetary", "parallel"}
        Planetary (the input pinion is the sun, meshing in the carrier frame) or a parallel
        stage (spur pair or toothed belt, the pinion on the motor shaft).
    gear_efficiency : float [-]
        Mesh efficiency η of the reduction (driving: motor torque = output torque / (N·η);
        backdriven: × η/N).
    gear_inertia : float [kg·m²]
        Inertia of the reduction referred to its input (the catalogue's J_1), with the motor.
    gear_stiffness : float [N·m/rad]
        Torsional stiffness of the reduction at its output, in series with the coupling;
        0: rigid.
    gear_backlash : float [rad]
        Half of the reduction's backlash at its output (0: none).
    pinion_teeth : int
        Teeth of the input pinion (sun gear or motor pinion); 0: no mesh-order excitation.
    transmission_error : float [rad]
        Amplitude of the transmission error at the mesh order, as an output angle.
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

    # defaults: the flight-control EMA sized for the default duty (module docstring)
    motor_inertia: float = 1.8e-4
    torque_constant: float = 0.49
    pole_pairs: int = 2
    continuous_torque: float = 2.2
    peak_current: float = 9.04
    max_speed: float = 4600.0 * 2.0 * math.pi / 60.0
    gear_ratio: float = 3.0
    gear_kind: str = "planetary"
    gear_efficiency: float = 0.97
    gear_inertia: float = 0.16e-4
    gear_stiffness: float = 2.2e3
    gear_backlash: float = 1.5 * ARCMIN
    pinion_teeth: int = 24
    transmission_error: float = 5e-5
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
        require_range("drive_train.continuous_torque", self.continuous_torque, 0.0, 1e4, unit="N·m")
        require_range("drive_train.peak_current", self.peak_current, 0.0, 1e4, unit="A")
        require_range("drive_train.max_speed", self.max_speed, 0.0, 1e5, unit="rad/s")
        require_range("drive_train.gear_ratio", self.gear_ratio, 1.0, 1000.0)
        require(
            self.gear_kind in GEAR_KINDS,
            "drive_train.gear_kind",
            self.gear_kind,
            f"must be one of {', '.join(GEAR_KINDS)}",
        )
        require_range("drive_train.gear_efficiency", self.gear_efficiency, 0.3, 1.0)
        require_range("drive_train.gear_inertia", self.gear_inertia, 0.0, 1.0, unit="kg·m²")
        require(
            self.gear_stiffness == 0.0 or 10.0 <= self.gear_stiffness <= 1e8,
            "drive_train.gear_stiffness",
            self.gear_stiffness,
            "must be 0 (rigid) or in [10, 1e+08] N·m/rad",
        )
        require_range("drive_train.gear_backlash", self.gear_backlash, 0.0, 0.05, unit="rad")
        require(
            isinstance(self.pinion_teeth, int)
            and not isinstance(self.pinion_teeth, bool)
            and 0 <= self.pinion_teeth <= 500,
            "drive_train.pinion_teeth",
            self.pinion_teeth,
            "must be an integer in [0, 500] (0: no mesh-order excitation)",
        )
        require_range(
            "drive_train.transmission_error", self.transmission_error, 0.0, 0.01, unit="rad"
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
        return cls.direct(coupled=False, rigid_thrust_bearing=True, load_application="nut")

    @classmethod
    def direct(cls, **changes) -> DriveTrain:
        """The former default (before the sized drive): a ~1–2 N·m motor straight on the
        coupling, no reduction, no motor limits (no duty check)."""
        values = dict(
            motor_inertia=3e-5,
            torque_constant=0.5,
            pole_pairs=4,
            continuous_torque=0.0,
            peak_current=0.0,
            max_speed=0.0,
            gear_ratio=1.0,
            gear_efficiency=1.0,
            gear_inertia=0.0,
            gear_stiffness=0.0,
            gear_backlash=0.0,
            pinion_teeth=0,
            transmission_error=0.0,
        )
        values.update(changes)
        return cls(**values)

    @classmethod
    def flight_ema(cls, **changes) -> DriveTrain:
        """The flight-control EMA sized for the default duty (the defaults): 2.2 N·m servo
        motor and a ratio-3 planetary gearhead (module docstring: every figure's source)."""
        return cls(**changes)

    @property
    def geared(self) -> bool:
        """True when a reduction sits between motor and screw (ratio above 1)."""
        return self.gear_ratio != 1.0

    @property
    def mesh_order(self) -> float:
        """Mesh cycles of the reduction's input stage per motor revolution: z_pinion for a
        parallel stage, z_sun·(1 − 1/N) for a planetary one (the sun meshes in the carrier
        frame, which turns at 1/N of the motor); 0 without a reduction or teeth."""
        if not self.geared or not self.pinion_teeth:
            return 0.0
        if self.gear_kind == "parallel":
            return float(self.pinion_teeth)
        return self.pinion_teeth * (1.0 - 1.0 / self.gear_ratio)

    @property
    def peak_torque(self) -> float | None:
        """Motor peak torque k_t·I_peak [N·m] (the speed loop's saturation), None if not given."""
        return self.torque_constant * self.peak_current if self.peak_current else None

    def motor_torque_for(self, screw_torque: float, driving: bool = True) -> float:
        """Steady motor torque [N·m] that holds ``screw_torque`` at the screw through the
        reduction: / (N·η) when the motor drives, × η/N when the load drives it back."""
        n, eta = self.gear_ratio, self.gear_efficiency
        return screw_torque / (n * eta) if driving else screw_torque * eta / n

    def coupling_pair_inertia(self, screw_inertia: float) -> float:
        """Reduced inertia [kg·m²] of the torsional mode between gearbox output and screw: the
        motor side seen from the output, (J_m + J_g)·N², against the screw."""
        j_out = (self.motor_inertia + self.gear_inertia) * self.gear_ratio**2
        return j_out * screw_inertia / (j_out + screw_inertia)

    def reflected_inertia(self, screw_inertia: float) -> float:
        """Inertia the motor accelerates [kg·m²]: motor + reduction + screw / N²."""
        return self.motor_inertia + self.gear_inertia + screw_inertia / self.gear_ratio**2

    def as_dict(self) -> dict:
        return asdict(self)


def load_drive_train(source: str | Path | dict | DriveTrain) -> DriveTrain:
    """A drive train from a name (:data:`NAMED`), a TOML file of :class:`DriveTrain` fields
    (SI, as named in the dataclass), or their dict; unknown keys are named."""
    if isinstance(source, DriveTrain):
        return source
    if isinstance(source, str) and source in NAMED:
        return {
            "actuator": DriveTrain.flight_ema,
            "direct": DriveTrain.direct,
            "paper01": DriveTrain.paper01,
        }[source]()
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


def duty_check(
    drive_train: DriveTrain,
    design,
    peak_load: float,
    max_speed: float,
    *,
    continuous_load: float | None = None,
) -> list[str]:
    """Whether the motor and reduction can run a duty; the warnings to show.

    The steady motor torque that holds a load F [N] at constant speed is
    T_m = |F|·L/(2π·η_s) / (N·η) (L: the design's screw lead, η_s = :data:`SCREW_EFFICIENCY`,
    acceleration torque not included); the motor speed is N·``max_speed`` [rad/s of the screw].
    ``peak_load`` is checked against the peak torque, ``continuous_load`` (the duty's RMS load,
    what heats the winding; default ``peak_load``) against the continuous torque.

    Returns
    -------
    list of str
        One warning when the continuous load's T_m exceeds the motor's continuous torque (the
        duty may run, but not continuously: the motor overheats); empty when within it or when
        the drive train gives no continuous torque.

    Raises
    ------
    ParameterError
        The motor speed exceeds the motor's ``max_speed``, or T_m exceeds its peak torque
        k_t·peak_current (the speed loop would saturate and the duty cannot be run). Checks
        that need a figure the drive train does not give (0) are skipped.
    """
    require_range("duty.peak_load", abs(peak_load), 0.0, 1e7, unit="N")
    require_range("duty.max_speed", abs(max_speed), 0.0, 1e5, unit="rad/s")
    dt = drive_train
    screw_torque = abs(peak_load) * design.screw_lead / (2.0 * math.pi * SCREW_EFFICIENCY)
    motor_torque = dt.motor_torque_for(screw_torque)
    motor_speed = dt.gear_ratio * abs(max_speed)
    if dt.max_speed and motor_speed > dt.max_speed:
        raise ParameterError(
            "duty.max_speed",
            abs(max_speed),
            f"needs {motor_speed:.4g} rad/s at the motor (reduction {dt.gear_ratio:g}), above "
            f"its max_speed {dt.max_speed:.4g} rad/s: at most {dt.max_speed / dt.gear_ratio:.4g} "
            "rad/s at the screw",
        )
    peak = dt.peak_torque
    if peak is not None and motor_torque > peak:
        raise ParameterError(
            "duty.peak_load",
            abs(peak_load),
            f"needs {motor_torque:.3g} N·m at the motor, above its peak torque {peak:.3g} N·m "
            f"(k_t × peak_current): at most {abs(peak_load) * peak / motor_torque:.4g} N",
        )
    steady = abs(peak_load if continuous_load is None else continuous_load)
    steady_torque = motor_torque * steady / abs(peak_load) if peak_load else 0.0
    if dt.continuous_torque and steady_torque > dt.continuous_torque:
        return [
            f"the duty's RMS load {steady:.4g} N needs {steady_torque:.3g} N·m at the motor, "
            f"above its continuous torque {dt.continuous_torque:.3g} N·m: it can run, but not "
            "continuously"
        ]
    return []
