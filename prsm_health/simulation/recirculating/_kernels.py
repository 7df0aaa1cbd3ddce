"""numba kernels of the recirculating PRSM's axial model: contact forces and a guarded RK4.

Only float64 arrays and scalars cross this boundary; the parameter vector's layout is
:data:`P_*` below, the physics in :mod:`.model` (which documents every term and cites paper 03).

State ``y`` (its layout: :func:`y_work`, :func:`y_payload`, :func:`y_spin`): nut position and
velocity, each roller's absolute axial position and velocity, three energy accumulators (work
of the prescribed screw/carrier motion, dissipated energy, work against the load), so that the
energy balance is integrated by the same steps as the motion, the payload's position and
velocity (behind the linkage, or following the nut rigidly), then each roller's spin (absolute
angular speed about its axis).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

TWO_PI = 2.0 * math.pi

# ---- parameter vector layout
P_N = 0  # rollers
P_LEAD = 1  # lead L [m]
P_PITCH = 2  # thread pitch p [m] (period of the grooves)
P_M_ROLLER = 3
P_M_NUT = 4  # nut, cam rings and payload [kg]
P_K_THREAD = 5  # Hertz constant of one thread side [N/m^1.5]
P_B_SCREW = 6  # half-clearance, screw side [m]
P_B_NUT = 7
P_C_THREAD = 8  # thread damping [N·s/m]
P_D_THREAD = 9  # penetration over which the thread damping switches on [m]
P_K_CAM = 10  # IMPACT (eq. 38) stiffness [N/m^e]
P_E_CAM = 11
P_C_CAM = 12
P_D_CAM = 13
P_ROOM = 14  # axial room of a roller between the two cam rings [m]
P_STROKE = 15  # platform height: the reset stroke [m]
P_BETA = 16  # half the threadless sector's orbital angle [rad]
P_LIFT = 17  # radial lift over the screw thread crest [m]
P_LIFT_RAMP = 18  # orbital angle over which a lift (or the platform's edge) ramps [rad]
P_COT_FLANK = 19  # axial play per radial lift: cos β / sin β of the flank
P_RATIO = 20  # carrier / screw speed
P_PHI_ENTRY = 21  # orbital angle where a roller enters the sector [rad]
P_LOAD_RAMP = 22  # time over which the load rises from 0 [s] (the load: knots + sinusoid)
P_SPALL_ANGLE = 23  # orbital angle where a nut-flank spall starts [rad]
P_SPALL_WIDTH = 24  # its angular extent along the roller's path [rad] (0: no spall)
P_SPALL_DEPTH = 25  # material missing from the nut flank [m]
P_LOAD_SINE = 26  # amplitude of a sinusoid added to the load knots [N]
P_LOAD_FREQUENCY = 27  # its frequency [Hz]
P_SPALL_SHARE = 28  # share of the engaged thread turns the spall is on (1/n_t: one turn)
P_CAM_WEAR = 29  # material worn off the chamfer at its entrance [m], tapering to 0 at its top
P_PLATFORM_LOSS = 30  # height the platform lost [m]: the reset falls short by it
P_EDGE_WIDTH = 31  # orbital extent of the damaged nut thread after the sector's exit [rad]
P_EDGE_DEPTH = 32  # material missing from both nut flanks there [m]
P_LINK_K = 33  # linkage stiffness nut–payload [N/m] (0: the payload rides rigidly on the nut)
P_LINK_C = 34  # linkage damping [N·s/m]
P_M_PAYLOAD = 35  # payload behind the linkage [kg]
P_MU_STATIC = 36  # paper 03 §4.1's Coulomb friction (ADAMS): static coefficient μ_s
P_MU_DYNAMIC = 37  # dynamic coefficient μ_d
P_V_STATIC = 38  # slip speed where μ_s is reached [m/s]
P_V_DYNAMIC = 39  # slip speed from which μ_d holds [m/s]
P_I_ROLLER = 40  # roller's moment of inertia about its axis [kg·m²]
P_SPIN_RATIO = 41  # the rolling roller's spin per screw speed (eq. 27)
P_R_ORBIT = 42  # orbit radius of the roller axes [m]
P_R_FACE = 43  # radial offset of the cam-ring contact from the roller's axis [m]
P_SIZE = 44

# ---- state layout: nut position and velocity, the rollers' positions (n) and velocities (n),
# the drive's work, the dissipated energy, the load's work, the payload's position and velocity,
# the rollers' spins (n)


@njit(cache=True, inline="always")
def y_work(n):
    """Index of the drive's work in the state (+1: the dissipated energy, +2: the load's)."""
    return 2 + 2 * n


@njit(cache=True, inline="always")
def y_payload(n):
    """Index of the payload's position in the state (+1: its velocity)."""
    return 2 + 2 * n + 3


