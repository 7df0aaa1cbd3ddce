"""The recirculating PRSM (paper 03) as a dynamic model: the nut and each grooved roller moving
axially, the threads, the threadless sector and the two cam rings.

Bodies and degrees of freedom
-----------------------------
The screw turns at a prescribed speed ω_s(t) (constant or piecewise linear, forward or at rest)
and is axially fixed (rigid); the carrier turns with it
at the rolling ratio ω_c = d_s/(2d_c)·ω_s (eq. 25: no slip, the paper's own simulation is within
1 % of it); the nut (with its cam rings) and every roller move axially — the N + 1 axial
degrees of freedom, integrated by a guarded fixed-step RK4 (:mod:`._kernels`) — and the payload
either rides rigidly on the nut or sits behind a linkage (spring and damper: one more degree of
freedom, the load on it; the standard model's drive train, :mod:`prsm_health.actuator.drive_train`).

Forces, each from one contact law and its energy
------------------------------------------------
- **Threads.** A grooved roller (no helix) engages the screw and the nut threads of lead L: its
  axial error against the nearest screw groove is e_s = wrap_p(z − L(θ_s − φ)/2π − c_s) and
  against the nut's e_n = wrap_p(z − x_n + Lφ/2π − c_n) (φ its orbital angle, p the pitch,
  c the assembly offsets that centre every roller at the start, eqs. 35–37); held in both, the
  nut advances L per screw turn (eq. 28) and the roller drifts back one lead per carrier
  revolution relative to the nut (eq. 31). Each side is a Hertz contact beyond a half-clearance
  b: F = K·(|e| − b)^1.5 (+ damping), K matched to paper 04's thread stiffness at the nominal
  share of the load (:func:`prsm_health.physics.stiffness.thread_load.roller_side_stiffness`).
- **The threadless sector (2β, eq. 11).** Inside it a roller is lifted over the screw thread and
  out of the nut's: both sides' play grows by the radial lift h_r (eq. 8's) times cot β_flank (a
  radial gap h is an axial gap h·cos β/sin β at a flank at β), up over the first quarter of β,
  held, down over the last quarter — so the threads let go and take the roller back gradually.
- **Cam rings.** The roller sits between two cam rings fixed to the nut, their faces the cam
  spacing h (eq. 36's layout) apart: the roller (s1 + s2 long) has L + p/N of axial room. The
  ring on the side the roller drifts to carries the convex platform: in the sector its chamfer
  (α/2) pushes the roller forward by one lead over the first β (the crossing, eqs. 9–11), its
  top holds it, its exit edge drops over the last lift ramp. Every ring contact is the paper's
  ADAMS IMPACT law (eq. 38, §4.1: K = 1e5 N/mm, e = 1.5, C = 50 N·s/mm, d = 0.1 mm); the far
  ring's face stops a roller the push threw too far.
- **Spin.** Each roller's spin about its axis: on its threads rolling holds it at eq. (27)'s
  (set after every step — the threads' friction spins a landing roller up in microseconds —,
  the drive's work I·Ω·ΔΩ and the slip's ½·I·ΔΩ² booked); lifted out of them, the cam rings'
  friction turns it — the paper's ADAMS Coulomb law (§4.1: μ_s 0.3, μ_d 0.25 reached at 0.9
  and 1.0 m/s of slip) at the middle of the platform's annulus (eqs. 20–21), where the
  roller's face slips forward, so the platform speeds the spin up (Fig. 23's change at the
  reset, the opposite sign to the paper's drop: docs/validation.md). Tangential: no axial
  effect.
- **Load.** An axial force on the nut, positive opposing forward motion (negative: assisting
  it, the other flanks carry it): constant, or the profile's knots plus a sinusoid (a reversing
  load swings it through zero: the rollers cross their clearance), ramped in over ``load_ramp``
  (a step would ring the nut on its threads for the whole run).

Faults, each a change of one surface (:mod:`prsm_health.actuator.faults` maps a health state's
faults onto them): a **nut spall** (:class:`NutSpall`: the loaded flank lower over an arc, on
a share of the turns); **cam-chamfer wear** (the chamfer's entrance worn down, tapering to its
top: met later, climbed faster); **platform height loss** (the top lower: the push falls short
of a lead, the threads must finish the reset); a damaged **re-entry edge** (:class:`~prsm_health.actuator.faults.ReentryEdgeDamage`:
both nut flanks lower over a stretch after the exit: the landing roller takes its share back
later, at the intact thread). What the model shows of them (docs/faults.md): the worn chamfer
moves the entry pulse by the geometry's β·w/(stroke + w); an edge chip deeper than the landing
roller's offset (up to p/N) delays the landing to the intact thread; the platform's lost height
is masked at every speed tried (2–126 rad/s) because nothing holds a lifted roller on the
platform — the chamfer's elastic push throws it at twice the chamfer's speed and it rattles
between the platform and the far ring until the threads take it back.

Idealised: the platform top holds a reset roller across the whole threadless area (2β) until the
nut thread takes it back; the paper lays out one β per direction of rotation, so a real roller
runs the second β free of the platform. Forward rotation or rest only — the speed may vary
(the motion's knots), the load may reverse. Turning back needs the second platform, on the other
ring, for the other direction: the paper lays it out over the other β but does not dimension
it, and with both platforms full height over the area the forward-reset roller (one lead from
the first ring) would stand where the second one is — so their real layout differs, and is
not modelled. Not modelled: the threads' friction beyond rolling (sliding losses, the drive's
efficiency), the carrier grooves' tangential gap (the carrier collisions of Fig. 32: the gap is
not given), radial and tilting motion; the screw's own axial and torsional compliance. The
energy of every modelled contact is accounted for: the work of the prescribed screw/carrier
motion equals the change of kinetic and elastic energy plus what the dampers and the
friction took plus the work against the load (:attr:`RecirculatingRun.energy_error`).

References
----------
Paper 03 — eqs. (8)–(11) threadless area and crossing, (25)–(31) motion, (35)–(37) assembly,
(38) and §4.1 contact and friction; paper 04 — thread stiffness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.faults import ReentryEdgeDamage
from prsm_health.core.errors import ConvergenceError, require, require_positive
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.recirculating import (
    PAPER03_CONTACT,
    ImpactContact,
    RecirculatingGeometry,
    cam_ring_spacing,
    orbital_angle,
    platform_contact_offset,
    radial_lift,
    reset_stroke,
)
from prsm_health.physics.stiffness.thread_load import roller_side_stiffness

from . import _kernels as K

#: Outer step of the integrator [s]: a quarter of the period of a roller on its threads (≈ 30 kHz
#: for the paper03 preset); the guard cuts it wherever a contact needs less.
STEP = 2e-6
#: Most sub-steps the guard may cut one outer step into before it refuses the run.
MAX_SUBSTEPS = 2000
#: Damping ratio of a roller on one thread side (the standard model's contact damping).
THREAD_DAMPING_RATIO = 0.03
#: Penetration over which the thread damping switches on [m] (continuity at first contact).
THREAD_DAMPING_DEPTH = 1e-6
#: Share of β over which the lift (and the platform's exit edge) ramps.
LIFT_RAMP_SHARE = 0.25
#: The load's rise from zero at the start [s]: the model starts unloaded (a step would ring the
#: nut on its threads for the whole run).
LOAD_RAMP = 5e-3
#: Paper 03 §4.1's Coulomb friction of its ADAMS model (every contact): static and dynamic
#: coefficients, the slip speeds [m/s] where each is reached.
FRICTION_STATIC, FRICTION_DYNAMIC = 0.3, 0.25
SLIP_STATIC, SLIP_DYNAMIC = 0.9, 1.0


@dataclass(frozen=True)
class NutSpall:
    """A spall on the nut's thread flank: material missing over an arc of the rollers' path.

    Every roller passes it once per carrier revolution — N·f_c, the rate of the resets: each
    drops by ``depth`` into it, unloading, and strikes its far edge as the flank takes the load
    back (the load sets the strike; the reset's platform impact does not feel the load).

    Parameters
    ----------
    angle : float [rad]
        Orbital angle (nut frame) where the spall starts, from the threadless area's entrance
        side (−β).
    length : float [m]
        Its length along the thread (an arc of the orbit radius d_c/2).
    depth : float [m]
        Material missing from the flank, > 0.
    share : float [-]
        Share of the engaged thread turns it is on, in (0, 1]: 1/n_t for a spall on one turn
        (what a health state's ``spall`` fault on the nut makes: the spalled turn's share of
        the contact closes ``depth`` later, the other turns as before, as in the standard
        model), 1 for a spall across every turn at that angle (the spall study's worst case).
    """

    angle: float
    length: float
    depth: float
    share: float = 1.0

    def __post_init__(self):
        require(
            isinstance(self.angle, (int, float)) and math.isfinite(self.angle),
            "nut_spall.angle",
            self.angle,
            "must be a finite angle [rad]",
        )
        require_positive("nut_spall.length", self.length)
        require_positive("nut_spall.depth", self.depth)
        require(
            isinstance(self.share, (int, float)) and 0.0 < self.share <= 1.0,
            "nut_spall.share",
            self.share,
            "must be in (0, 1]: the share of the engaged thread turns the spall is on",
        )


@dataclass(frozen=True)
class RecirculatingRun:
    """Truth of a simulated recirculating PRSM (SI units; roller arrays are rollers × samples).

    Attributes
    ----------
    time, nut_position, nut_velocity, nut_acceleration : numpy.ndarray [s, m, m/s, m/s²]
    drive_torque : numpy.ndarray [N·m]
        The torque the prescribed screw (and, through rolling, carrier) motion takes: its
        power over ω_s.
    axial_load : numpy.ndarray [N]
        The applied load at each sample (positive resists forward motion), on the nut or,
        behind a linkage, on the payload.
    linkage_force, payload_position, payload_velocity : numpy.ndarray [N, m, m/s]
        The linkage's force on the nut (what a load cell in the rod reads; the load itself
        without a linkage) and the payload's motion (the nut's without a linkage).
    roller_position : numpy.ndarray [m]
        Each roller's axial position relative to the nut (0: against the left cam ring).
    screw_force, nut_force, cam_force : numpy.ndarray [N]
        Axial force on each roller from the screw thread, the nut thread, the cam rings.
    in_sector : numpy.ndarray of bool
        Whether each roller is in the threadless sector.
    roller_spin : numpy.ndarray [rad/s]
        Each roller's angular speed about its axis (absolute; eq. 27's while it rolls).
    resets : numpy.ndarray of int
        Crossings of the sector each roller completed.
    work_in, dissipated, work_load, mechanical_energy : numpy.ndarray [J]
        Cumulative work of the prescribed motion, energy the dampers took, work against the
        load; kinetic plus elastic energy.
    screw_angle, screw_speed, carrier_speed : numpy.ndarray [rad, rad/s, rad/s]
        The prescribed screw motion and the carrier's (rolling ratio).
    """

    time: np.ndarray
    nut_position: np.ndarray
    nut_velocity: np.ndarray
    nut_acceleration: np.ndarray
    drive_torque: np.ndarray
    axial_load: np.ndarray
    linkage_force: np.ndarray
    payload_position: np.ndarray
    payload_velocity: np.ndarray
    roller_position: np.ndarray
    screw_force: np.ndarray
    nut_force: np.ndarray
    cam_force: np.ndarray
    in_sector: np.ndarray
    roller_spin: np.ndarray
    resets: np.ndarray
    work_in: np.ndarray
    dissipated: np.ndarray
    work_load: np.ndarray
    mechanical_energy: np.ndarray
    screw_angle: np.ndarray
    screw_speed: np.ndarray
    carrier_speed: np.ndarray

    @property
    def energy_error(self) -> float:
        """|ΔE − (W_in − W_diss − W_load)| at the end over the gross work that flowed in or out
        (∫|P| dt of the drive and of the load: a reversing load's net works cancel) [-]."""
        balance = self.work_in[-1] - self.dissipated[-1] - self.work_load[-1]
        change = self.mechanical_energy[-1] - self.mechanical_energy[0]
        drive = np.abs(self.drive_torque * self.screw_speed)
        load = np.abs(self.axial_load * self.payload_velocity)
        scale = max(
            float(np.trapezoid(drive, self.time)), float(np.trapezoid(load, self.time)), 1e-12
        )
        return abs(change - balance) / scale


def simulate_recirculating(
    design: PRSMDesign,
    *,
    screw_speed,
    load,
    duration: float,
    load_sine: tuple[float, float] = (0.0, 0.0),
    clearance: float = 5e-6,
    clearance_nut: float | None = None,
    payload_mass: float = 0.0,
    load_ramp: float = LOAD_RAMP,
    linkage: tuple[float, float] | None = None,
    contact: ImpactContact = PAPER03_CONTACT,
    nut_spall: NutSpall | None = None,
    cam_wear: float = 0.0,
    platform_loss: float = 0.0,
    reentry_edge: ReentryEdgeDamage | None = None,
    step: float = STEP,
) -> RecirculatingRun:
    """Simulate a recirculating PRSM: the screw turning forward (a constant speed or the
    motion's knots) under an axial load.

    Parameters
    ----------
    design : PRSMDesign
        A recirculating design (its ``[recirculation]`` geometry, or paper 03's rules).
    screw_speed : float or array of shape (2 or 3, K) [rad/s; s, rad/s]
        A constant speed > 0, or the motion's knots (times from 0, speeds ≥ 0; a third row
        of angles, as ``OperatingProfile.motion_knots`` gives it, is recomputed), the speed
        linear between knots: forward rotation or rest (the left ring's platform resets the
        rollers); the load may reverse.
    load : float or array of shape (2, K) [N; s, N]
        Axial load on the nut (positive resists forward motion): a constant, or knots
        (times, loads) interpolated linearly (``OperatingProfile.load_knots``).
    load_sine : (float, float) [N, Hz]
        Amplitude and frequency of a sinusoid added to the load.
    duration : float [s]
    clearance : float [m]
        Half-clearance of each roller on the screw side (and the nut side unless
        ``clearance_nut``).
    clearance_nut : float or None [m]
        Half-clearance on the nut side (None: ``clearance``).
    payload_mass : float [kg]
        Mass moving with the nut (besides the design's nut mass), or behind the linkage.
    linkage : (float, float) or None [N/m, -]
        Stiffness and damping ratio (of the payload on it, nut held) of a linkage between the
        nut and the payload: the load then acts on the payload and the nut feels the linkage's
        force (an actuator's rod end and attachment, as the standard model's drive train);
        None: the payload rides rigidly on the nut and the load acts on the nut.
    load_ramp : float [s]
        Time over which the load rises from 0.
    contact : ImpactContact
        The cam-ring contact (default paper 03 §4.1).
    nut_spall : NutSpall or None
        A spall on the nut's thread flank (None: healthy).
    cam_wear : float [m]
        Material the rollers' strikes wore off the chamfer's entrance (0: new), tapering to
        nothing at the platform's top: the roller meets the chamfer later and is pushed faster
        (the reset's entry pulse later and stronger). At most half the reset stroke.
    platform_loss : float [m]
        Height the platform lost (0: new): the reset pushes the roller L − h instead of one
        lead L, and the nut thread pushes the landing roller the rest (a strike at the exit,
        whatever the load). Below 0.4 of the pitch: at p/2 the landing roller's nearest groove
        is the one it left — the reset fails and the roller jams against the ring at its next
        pass (not modelled: refused).
    reentry_edge : ReentryEdgeDamage or None
        Damage at the nut thread's re-entry edge (the health state's fault of
        :mod:`prsm_health.actuator.faults`; None: intact).
    step : float [s]
        Outer step; the guard sub-steps where a contact needs it.

    Raises
    ------
    ParameterError
        A standard design, or a value out of range (named).
    ConvergenceError
        A contact stiffer than :data:`MAX_SUBSTEPS` sub-steps of ``step`` can follow.
    """
    require(
        design.variant == "recirculating",
        "design.variant",
        design.variant,
        "must be 'recirculating' (the standard PRSM runs in prsm_health.simulation.dynamics)",
    )
    motion = _motion_knots(screw_speed, duration)
    knots = _load_knots(load, duration)
    require(
        len(load_sine) == 2 and all(math.isfinite(v) for v in load_sine) and load_sine[1] >= 0,
        "load_sine",
        load_sine,
        "must be (amplitude [N], frequency ≥ 0 [Hz])",
    )
    require_positive("duration", duration)
    require_positive("clearance", clearance)
    if clearance_nut is not None:
        require_positive("clearance_nut", clearance_nut)
    require_positive("step", step)
    require(
        isinstance(payload_mass, (int, float)) and payload_mass >= 0,
        "payload_mass",
        payload_mass,
        "must be ≥ 0 [kg]",
    )
    require(
        isinstance(load_ramp, (int, float)) and load_ramp >= 0,
        "load_ramp",
        load_ramp,
        "must be ≥ 0 [s]",
    )
    require(
        isinstance(cam_wear, (int, float)) and 0.0 <= cam_wear <= 0.5 * reset_stroke(design),
        "cam_wear",
        cam_wear,
        f"must be in [0, {0.5 * reset_stroke(design):g}] m: at most half the reset stroke",
    )
    require(
        isinstance(platform_loss, (int, float)) and 0.0 <= platform_loss < 0.4 * design.pitch,
        "platform_loss",
        platform_loss,
        f"must be in [0, {0.4 * design.pitch:g}) m: below 0.4 pitch (from p/2 the reset fails "
        "and the roller jams against the ring, which the model does not follow)",
    )
    if linkage is not None:
        stiffness, ratio = linkage
        require_positive("linkage stiffness", stiffness)
        require(
            isinstance(ratio, (int, float)) and ratio >= 0,
            "linkage damping ratio",
            ratio,
            "must be ≥ 0",
        )
        require(payload_mass > 0, "payload_mass", payload_mass, "must be > 0 behind a linkage")
    p, rollers, y0 = _parameters(
        design,
        motion[1, 0],
        float(np.max(np.abs(knots[1]))) + abs(float(load_sine[0])),
        clearance=clearance,
        clearance_nut=clearance_nut,
        payload_mass=payload_mass,
        linkage=linkage,
        load_ramp=load_ramp,
        load_sine=load_sine,
        contact=contact,
        nut_spall=nut_spall,
        cam_wear=cam_wear,
        platform_loss=platform_loss,
        reentry_edge=reentry_edge,
    )
    n_steps = int(round(duration / step)) + 1
    n = design.n_rollers
    out = np.zeros((n_steps, K.OUT_SIZE))
    roller_out = np.zeros((n_steps, n, K.ROLLER_SIZE))
    done = K.integrate(y0, p, rollers, knots, motion, step, n_steps, MAX_SUBSTEPS, out, roller_out)
    if done < n_steps:
        raise ConvergenceError(
            f"recirculating PRSM: at t = {done * step:.6g} s a contact needs more than "
            f"{MAX_SUBSTEPS} sub-steps of {step:g} s: lower step or check the contact parameters"
        )
    sector = roller_out[:, :, K.ROLLER_SECTOR].T > 0.5
    exits = np.sum(sector[:, :-1] & ~sector[:, 1:], axis=1)
    return RecirculatingRun(
        time=out[:, K.OUT_T],
        nut_position=out[:, K.OUT_X],
        nut_velocity=out[:, K.OUT_V],
        nut_acceleration=out[:, K.OUT_A],
        drive_torque=out[:, K.OUT_TORQUE],
        axial_load=out[:, K.OUT_LOAD],
        linkage_force=out[:, K.OUT_ROD],
        payload_position=out[:, K.OUT_XP],
        payload_velocity=out[:, K.OUT_VP],
        roller_position=roller_out[:, :, K.ROLLER_U].T.copy(),
        screw_force=roller_out[:, :, K.ROLLER_F_SCREW].T.copy(),
        nut_force=roller_out[:, :, K.ROLLER_F_NUT].T.copy(),
        cam_force=roller_out[:, :, K.ROLLER_F_CAM].T.copy(),
        in_sector=sector,
        roller_spin=roller_out[:, :, K.ROLLER_SPIN].T.copy(),
        resets=exits.astype(int),
        work_in=out[:, K.OUT_W_IN],
        dissipated=out[:, K.OUT_W_DISS],
        work_load=out[:, K.OUT_W_LOAD],
        mechanical_energy=out[:, K.OUT_ENERGY],
        screw_angle=out[:, K.OUT_THETA],
        screw_speed=out[:, K.OUT_OMEGA],
        carrier_speed=speed_ratios(design).carrier * out[:, K.OUT_OMEGA],
    )


def _motion_knots(screw_speed, duration: float) -> np.ndarray:
    """The screw's motion as (3, K) knots [s, rad/s, rad], checked: forward or at rest."""
    what = "forward rotation or rest only (turning back needs the other direction's platform, "
    what += "which paper 03 does not dimension)"
    if isinstance(screw_speed, (int, float)):
        require(
            math.isfinite(screw_speed) and screw_speed > 0,
            "screw_speed",
            screw_speed,
            f"must be a finite speed > 0 [rad/s]: {what}",
        )
        times, speeds = np.array([0.0, max(duration, 1e-9)]), np.full(2, float(screw_speed))
    else:
        given = np.asarray(screw_speed, dtype=float)
        require(
            given.ndim == 2
            and given.shape[0] in (2, 3)
            and given.shape[1] >= 2
            and bool(np.all(np.isfinite(given[:2])))
            and given[0, 0] == 0.0
            and bool(np.all(np.diff(given[0]) > 0)),
            "screw_speed",
            f"array of shape {given.shape}",
            "must be a speed [rad/s] or (2 or 3, K ≥ 2) knots: increasing times from 0 [s], "
            "finite speeds [rad/s]",
        )
        times, speeds = given[0], given[1]
        require(
            bool(np.all(speeds >= 0.0)) and bool(np.any(speeds > 0.0)),
            "screw_speed",
            f"knots from {speeds.min():g} to {speeds.max():g} rad/s",
            f"must be ≥ 0 and not all 0: {what}",
        )
    angles = cumulative_trapezoid(speeds, times, initial=0.0)  # exact: linear between knots
    return np.ascontiguousarray(np.vstack([times, speeds, angles]))


def _load_knots(load, duration: float) -> np.ndarray:
    """The load as (2, K) knots [s, N], checked."""
    if isinstance(load, (int, float)):
        require(math.isfinite(load), "load", load, "must be a finite force [N]")
        return np.array([[0.0, max(duration, 1e-9)], [float(load), float(load)]])
    knots = np.asarray(load, dtype=float)
    require(
        knots.ndim == 2
        and knots.shape[0] == 2
        and knots.shape[1] >= 2
        and bool(np.all(np.isfinite(knots)))
        and bool(np.all(np.diff(knots[0]) > 0)),
        "load",
        f"array of shape {knots.shape}",
        "must be a force [N] or (2, K ≥ 2) knots: increasing times [s], finite forces [N]",
    )
    return np.ascontiguousarray(knots)


def _parameters(
    design,
    screw_speed,
    nominal_load,
    *,
    clearance,
    clearance_nut=None,
    payload_mass=0.0,
    linkage=None,
    load_ramp,
    load_sine=(0.0, 0.0),
    contact,
    nut_spall=None,
    cam_wear=0.0,
    platform_loss=0.0,
    reentry_edge=None,
):
    """(parameter vector, per-roller table, initial state) of :func:`simulate_recirculating`'s
    checked arguments: ``screw_speed`` [rad/s] the speed at t = 0, ``nominal_load`` [N] the
    largest load, which sets the threads' Hertz constant."""
    geometry = RecirculatingGeometry.for_design(design)
    n = design.n_rollers
    lead, pitch = design.screw_lead, design.pitch
    beta = orbital_angle(design)
    ratio = speed_ratios(design).carrier
    room = cam_ring_spacing(design, geometry) - (
        geometry.roller_half_length_1 + geometry.roller_half_length_2
    )
    m_r = design.masses.roller_mass
    # the thread's Hertz constant from paper 04's stiffness at the nominal share: all but the
    # rollers crossing carry the load (one at a time for the presets)
    share = max(abs(nominal_load), 1.0) / max(n - 1, 1)
    k_lin = min(
        float(roller_side_stiffness(design, share, "screw")),
        float(roller_side_stiffness(design, share, "nut")),
    )
    deflection = 1.5 * share / k_lin  # F = K δ^1.5 with dF/dδ = k_lin at F = share
    k_hertz = share / deflection**1.5
    p = np.zeros(K.P_SIZE)
    p[K.P_N] = n
    p[K.P_LEAD] = lead
    p[K.P_PITCH] = pitch
    p[K.P_M_ROLLER] = m_r
    p[K.P_M_NUT] = design.masses.nut_mass + payload_mass
    p[K.P_K_THREAD] = k_hertz
    p[K.P_B_SCREW] = clearance
    p[K.P_C_THREAD] = 2.0 * THREAD_DAMPING_RATIO * math.sqrt(k_lin * m_r)
    p[K.P_D_THREAD] = THREAD_DAMPING_DEPTH
    p[K.P_K_CAM] = contact.stiffness
    p[K.P_E_CAM] = contact.exponent
    p[K.P_C_CAM] = contact.max_damping
    p[K.P_D_CAM] = contact.depth
    p[K.P_ROOM] = room
    p[K.P_STROKE] = reset_stroke(design)
    p[K.P_BETA] = beta
    p[K.P_LIFT] = radial_lift(design)
    p[K.P_LIFT_RAMP] = LIFT_RAMP_SHARE * beta
    p[K.P_COT_FLANK] = 1.0 / math.tan(design.contact_angle)
    p[K.P_RATIO] = ratio
    p[K.P_PHI_ENTRY] = -beta  # §3.2: forward rotation enters at −β
    p[K.P_LOAD_RAMP] = load_ramp
    # the roller's spin: paper 03 §4.1's friction at the cam rings, rolling on the threads
    p[K.P_MU_STATIC], p[K.P_MU_DYNAMIC] = FRICTION_STATIC, FRICTION_DYNAMIC
    p[K.P_V_STATIC], p[K.P_V_DYNAMIC] = SLIP_STATIC, SLIP_DYNAMIC
    p[K.P_I_ROLLER] = design.masses.roller_inertia
    p[K.P_SPIN_RATIO] = speed_ratios(design).roller_spin
    p[K.P_R_ORBIT] = design.orbit_diameter / 2
    p[K.P_R_FACE] = platform_contact_offset(design, geometry)
    p[K.P_B_NUT] = clearance if clearance_nut is None else clearance_nut
    p[K.P_LOAD_SINE], p[K.P_LOAD_FREQUENCY] = float(load_sine[0]), float(load_sine[1])
    if linkage is not None:  # the payload behind it, no longer in the nut's mass
        stiffness, damping_ratio = linkage
        p[K.P_M_NUT] = design.masses.nut_mass
        p[K.P_M_PAYLOAD] = payload_mass
        p[K.P_LINK_K] = stiffness
        p[K.P_LINK_C] = 2.0 * damping_ratio * math.sqrt(stiffness * payload_mass)
    p[K.P_CAM_WEAR] = cam_wear
    p[K.P_PLATFORM_LOSS] = platform_loss
    if reentry_edge is not None:
        p[K.P_EDGE_WIDTH] = 2.0 * reentry_edge.length / design.orbit_diameter
        p[K.P_EDGE_DEPTH] = reentry_edge.depth
    if nut_spall is not None:
        p[K.P_SPALL_ANGLE] = nut_spall.angle
        p[K.P_SPALL_WIDTH] = 2.0 * nut_spall.length / design.orbit_diameter
        p[K.P_SPALL_DEPTH] = nut_spall.depth
        p[K.P_SPALL_SHARE] = nut_spall.share
    # roller 1 at the sector's entrance, roller i (i − 1)·2π/N behind it (§3.2 steps 4–6)
    behind = np.arange(n) * 2.0 * math.pi / n
    phi0 = p[K.P_PHI_ENTRY] - behind
    # each roller where its drift has brought it: against the platform's ring at the entrance,
    # one lead from it just after a reset (the far ring then L + p/N − L = p/N away)
    drift = lead * behind / (2.0 * math.pi)
    u0 = drift
    rollers = np.zeros((n, 3))
    rollers[:, K.R_PHI0] = phi0
    # centred in their grooves at the start (eqs. 35–37's assembly): e_s = e_n = 0
    rollers[:, K.R_C_SCREW] = u0 + lead * phi0 / (2.0 * math.pi)
    rollers[:, K.R_C_NUT] = u0 + lead * phi0 / (2.0 * math.pi)
    v0 = lead * screw_speed / (2.0 * math.pi)
    y0 = np.zeros(K.state_size(n))
    y0[1] = v0
    y0[K.y_payload(n) + 1] = v0  # the payload moves with the nut, the linkage unstretched
    y0[K.y_spin(n) :] = speed_ratios(design).roller_spin * screw_speed  # rolling (eq. 27)
    y0[2 : 2 + n] = u0
    y0[2 + n : 2 + 2 * n] = v0 - lead * ratio * screw_speed / (2.0 * math.pi)
    return p, rollers, y0


def right_hand_side(
    design: PRSMDesign,
    *,
    screw_speed: float,
    load: float,
    clearance: float = 5e-6,
    payload_mass: float = 0.0,
    load_ramp: float = LOAD_RAMP,
    contact: ImpactContact = PAPER03_CONTACT,
):
    """(f, y0): the model's right-hand side f(t, y) → dy/dt and its initial state, for any ODE
    solver (the benchmark drives scipy's with it). ``y``: the kernels' state (its layout:
    :mod:`._kernels`); the rolling :func:`simulate_recirculating` sets on the threads after
    each step is not in a right-hand side, so a solver's spins run free."""
    p, rollers, y0 = _parameters(
        design,
        screw_speed,
        load,
        clearance=clearance,
        payload_mass=payload_mass,
        load_ramp=load_ramp,
        contact=contact,
    )
    knots = _load_knots(load, 1.0)
    motion = _motion_knots(screw_speed, 1.0)
    scratch = np.zeros((design.n_rollers, K.ROLLER_SIZE))

    def f(t, y):
        dy = np.empty(len(y0))
        K.forces(t, np.asarray(y, float), p, rollers, knots, motion, scratch, False, dy)
        return dy

    return f, y0
