"""The actuator's compliance chain between its two position sensors, and the thread clearance
read from a reversal's lost motion through it.

A slow reversal under a load that follows the motion (±F) pushes the nut from one set of flanks
onto the other. Between the angle sensor and the position sensor, the nut lags the rigid
kinematics (lead × angle) by the play crossed plus every elastic deflection carried by the
load; the lag's jump between the two directions is the *lost motion* L
(:func:`prsm_health.signals.lost_motion.lost_motion_step`). Where the sensors sit decides which
elements count (the simulator's instrumentation, :mod:`prsm_health.simulation.sensors`):

- ``screw_angle`` is the motor's resolver divided by the reduction N: it reads the gearbox
  *input*, so the gearhead's backlash and torsion and the coupling are between the sensors;
- ``nut_position`` reads the nut against the housing (the LVDT's rod is the nut's), so the
  screw's axial travel on its thrust bearing counts, and the linkage and payload beyond the
  rod do not.

The chain, from the angle sensor to the position sensor, each term as the peak-to-peak lag
between +F and −F [m] (``p`` the nut travel per screw radian, lead/2π,
:attr:`~prsm_health.physics.kinematics.SpeedRatios.nut`):

- gearhead backlash: 2·b_g·p (b_g the half-backlash at the output, ``gear_backlash``);
- gear and coupling torsion: the screw torque T = F·p/η_s (η_s the screw's efficiency: the
  motor drives against the load on both strokes), twisting the gear (k_g, at the output) and
  the coupling (k_c) in series: 2T·(1/k_g + 1/k_c)·p;
- thrust bearing (and the screw between bearing and nut, which its stiffness includes):
  2F/k_b, and its play 2·play_b (play_b the half-play, ``thrust_bearing_play``);
- thread contacts: 2·δ(F), δ the axial approach of the rollers' engagements with the load
  shared over the engaged threads (paper 04) and over the rollers
  (:func:`~prsm_health.physics.stiffness.axial.axial_stiffness`; its screw-shaft term is left
  out: the drive train's bearing stiffness already holds the screw, 1.5e8 N/m "in all");
- linkage: 0, beyond the position sensor;
- sensor lag: the sensors' own delays (not the actuator's: ``sensor_delays``, 0 for ideal
  sensors). A channel read through a filter lags the motion by its group delay τ (at the
  reversal's frequency; a first-order low-pass at f_c: τ ≈ 1/(2π·f_c)), so the position
  reads x − τ_x·v and the angle θ − τ_θ·ω: the lag position − p·angle gains −(τ_x − τ_θ)·v,
  which flips with the motion as the play does. Over the two directions that is
  2·(τ_x − τ_θ)·|v| (negative when the angle lags more; a delay common to both cancels), v the
  nut speed p·ω.

Drive-train figures and their sources: :mod:`prsm_health.actuator.drive_train` (gear: Yaskawa
SGMMV manual §11.1.1, 3 arcmin backlash and 10 arcmin torsion at rated torque; coupling:
RINGFEDER GWB DKN size 20, 1.5e3 N·m/rad; thrust bearing: engineering estimate).

**What a fitted step reads.** :func:`~prsm_health.signals.lost_motion.lost_motion_step` fits
one step on the direction of motion over the whole reversal, so it reads the lag averaged over
the samples of each direction. A play is crossed whole at every load; an elastic term follows
the load, which in a cosine reversal is F·|cos φ| with φ uniform in time: a linear term reads
2/π of its peak-to-peak, a Hertzian one (δ ∝ F^(2/3)) about 0.71. :func:`compliance_chain`'s
``reversal_shape`` gives the chain as that reading sees it (``"constant"``: ±F held, the
peak-to-peak itself). The step is fitted beside a polynomial in the position, which cannot
absorb a term that flips with the motion; each position is passed in both directions, so the
step reads the lag's mean times the direction: the sensor lag reads 2·Δτ·p·ω times the mean of
|cos φ|, 2/π, like a linear elastic term (measured, the flight-ema LVDT's 0.318 ms as a pure
delay on an ideal run: +6.64 µm against the 6.45 µm of this mean, the 3 % the fit's polynomial
and the nut's elastic motion move).

**Clearance.** Every roller's thread contacts on the screw side and on the nut side each have
two flanks and a half-clearance b: each side's dead band is 2b, the sides are in series, so a
reversal crosses 4b of play at zero load (paper 01's f(δ, b) on both engagements) —
:data:`CLEARANCE_SLOPE`. :func:`clearance_from_lost_motion` inverts L = chain + 4·b.
Simulated units read a slightly lower slope (3.80 on the built-in check with uneven wear): the
rollers' gaps differ (wear spread, pitch errors), the rollers with the smaller gaps carry more
of the load and, Hertzian, are the stiffer, so the common approach follows a load-weighted
mean of the gaps, below their plain mean.

References
----------
- Paper 01 (docs/references.md) §1.1–1.3 — the backlash function f(δ, b) of each thread
  engagement (the dead band of 2b per engagement behind :data:`CLEARANCE_SLOPE`).
- Paper 04 (docs/references.md) — the axial stiffness of the engaged threads,
  1/K_total = 1/K_engaged + 1/K_shaft (the thread-contact term; its K_shaft part left out).
- ISO 230-2:2014 §3.2 — the reversal value B: the mean offset between the two directions of
  approach, which :func:`~prsm_health.signals.lost_motion.lost_motion_step` fits.
- Drive train: :mod:`prsm_health.actuator.drive_train` (the datasheets named above).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.drive_train import SCREW_EFFICIENCY, DriveTrain
from prsm_health.core.errors import require, require_range

from .kinematics import speed_ratios
from .stiffness.axial import axial_stiffness

#: Lost motion per metre of the thread half-clearance b: 4 (module docstring, Clearance).
CLEARANCE_SLOPE = 4.0
REVERSAL_SHAPES = ("constant", "cosine")
#: The channels the lost motion reads, whose delays enter the sensor term.
DELAYED_CHANNELS = ("nut_position", "screw_angle")
#: Phases of a cosine reversal averaged over (uniform in time): the mean of |cos φ|^(2/3)
#: over 256 midpoints is exact to ~1e-4.
_PHASES = 256
#: Quantiles of a recording's load shares the thread term is averaged over.
_QUANTILES = 64


@dataclass(frozen=True)
class LostMotionChain:
    """Each element's lost motion [m] between the angle and the position sensor, for a reversal
    between +``load_amplitude`` and −``load_amplitude`` (module docstring: the equations).

    Attributes
    ----------
    gear_backlash, gear_coupling_twist, thrust_bearing, thrust_bearing_play, thread_contacts,
    linkage : float [m]
        ``thrust_bearing`` its elastic part 2F/k_b, ``thrust_bearing_play`` its play 2·play_b.
    sensor_lag : float [m]
        The position sensor's delay behind the angle sensor's, as lost motion (0: ideal).
    load_amplitude : float [N]
    reversal_shape : {"constant", "cosine"}
        ``constant``: the peak-to-peak at ±F; ``cosine``: as a step fitted over a cosine
        reversal reads it (elastic terms averaged over the load's |cos φ|).
    """

    gear_backlash: float
    gear_coupling_twist: float
    thrust_bearing: float
    thrust_bearing_play: float
    thread_contacts: float
    linkage: float
    sensor_lag: float
    load_amplitude: float
    reversal_shape: str

    @property
    def terms(self) -> dict[str, float]:
        """Element → its lost motion [m], in the chain's order."""
        return {f.name: getattr(self, f.name) for f in fields(self)[:7]}

    @property
    def total(self) -> float:
        """The lost motion of the chain at b = 0 [m]."""
        return float(sum(self.terms.values()))

    @property
    def constant(self) -> float:
        """Its part that does not follow the load [m]: the plays crossed whole (gearhead
        backlash, thrust-bearing play) and the sensors' lag (a speed's, not a load's)."""
        return self.gear_backlash + self.thrust_bearing_play + self.linkage + self.sensor_lag

    @property
    def elastic(self) -> float:
        """Its part that follows the load [m]: torsion, the bearing's and the threads'
        deflections."""
        return self.total - self.constant


def compliance_chain(
    design: PRSMDesign,
    drive_train: DriveTrain,
    load_amplitude: float,
    *,
    reversal_shape: str = "constant",
    screw_efficiency: float = SCREW_EFFICIENCY,
    speed_amplitude: float | None = None,
    sensor_delays: Mapping[str, float] | None = None,
    load_shares=None,
    screw_torque: float | None = None,
) -> LostMotionChain:
    """The actuator's lost motion at b = 0 for a reversal under ±``load_amplitude`` [N], element
    by element (module docstring: the equations, the sensors' places, the sources).

    Parameters
    ----------
    design : PRSMDesign
    drive_train : DriveTrain
        ``coupled = False`` takes the reduction and coupling as rigid, ``rigid_thrust_bearing``
        the bearing, ``gear_stiffness = 0`` the gear.
    load_amplitude : float [N]
        F > 0, the load on each side of the reversal.
    reversal_shape : {"constant", "cosine"}
        How the load follows the reversal: held at ±F (the peak-to-peak), or F·cos of the
        cosine reversal (the built-in check's), read as a fitted step.
    screw_efficiency : float [-]
        η_s of the screw torque T = F·p/η_s (default: the drive train's estimate, 0.85).
    speed_amplitude : float [rad/s], optional
        The screw speed ω of the reversal (its amplitude for a cosine); needed with
        ``sensor_delays``.
    sensor_delays : mapping, optional
        ``{"nut_position": τ_x, "screw_angle": τ_θ}`` [s], each channel's group delay at the
        reversal's frequency (a missing channel: 0; from a simulated instrumentation,
        :func:`prsm_health.simulation.sensors.channel_group_delay`). None: ideal sensors, no
        sensor term.
    load_shares : array-like, optional
        |F(t)|/F over the samples the reading averages, each in [0, 1] (the load follows the
        speed, so a recording gives them as |ω(t)|/ω): overrides ``reversal_shape`` — a
        triangle reversal, or a step fitted only where the speed is beyond a share of its
        amplitude (:func:`~prsm_health.signals.lost_motion.settled_lost_motion_step`).
    screw_torque : float [N·m], optional
        The mean |torque| on the screw over the samples read, measured (the drive's torque
        through the reduction): the torsion term is then 2·T·(1/k_g + 1/k_c)·p with it instead
        of F·p/η_s — the friction the load does not carry (preload, viscous drag, a degraded
        lubricant) winds the train up too.
    """
    require_range("load_amplitude", load_amplitude, 1e-3, 1e7, unit="N")
    require(
        reversal_shape in REVERSAL_SHAPES,
        "reversal_shape",
        reversal_shape,
        f"must be one of {', '.join(REVERSAL_SHAPES)}",
    )
    require_range("screw_efficiency", screw_efficiency, 0.1, 1.0)
    dt = drive_train
    lead = speed_ratios(design).nut  # nut travel per screw radian [m/rad]
    # the loads the reading averages over (one for ±F held)
    if load_shares is not None:
        shares = np.asarray(load_shares, dtype=float).ravel()
        require(
            len(shares) > 0 and bool(np.all((shares >= 0.0) & (shares <= 1.0))),
            "load_shares",
            f"{len(shares)} values",
            "must be one or more shares of the load in [0, 1]",
        )
        mean_share = float(np.mean(shares))
        if len(shares) > _QUANTILES:
            # the thread term's mean over thousands of samples from its quantiles: a smooth
            # function of the load, so 64 of them give its mean to ~1e-5 (measured on a
            # recording's 6 600 settled samples), and the axial stiffness costs per load
            # (0.4 s a chain over all of them)
            shares = np.quantile(shares, (np.arange(_QUANTILES) + 0.5) / _QUANTILES)
            shares *= mean_share / float(np.mean(shares))  # the linear terms' mean kept exact
        loads = load_amplitude * shares
    elif reversal_shape == "cosine":
        phases = (np.arange(_PHASES) + 0.5) * (0.5 * math.pi / _PHASES)
        loads = load_amplitude * np.cos(phases)
    else:
        loads = np.array([float(load_amplitude)])
    mean_load = float(np.mean(loads))

    rigid_drive = not dt.coupled
    backlash = 0.0 if rigid_drive or not dt.geared else 2.0 * dt.gear_backlash * lead
    twist = 0.0
    if not rigid_drive:
        compliance = 1.0 / dt.coupling_stiffness
        if dt.geared and dt.gear_stiffness > 0.0:
            compliance += 1.0 / dt.gear_stiffness
        torque = mean_load * lead / screw_efficiency if screw_torque is None else screw_torque
        twist = 2.0 * torque * compliance * lead
    bearing = bearing_play = 0.0
    if not dt.rigid_thrust_bearing:
        bearing = 2.0 * mean_load / dt.thrust_bearing_stiffness
        bearing_play = 2.0 * dt.thrust_bearing_play
    sensor_lag = 0.0
    if sensor_delays is not None:
        unknown = set(sensor_delays) - set(DELAYED_CHANNELS)
        require(
            not unknown, "sensor_delays", sorted(unknown), f"keys: {', '.join(DELAYED_CHANNELS)}"
        )
        require(speed_amplitude is not None, "speed_amplitude", None, "needed with sensor_delays")
        require_range("speed_amplitude", speed_amplitude, 1e-6, 1e4, unit="rad/s")
        delays = {c: float(sensor_delays.get(c, 0.0)) for c in DELAYED_CHANNELS}
        for channel, delay in delays.items():
            require_range(f"sensor_delays.{channel}", delay, -1.0, 1.0, unit="s")
        # |v| averaged like the loads: p·ω·|cos φ| follows the same phases as F·|cos φ|
        mean_speed = lead * speed_amplitude * mean_load / load_amplitude
        lag = delays["nut_position"] - delays["screw_angle"]
        sensor_lag = 2.0 * lag * mean_speed
    axial = axial_stiffness(design, loads)
    contact = axial.deformation - axial.deformation_split["shaft"]
    return LostMotionChain(
        gear_backlash=float(backlash),
        gear_coupling_twist=float(twist),
        thrust_bearing=float(bearing),
        thrust_bearing_play=float(bearing_play),
        thread_contacts=float(2.0 * np.mean(contact)),
        linkage=0.0,
        sensor_lag=float(sensor_lag),
        load_amplitude=float(load_amplitude),
        reversal_shape=reversal_shape,
    )


def clearance_from_lost_motion(
    lost_motion: float, chain: LostMotionChain, slope: float = CLEARANCE_SLOPE
) -> float:
    """The thread half-clearance b [m] from a reversal's lost motion L [m]:
    b = (L − chain.total)/slope, slope 4 (module docstring: 4b of play at zero load). Negative
    when L is below the chain (a preload, or a chain softer than the actuator's): not clipped,
    so the error shows."""
    require(math.isfinite(lost_motion), "lost_motion", lost_motion, "must be a finite length")
    require_range("slope", slope, 0.5, 10.0)
    return (lost_motion - chain.total) / slope