@njit(cache=True, inline="always")
def y_spin(n):
    """Index of the first roller's spin in the state."""
    return 2 + 2 * n + 5


@njit(cache=True, inline="always")
def state_size(n):
    """Length of the state of n rollers."""
    return 3 * n + 7


#: Per-roller arrays (rows of ``rollers``): start orbital angle, screw- and nut-side offsets.
R_PHI0, R_C_SCREW, R_C_NUT = 0, 1, 2

# ---- recorded per sample
OUT_T, OUT_X, OUT_V, OUT_A, OUT_TORQUE, OUT_W_IN, OUT_W_DISS, OUT_W_LOAD, OUT_ENERGY = range(9)
OUT_LOAD = 9
OUT_ROD = 10  # force of the linkage on the nut [N] (the load itself without a linkage)
OUT_XP, OUT_VP = 11, 12  # payload position and velocity
OUT_THETA, OUT_OMEGA = 13, 14  # screw angle [rad] and speed [rad/s]
OUT_SIZE = 15
#: Per roller per sample: relative position to the nut, screw-side and nut-side thread force,
#: cam force (both rings), in the sector (1/0), spin [rad/s].
ROLLER_U, ROLLER_F_SCREW, ROLLER_F_NUT, ROLLER_F_CAM, ROLLER_SECTOR, ROLLER_SPIN = range(6)
ROLLER_SIZE = 6


@njit(cache=True, inline="always")
def _wrap(x, period):
    """x wrapped into [−period/2, period/2)."""
    return x - period * math.floor(x / period + 0.5)


@njit(cache=True, inline="always")
def _step_on(d, depth):
    """ADAMS STEP from 0 at d = 0 to 1 at d = depth (cubic)."""
    u = min(max(d / depth, 0.0), 1.0)
    return u * u * (3.0 - 2.0 * u)


@njit(cache=True, inline="always")
def _sector(p, phi):
    """(angle travelled into the threadless sector a ∈ [0, 2π), in it?)."""
    a = (phi - p[P_PHI_ENTRY]) % TWO_PI
    return a, a < 2.0 * p[P_BETA]


@njit(cache=True, inline="always")
def _trapezoid(a, end, ramp):
    """0 → 1 over [0, ramp], 1, 1 → 0 over [end − ramp, end] (0 outside [0, end]); and d/da."""
    if a <= 0.0 or a >= end:
        return 0.0, 0.0
    if a < ramp:
        return a / ramp, 1.0 / ramp
    if a > end - ramp:
        return (end - a) / ramp, -1.0 / ramp
    return 1.0, 0.0


@njit(cache=True, inline="always")
def _lift_play(p, a, inside):
    """Axial play the lift adds on each thread side, screw and nut alike [m], and d/da: the
    roller is lifted out of both threads across the threadless area (2β), the lift rising and
    falling over a ramp at each end so the threads let go and take the roller back gradually.

    An idealisation of A → A' → A'' (§2.1): lifted over the screw thread's crest during the
    crossing, the roller is held on the platform until the nut thread takes it back; what it
    leaves out is said in :mod:`.model`."""
    if not inside:
        return 0.0, 0.0
    scale = p[P_LIFT] * p[P_COT_FLANK]
    value, slope = _trapezoid(a, 2.0 * p[P_BETA], p[P_LIFT_RAMP])
    return scale * value, scale * slope


@njit(cache=True, inline="always")
def _spall(p, phi):
    """Depth missing from the nut flank under a roller at orbital angle φ [m], and d/dφ: a
    spall of the nut thread at a fixed angle, its edges a tenth of its width wide."""
    width = p[P_SPALL_WIDTH]
    if width <= 0.0:
        return 0.0, 0.0
    along = (phi - p[P_SPALL_ANGLE]) % TWO_PI
    value, slope = _trapezoid(along, width, 0.1 * width)
    return p[P_SPALL_DEPTH] * value, p[P_SPALL_DEPTH] * slope


@njit(cache=True, inline="always")
def _edge(p, a):
    """Depth missing from both nut flanks at the thread's re-entry edge under a roller that has
    travelled a into the sector [m], and d/da: the first stretch of nut thread after the
    threadless area's exit (a = 2β) is worn or chipped, the depth ending over the last tenth
    of the stretch where the intact thread starts."""
    width = p[P_EDGE_WIDTH]
    if width <= 0.0:
        return 0.0, 0.0
    along = a - 2.0 * p[P_BETA]
    if along <= 0.0 or along >= width:
        return 0.0, 0.0
    ramp = 0.1 * width
    if along > width - ramp:
        return p[P_EDGE_DEPTH] * (width - along) / ramp, -p[P_EDGE_DEPTH] / ramp
    return p[P_EDGE_DEPTH], 0.0


@njit(cache=True, inline="always")
def _platform(p, a, inside):
    """Platform surface height above its ring's face [m] and d/da: the chamfer rises by the
    stroke over the crossing (the first β), the platform top holds it, and its exit edge drops
    over the last lift ramp as the threads take the roller back.

    Faults of the ring: chamfer wear removes w at the chamfer's entrance, tapering to nothing at
    its top (where the rollers strike it: the surface is max(0, (stroke + w)·a/β − w), met later
    and climbed faster); a platform that lost height h tops out at stroke − h (the reset falls
    short of one lead by h and the nut thread must push the landing roller the rest)."""
    if not inside:
        return 0.0, 0.0
    beta, ramp, stroke = p[P_BETA], p[P_LIFT_RAMP], p[P_STROKE]
    wear, top = p[P_CAM_WEAR], p[P_STROKE] - p[P_PLATFORM_LOSS]
    if a < beta:
        rise = (stroke + wear) * a / beta - wear
        if rise <= 0.0:
            return 0.0, 0.0
        if rise >= top:
            return top, 0.0
        return rise, (stroke + wear) / beta
    if a > 2.0 * beta - ramp:
        return top * (2.0 * beta - a) / ramp, -top / ramp
    return top, 0.0


@njit(cache=True, inline="always")
def _screw(t, motion):
    """Screw angle [rad] and speed [rad/s] at t from the motion's knots (rows: times [s],
    speeds [rad/s], angles [rad] at the knots): the speed linear between knots, the angle its
    exact integral; held at the last speed beyond the last knot."""
    times = motion[0]
    k = np.searchsorted(times, t, side="right") - 1
    k = min(max(k, 0), len(times) - 1)
    tau = t - times[k]
    if k == len(times) - 1:
        return motion[2, k] + motion[1, k] * tau, motion[1, k]
    slope = (motion[1, k + 1] - motion[1, k]) / (times[k + 1] - times[k])
    return motion[2, k] + motion[1, k] * tau + 0.5 * slope * tau * tau, motion[1, k] + slope * tau


@njit(cache=True, inline="always")
def _load(t, p, knots):
    """Axial load on the nut at t [N], resisting forward motion when positive: the profile's
    knots plus its sinusoid, brought in over the load ramp."""
    value = np.interp(t, knots[0], knots[1])
    value += p[P_LOAD_SINE] * math.sin(TWO_PI * p[P_LOAD_FREQUENCY] * t)
    if p[P_LOAD_RAMP] > 0.0 and t < p[P_LOAD_RAMP]:
        value *= t / p[P_LOAD_RAMP]
    return value


@njit(cache=True, inline="always")
def _rod(y, p, ip):
    """Force of the linkage on the nut [N], positive resisting forward motion: spring and
    damper between the nut (y[0], y[1]) and the payload (y[ip], y[ip + 1])."""
    return p[P_LINK_K] * (y[0] - y[ip]) + p[P_LINK_C] * (y[1] - y[ip + 1])


@njit(cache=True, inline="always")
def _coulomb(slip, p):
    """Friction coefficient against a slip speed [m/s], signed as the slip: ADAMS's Coulomb law
    as paper 03 §4.1 sets it — a cubic STEP from −μ_s to μ_s across ±v_s, then from μ_s to
    μ_d between v_s and v_d, μ_d beyond."""
    speed = abs(slip)
    v_s, v_d = p[P_V_STATIC], p[P_V_DYNAMIC]
    if speed < v_s:
        return p[P_MU_STATIC] * (2.0 * _step_on(slip + v_s, 2.0 * v_s) - 1.0)
    mu = p[P_MU_DYNAMIC]
    if speed < v_d:
        mu = p[P_MU_STATIC] + (p[P_MU_DYNAMIC] - p[P_MU_STATIC]) * _step_on(speed - v_s, v_d - v_s)
    return mu if slip > 0.0 else -mu


@njit(cache=True, inline="always")
def _impact(d, d_dot, kin_unit, p):
    """One cam-ring contact penetrated by d [m] (≤ 0: apart) at rate d_dot, kin_unit·ω_s of it
    from the prescribed motion: paper 03's IMPACT law (eq. 38), returned as :func:`_hertz`."""
    if d <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    elastic = p[P_K_CAM] * d ** p[P_E_CAM]
    damping = p[P_C_CAM] * _step_on(d, p[P_D_CAM])
    force = max(elastic + damping * d_dot, 0.0)
    k_eff = p[P_E_CAM] * p[P_K_CAM] * d ** (p[P_E_CAM] - 1.0)
    rate = max(math.sqrt(k_eff / p[P_M_ROLLER]), damping / p[P_M_ROLLER])
    return force, force * kin_unit, (force - elastic) * d_dot, rate


@njit(cache=True, inline="always")
def _hertz(d, d_dot, kin_unit, p):
    """One thread side penetrated by d [m] (≤ 0: apart) at rate d_dot, kin_unit·ω_s of it
    from the prescribed motion (kin_unit [m/rad]): (force [N], its torque on the screw's
    prescribed motion force·kin_unit [N·m], dissipated power [W], the contact's rate [1/s] for
    the step guard)."""
    if d <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    elastic = p[P_K_THREAD] * d**1.5
    force = max(elastic + p[P_C_THREAD] * _step_on(d, p[P_D_THREAD]) * d_dot, 0.0)
    k_eff = 1.5 * p[P_K_THREAD] * math.sqrt(d)
    rate = max(math.sqrt(k_eff / p[P_M_ROLLER]), p[P_C_THREAD] / p[P_M_ROLLER])
    return force, force * kin_unit, (force - elastic) * d_dot, rate


@njit(cache=True)
def forces(t, y, p, rollers, knots, motion, roller_out, with_out, dy):
    """The state's rates into ``dy`` (every entry written: the caller owns it, no allocation
    on the hot path); returns the largest contact rate [1/s] and the torque the prescribed
    screw (and, rolling, carrier) motion takes [N·m].

    Every prescribed rate is ω_s times a geometric factor (the carrier turns at ratio·ω_s),
    so the torque is Σ force × factor and the power it puts in torque × ω_s — defined at rest.
    ``roller_out`` (rollers × ROLLER_SIZE) filled when ``with_out``.
    """
    n = int(p[P_N])
    lead, pitch = p[P_LEAD], p[P_PITCH]
    m_r, m_n = p[P_M_ROLLER], p[P_M_NUT]
    ratio = p[P_RATIO]
    theta, omega = _screw(t, motion)
    a_dot_unit = abs(ratio)  # the sector angle grows at the carrier's speed (forward)
    x, v = y[0], y[1]
    f_nut = 0.0
    torque = 0.0
    p_diss = 0.0
    rate = 0.0
    for i in range(n):
        z, w = y[2 + i], y[2 + n + i]
        phi = rollers[i, R_PHI0] + ratio * theta
        a, inside = _sector(p, phi)
        play, dplay = _lift_play(p, a, inside)
        pit, dpit = _spall(p, phi)
        f_roller = 0.0
        f_screw = 0.0
        edge, dedge = _edge(p, a)
        # ---- thread contacts: screw side, nut side (dead-zone Hertz, damped)
        f_side = 0.0
        for side in range(2):
            if side == 0:
                e = _wrap(z - lead * (theta - phi) / TWO_PI - rollers[i, R_C_SCREW], pitch)
                e_dot_free = w  # the part from the state
                e_kin_unit = -lead * (1.0 - ratio) / TWO_PI  # per ω_s, the prescribed motion's
                b = p[P_B_SCREW] + play
                play_unit = dplay * a_dot_unit
            else:
                e = _wrap(z - x + lead * phi / TWO_PI - rollers[i, R_C_NUT], pitch)
                e_dot_free = w - v
                e_kin_unit = lead * ratio / TWO_PI
                b = p[P_B_NUT] + play + edge
                play_unit = (dplay + dedge) * a_dot_unit
            sign = 1.0 if e >= 0.0 else -1.0
            d = abs(e) - b
            kin_unit = sign * e_kin_unit - play_unit
            d_dot = sign * e_dot_free + omega * kin_unit
            force, torque_part, power_diss, contact_rate = _hertz(d, d_dot, kin_unit, p)
            if side == 1 and e >= 0.0 and pit > 0.0:
                # the spalled turn (share s of the engaged ones, the flank that carries the
                # load) closes the pit's depth later; the other turns as before
                share = p[P_SPALL_SHARE]
                pit_unit = dpit * ratio
                f2, torque2, diss2, _r = _hertz(
                    d - pit, d_dot - omega * pit_unit, kin_unit - pit_unit, p
                )
                force = (1.0 - share) * force + share * f2
                torque_part = (1.0 - share) * torque_part + share * torque2
                power_diss = (1.0 - share) * power_diss + share * diss2
            torque += torque_part
            p_diss += power_diss
            rate = max(rate, contact_rate)
            f_roller -= sign * force
            if side == 1:
                f_nut += sign * force
                f_side = -sign * force
            else:
                f_screw = -sign * force
        # ---- cam rings: the left ring's face at u = 0 with its platform (forward rotation's),
        # the right ring's face at u = room
        u, u_dot = z - x, w - v
        rise, drise_da = _platform(p, a, inside)
        f_cam = 0.0
        cam_normal = 0.0
        for ring in range(2):
            if ring == 0:
                d = rise - u
                kin_unit = drise_da * a_dot_unit  # the platform's rate per ω_s
                push = 1.0
            else:
                d = u - p[P_ROOM]
                kin_unit = 0.0
                push = -1.0
            d_dot = omega * kin_unit - push * u_dot
            force, torque_part, power_diss, contact_rate = _impact(d, d_dot, kin_unit, p)
            torque += torque_part
            p_diss += power_diss
            rate = max(rate, contact_rate)
            f_cam += push * force
            cam_normal += force
        # ---- the roller's spin while it is out of the threads: the cam rings' friction turns
        # it (paper 03 §4.1's law at the contact's offset from the roller's axis); its force
        # is tangential — no axial effect —, its power from the prescribed carrier in the
        # torque, what it slips in the dissipation, the spin's own in its kinetic energy. On
        # the threads, rolling holds it (:func:`integrate` sets it to eq. 27's).
        spin = y[y_spin(n) + i]
        slip = ratio * omega * p[P_R_ORBIT] + spin * p[P_R_FACE]  # the ring does not turn
        f = -_coulomb(slip, p) * cam_normal
        spin_torque = p[P_R_FACE] * f
        p_diss -= f * slip
        torque -= f * ratio * p[P_R_ORBIT]
        dy[y_spin(n) + i] = spin_torque / p[P_I_ROLLER]
        f_roller += f_cam
        f_nut -= f_cam
        dy[2 + i] = w
        dy[2 + n + i] = f_roller / m_r
        if with_out:
            roller_out[i, ROLLER_U] = u
            roller_out[i, ROLLER_F_SCREW] = f_screw
            roller_out[i, ROLLER_F_NUT] = f_side
            roller_out[i, ROLLER_F_CAM] = f_cam
            roller_out[i, ROLLER_SECTOR] = 1.0 if inside else 0.0
            roller_out[i, ROLLER_SPIN] = spin
    load = _load(t, p, knots)
    ip = y_payload(n)
    iw = y_work(n)
    dy[0] = v
    if p[P_LINK_K] > 0.0:  # the load acts on the payload, the linkage on the nut
        relative = v - y[ip + 1]
        f_rod = _rod(y, p, ip)
        p_diss += p[P_LINK_C] * relative * relative
        dy[1] = (f_nut - f_rod) / m_n
        dy[ip] = y[ip + 1]
        dy[ip + 1] = (f_rod - load) / p[P_M_PAYLOAD]
        dy[iw + 2] = load * y[ip + 1]
        rate = max(rate, math.sqrt(p[P_LINK_K] / m_n), p[P_LINK_C] / m_n)
    else:  # the payload (in the nut's mass) follows the nut
        dy[1] = (f_nut - load) / m_n
        dy[ip] = v
        dy[ip + 1] = dy[1]
        dy[iw + 2] = load * v
    dy[iw] = torque * omega
    dy[iw + 1] = p_diss
    return rate, torque


@njit(cache=True)
def mechanical_energy(t, y, p, rollers, motion):
    """Kinetic energy of nut, rollers and payload plus the contacts' elastic energy [J]."""
    n = int(p[P_N])
    lead, pitch = p[P_LEAD], p[P_PITCH]
    ratio = p[P_RATIO]
    theta = _screw(t, motion)[0]
    x = y[0]
    energy = 0.5 * p[P_M_NUT] * y[1] ** 2
    if p[P_LINK_K] > 0.0:
        ip = y_payload(n)
        energy += 0.5 * p[P_M_PAYLOAD] * y[ip + 1] ** 2 + 0.5 * p[P_LINK_K] * (x - y[ip]) ** 2
    for i in range(n):
        z, w = y[2 + i], y[2 + n + i]
        energy += 0.5 * p[P_I_ROLLER] * y[y_spin(n) + i] ** 2
        energy += 0.5 * p[P_M_ROLLER] * w**2
        phi = rollers[i, R_PHI0] + ratio * theta
        a, inside = _sector(p, phi)
        play = _lift_play(p, a, inside)[0]
        pit = _spall(p, phi)[0]
        e_s = _wrap(z - lead * (theta - phi) / TWO_PI - rollers[i, R_C_SCREW], pitch)
        e_n = _wrap(z - x + lead * phi / TWO_PI - rollers[i, R_C_NUT], pitch)
        d_s = abs(e_s) - p[P_B_SCREW] - play
        d_n = abs(e_n) - p[P_B_NUT] - play - _edge(p, a)[0]
        energy += 0.4 * p[P_K_THREAD] * max(d_s, 0.0) ** 2.5
        if e_n >= 0.0 and pit > 0.0:  # the spalled turn's share closes later
            share = p[P_SPALL_SHARE]
            energy += 0.4 * p[P_K_THREAD] * (1.0 - share) * max(d_n, 0.0) ** 2.5
            energy += 0.4 * p[P_K_THREAD] * share * max(d_n - pit, 0.0) ** 2.5
        else:
            energy += 0.4 * p[P_K_THREAD] * max(d_n, 0.0) ** 2.5
        u = z - x
        rise, _ = _platform(p, a, inside)
        for d in (rise - u, u - p[P_ROOM]):
            if d > 0.0:
                energy += p[P_K_CAM] * d ** (p[P_E_CAM] + 1.0) / (p[P_E_CAM] + 1.0)
    return energy


@njit(cache=True)
def _roll(t, y, p, motion, rollers_then, step):
    """Rolling holds the spin of a roller on its threads at eq. (27)'s: each roller that had a
    thread force at the step's start is set to it at its end — the slip a landing roller makes
    until the threads' friction has turned it, shorter than a step (paper 03's μ_s = 0.3 on a
    1.7 kN share spins a 3.5 g roller up in microseconds), in one jump: the drive does
    I·Ω_k·ΔΩ of work, ½·I·ΔΩ² slips away (the friction between a prescribed surface and a free
    rotor until they roll). Returns the drive's torque for that work over the step [N·m]."""
    n = int(p[P_N])
    base, iw = y_spin(n), y_work(n)
    omega = _screw(t, motion)[1]
    rolling = p[P_SPIN_RATIO] * omega
    work = 0.0
    for i in range(n):
        if rollers_then[i, ROLLER_F_SCREW] == 0.0 and rollers_then[i, ROLLER_F_NUT] == 0.0:
            continue
        jump = rolling - y[base + i]
        work += p[P_I_ROLLER] * rolling * jump
        y[iw] += p[P_I_ROLLER] * rolling * jump
        y[iw + 1] += 0.5 * p[P_I_ROLLER] * jump * jump
        y[base + i] = rolling
    return work / (omega * step) if omega > 0.0 else 0.0


@njit(cache=True)
def integrate(y0, p, rollers, knots, motion, step, n_steps, max_substeps, out, roller_out):
    """Fixed outer steps of RK4, each cut into as many equal sub-steps as the stiffest active
    contact needs (rate × sub-step ≤ 0.5, from the penetration expected at the step's end);
    records every outer step. Returns the number of steps done (< n_steps: the guard's limit
    was reached at that step)."""
    n = int(p[P_N])
    size = state_size(n)
    iw, ip = y_work(n), y_payload(n)
    y = y0.copy()
    k1 = np.zeros(size)
    tmp = np.zeros(size)
    dy = np.zeros(size)  # the rates where the step starts (recorded, the first sub-step's)
    stage = np.zeros(size)  # a stage's rates, used as soon as computed
    scratch = roller_out[0].copy()
    t = 0.0
    pending = 0.0  # the torque of the last step's spin-ups [N·m]
    for k in range(n_steps):
        rate, torque = forces(t, y, p, rollers, knots, motion, roller_out[k], True, dy)
        out[k, OUT_T] = t
        out[k, OUT_X] = y[0]
        out[k, OUT_V] = y[1]
        out[k, OUT_A] = dy[1]
        out[k, OUT_TORQUE] = torque + pending
        out[k, OUT_W_IN] = y[iw]
        out[k, OUT_W_DISS] = y[iw + 1]
        out[k, OUT_W_LOAD] = y[iw + 2]
        out[k, OUT_ENERGY] = mechanical_energy(t, y, p, rollers, motion)
        out[k, OUT_THETA], out[k, OUT_OMEGA] = _screw(t, motion)
        out[k, OUT_LOAD] = _load(t, p, knots)
        out[k, OUT_ROD] = _rod(y, p, ip) if p[P_LINK_K] > 0.0 else out[k, OUT_LOAD]
        out[k, OUT_XP] = y[ip]
        out[k, OUT_VP] = y[ip + 1]
        # look ahead one step with an Euler predictor: an impact starting inside the step
        for j in range(size):
            tmp[j] = y[j] + step * dy[j]
        rate_end = forces(t + step, tmp, p, rollers, knots, motion, scratch, False, stage)[0]
        rate = max(rate, rate_end)
        subs = max(1, int(math.ceil(rate * step / 0.5)))
        if subs > max_substeps:
            return k
        h = step / subs
        for sub in range(subs):
            # the first sub-step starts where the recorded forces were taken: reuse them
            d1 = dy
            if sub > 0:
                forces(t, y, p, rollers, knots, motion, scratch, False, stage)
                d1 = stage
            for j in range(size):
                k1[j] = d1[j]
                tmp[j] = y[j] + 0.5 * h * d1[j]
            forces(t + 0.5 * h, tmp, p, rollers, knots, motion, scratch, False, stage)
            for j in range(size):
                k1[j] += 2.0 * stage[j]
                tmp[j] = y[j] + 0.5 * h * stage[j]
            forces(t + 0.5 * h, tmp, p, rollers, knots, motion, scratch, False, stage)
            for j in range(size):
                k1[j] += 2.0 * stage[j]
                tmp[j] = y[j] + h * stage[j]
            forces(t + h, tmp, p, rollers, knots, motion, scratch, False, stage)
            for j in range(size):
                y[j] += h * (k1[j] + stage[j]) / 6.0
            t += h
        # the step ends where it should, whatever rounding the sub-steps left
        t = (k + 1) * step
        pending = _roll(t, y, p, motion, roller_out[k], step)
    return n_steps
