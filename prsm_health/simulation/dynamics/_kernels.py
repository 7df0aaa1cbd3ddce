"""numba kernels of the PRSM lumped-parameter model: right-hand side and fixed-step RK4.

Only float64 arrays and scalars cross this boundary; the layout of every array is in
:mod:`.layout` (read as ``L.NAME``: numba folds module constants at compile time), its physics
in :mod:`.model` (which documents every term and cites its sources).

Force laws derive from one energy function (docs/validation.md, paper 01 dynamics): each
thread engagement has an axial closure with the helix built in and a radial closure coupled
through cot β, contact on either flank beyond a per-roller half-clearance b; the gear mesh has a
time-varying stiffness looked up in a table over one mesh cycle. Geometric errors of screw, nut
and gear enter the closures as functions of where each roller touches them, with their slopes
in the generalised forces, so they do work exactly as the energy says. Roller centres are
absolute positions, so the carrier pocket springs supply the centripetal force (no separate
centrifugal term, which would double count).
"""

from __future__ import annotations

import math

from numba import njit

from . import layout as L

TWO_PI = 2.0 * math.pi
INV_TWO_PI = 1.0 / TWO_PI  # the roller loop multiplies (IEEE: a division stays one)
#: LLVM fast-math flags of every kernel: none (IEEE arithmetic). With them (reciprocals, fused
#: multiply-adds, reassociation) the kernel was ≈ 10 % faster, but a process that loaded
#: `integrate` from numba's cache and compiled `rhs` itself (the linearisation calls it) ran
#: other bits than one that compiled or loaded both (seen on Haswell code, 3 fresh-cache test runs
#: in 9): runs of one recipe differed between processes, and these runs amplify a last-bit
#: difference to percent. IEEE arithmetic is the same whatever the compiler inlines or fuses.
#: tests/simulation/dynamics/test_kernel_cache_mix.py holds it.
FAST = False


@njit(cache=True, inline="always", fastmath=FAST)
def _segment(knots, t):
    # The k with knots[0, k] <= t < knots[0, k + 1], for knots[0, 0] <= t < knots[0, −1]: by
    # bisection (a duty of minutes has thousands of knots; a scan from the first cost a 30 s
    # profile's steps 26 %).
    lo, hi = 0, knots.shape[1] - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if knots[0, mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always", fastmath=FAST)
def screw_motion(t, motion):
    """Prescribed screw angle, speed and acceleration from piecewise-linear speed knots.

    ``motion`` rows: knot times [s], speeds [rad/s], angles at the knots [rad].
    """
    n = motion.shape[1]
    if t < motion[0, 0]:  # settling before the run: hold the initial speed
        return motion[2, 0] + motion[1, 0] * (t - motion[0, 0]), motion[1, 0], 0.0
    if t >= motion[0, n - 1]:
        w = motion[1, n - 1]
        return motion[2, n - 1] + w * (t - motion[0, n - 1]), w, 0.0
    k = _segment(motion, t)
    dt = t - motion[0, k]
    slope = (motion[1, k + 1] - motion[1, k]) / (motion[0, k + 1] - motion[0, k])
    return (
        motion[2, k] + motion[1, k] * dt + 0.5 * slope * dt * dt,
        motion[1, k] + slope * dt,
        slope,
    )


@njit(cache=True, inline="always", fastmath=FAST)
def axial_load(t, load_knots, amp, freq):
    """Resisting axial load [N] at time t: piecewise-linear knots plus a sinusoid."""
    n = load_knots.shape[1]
    if t <= load_knots[0, 0]:
        base = load_knots[1, 0]
    elif t >= load_knots[0, n - 1]:
        base = load_knots[1, n - 1]
    else:
        k = _segment(load_knots, t)
        w = (t - load_knots[0, k]) / (load_knots[0, k + 1] - load_knots[0, k])
        base = load_knots[1, k] + w * (load_knots[1, k + 1] - load_knots[1, k])
    if amp == 0.0:  # most profiles: no libm call per right-hand side (same bits)
        return base
    return base + amp * math.sin(TWO_PI * freq * t)


@njit(cache=True, inline="always", fastmath=FAST)
def _tanh(x):
    # tanh as a Padé [7/6] rational, ±1 beyond |x| = 4.97 where it reaches 1 (error ≤ 1e-4 there,
    # ≤ 1e-6 below |x| = 3): a smoothed sign, where libm's tanh was 9 % of a right-hand side.
    if x >= 4.97:
        return 1.0
    if x <= -4.97:
        return -1.0
    x2 = x * x
    numerator = x * (135135.0 + x2 * (17325.0 + x2 * (378.0 + x2)))
    return numerator / (135135.0 + x2 * (62370.0 + x2 * (3150.0 + 28.0 * x2)))


@njit(cache=True, inline="always", fastmath=FAST)
def _spring(closure, k, exponent):
    # Elastic part of a flank force: linear or Hertzian F = k·x^1.5.
    if closure <= 0.0:
        return 0.0
    if exponent == 1.0:
        return k * closure
    return k * closure * math.sqrt(closure)


@njit(cache=True, inline="always", fastmath=FAST)
def _flank(closure, rate, k, c, exponent):
    # Returns (contact force ≥ 0, dissipated power). A contact cannot pull: when the damper
    # would make the force negative it is clipped to 0, and the stored energy it releases
    # counts as dissipated, so the energy book stays exact.
    if closure <= 0.0:
        return 0.0, 0.0
    spring = _spring(closure, k, exponent)
    force = spring + c * rate
    if force < 0.0:
        force = 0.0
    return force, (force - spring) * rate


@njit(cache=True, inline="always", fastmath=FAST)
def _roller_frame(xr, yr, vxr, vyr, xb, yb, vxb, vyb, c, s, w_p):
    # Roller centre relative to a body centre in the pocket frame (e_r, e_t): radial and
    # tangential offsets and their rates (the frame turns with the carrier at w_p).
    dx, dy = xr - xb, yr - yb
    dvx, dvy = vxr - vxb, vyr - vyb
    rho = dx * c + dy * s
    tau = -dx * s + dy * c
    return rho, tau, dvx * c + dvy * s + tau * w_p, -dvx * s + dvy * c - rho * w_p


@njit(cache=True, inline="always", fastmath=FAST)
def _thread_pair(d_ax, d_ax_dot, approach, approach_dot, clearance, cot_b, k, c, expo):
    # Both flanks of one thread engagement: closure ±δ_axial + cot β·approach beyond the
    # half-clearance. Returns (plus-flank force, minus-flank force, dissipated power).
    f_plus, d1 = _flank(
        d_ax + cot_b * approach - clearance, d_ax_dot + cot_b * approach_dot, k, c, expo
    )
    f_minus, d2 = _flank(
        -d_ax + cot_b * approach - clearance, -d_ax_dot + cot_b * approach_dot, k, c, expo
    )
    return f_plus, f_minus, d1 + d2


@njit(cache=True, inline="always", fastmath=FAST)
def _pitted_flank(closure, rate, depth, depth_rate, share, k, c, exponent):
    # One flank of an engagement whose thread turns are sound but one, which has a depression
    # `depth` at the contact: the share `share` of the turns closes `depth` less. Returns the
    # total force, the pitted turn's force (its slope term), and the dissipated power.
    sound, d1 = _flank(closure, rate, k, c, exponent)
    pit, d2 = _flank(closure - depth, rate - depth_rate, k, c, exponent)
    return (1.0 - share) * sound + share * pit, share * pit, (1.0 - share) * d1 + share * d2


@njit(cache=True, inline="always", fastmath=FAST)
def _pitted_pair(d_ax, d_ax_dot, approach, approach_dot, clearance, cot_b, k, c, expo, spall):
    # _thread_pair with a depression on one thread turn; spall = (share, depth and its rate on
    # the plus flank, on the minus flank). Returns forces, pitted-turn forces, dissipation.
    share, d_plus, r_plus, d_minus, r_minus = spall
    f_plus, pit_plus, d1 = _pitted_flank(
        d_ax + cot_b * approach - clearance,
        d_ax_dot + cot_b * approach_dot,
        d_plus,
        r_plus,
        share,
        k,
        c,
        expo,
    )
    f_minus, pit_minus, d2 = _pitted_flank(
        -d_ax + cot_b * approach - clearance,
        -d_ax_dot + cot_b * approach_dot,
        d_minus,
        r_minus,
        share,
        k,
        c,
        expo,
    )
    return f_plus, f_minus, d1 + d2, pit_plus, pit_minus


@njit(cache=True, inline="always", fastmath=FAST)
def _gate(x, half, ramp):
    # 1 while |x| ≤ half − ramp/2, falling linearly to 0 at half + ramp/2: (value, slope).
    a = abs(x)
    if a <= half - 0.5 * ramp:
        return 1.0, 0.0
    if a >= half + 0.5 * ramp:
        return 0.0, 0.0
    slope = -1.0 / ramp if x > 0.0 else 1.0 / ramp
    return 1.0 - (a - half + 0.5 * ramp) / ramp, slope


@njit(cache=True, inline="always", fastmath=FAST)
def _periodic(x, n):
    # Linear interpolation at x table intervals into a periodic table of n points, n a power of
    # two (layout.N_ERROR_POINTS, MESH_POINTS): (index, next index, weight of the next). The index
    # wraps by a bit mask: a wrap by the floor of the period and bounds tests cost the kernel 9 %.
    floor = math.floor(x)
    i0 = int(floor) & (n - 1)
    return i0, (i0 + 1) & (n - 1), x - floor


@njit(cache=True, inline="always", fastmath=FAST)
def _mesh_stiffness(table, phase):
    # The mesh stiffness at ``phase`` [cycles], the table spanning one mesh cycle.
    n = table.shape[0]
    i0, i1, w = _periodic(phase * n, n)
    a = table[i0]
    return a + (table[i1] - a) * w


@njit(cache=True, inline="always", fastmath=FAST)
def _wave(errors, kind, u):
    # Error profile of one kind at contact coordinate u, linearly interpolated in its table:
    # (value [m], slope d/du [m/rad]).
    n = errors.shape[1] - 1
    i0, i1, w = _periodic(u * errors[kind, 0] * n, n)  # column 0: 1/period
    a, b = errors[kind, 1 + i0], errors[kind, 1 + i1]
    return a + (b - a) * w, (b - a) * (n * errors[kind, 0])


@njit(cache=True, inline="always", fastmath=FAST)
def _clamped(errors, kind, x):
    # A non-periodic table of x ≥ 0 from 0 to errors[kind, 0], linearly interpolated, its last
    # value beyond the end.
    n = errors.shape[1] - 2
    pos = x * errors[kind, 0] * n  # column 0: 1/range
    if pos >= n:
        return errors[kind, 1 + n]
    i0 = int(pos)
    a = errors[kind, 1 + i0]
    return a + (errors[kind, 2 + i0] - a) * (pos - i0)


@njit(cache=True, inline="always", fastmath=FAST)
def _traction(slip, v, cap, k, c, decay):
    # One rolling contact's tangential traction: the elastic displacement `slip` of a Mindlin
    # stiffness k sticks up to the Coulomb limit `cap` and slides beyond it (reset integrator,
    # Haessig & Friedland 1991); while it sticks, rolling carries the strained material out of
    # the contact, so the displacement relaxes at `decay` = rolling speed / relaxation length
    # (steady creep ξ then gives Kalker's linear creep force k·L·ξ). Returns the force on the
    # roller, d(slip)/dt and the dissipated power (friction work less the stored energy's rate).
    if cap <= 0.0:  # no normal load, no traction (the clamp resets the displacement)
        return 0.0, 0.0, 0.0
    f_stick = k * slip
    if f_stick > cap or f_stick < -cap:
        f = cap if f_stick > 0.0 else -cap
        if f_stick * v < 0.0:  # unloading back into stick
            rate = v - decay * slip
            return f, rate, f * v - f_stick * rate
        return f, 0.0, f * v
    return f_stick + c * v, v - decay * slip, c * v * v + f_stick * decay * slip


@njit(cache=True, fastmath=FAST)
def rhs(t, y, p, rollers, mesh_table, motion, load_knots, errors, dy, aux):
    """dy/dt of the full state at time t; auxiliary outputs (torques, powers) into ``aux``.

    Allocation-free: writes into ``dy`` and ``aux`` only.
    """
    n_rollers = rollers.shape[0]
    nq = L.Q_ROLLER0 + L.ROLLER_DOF * n_rollers
    v0 = nq  # offset of velocities; generalised forces are accumulated at dy[v0 + j]
    for j in range(2 * nq + L.N_EXTRA + L.N_TRACTION * n_rollers):
        dy[j] = 0.0
    for j in range(nq):
        dy[j] = y[v0 + j]

    mode = p[L.P_DRIVE_MODE]
    prescribed = mode == L.DRIVE_PRESCRIBED
    coupled = p[L.P_COUPLED] == 1.0
    axial_free = p[L.P_AXIAL_FREE] == 1.0
    on_payload = p[L.P_ON_PAYLOAD] == 1.0
    geared = p[L.P_GEARED] == 1.0
    ratio = p[L.P_RATIO]
    th_ref, w_ref, alpha_ref = screw_motion(t, motion)
    if geared:  # the motion knots are the screw's: the motor turns N times as far
        th_ref, w_ref, alpha_ref = ratio * th_ref, ratio * w_ref, ratio * alpha_ref
    if prescribed:
        th_m, w_m = th_ref, w_ref
        dy[L.Q_THM] = w_ref
    else:
        th_m, w_m = y[L.Q_THM], y[v0 + L.Q_THM]
    if coupled:
        th_s, w_s = y[L.Q_THS], y[v0 + L.Q_THS]
    elif geared:  # screw rigid on the output of a rigid reduction
        th_s, w_s = th_m / ratio, w_m / ratio
        dy[L.Q_THS] = w_s
    else:  # screw rigid on the motor shaft
        th_s, w_s = th_m, w_m
        dy[L.Q_THS] = w_m

    x_s, y_s, z_s = y[L.Q_XS], y[L.Q_YS], y[L.Q_ZS]
    vx_s, vy_s, vz_s = y[v0 + L.Q_XS], y[v0 + L.Q_YS], y[v0 + L.Q_ZS]
    x_n, y_n, th_n, z_n = y[L.Q_XN], y[L.Q_YN], y[L.Q_THN], y[L.Q_ZN]
    vx_n, vy_n, w_n, vz_n = y[v0 + L.Q_XN], y[v0 + L.Q_YN], y[v0 + L.Q_THN], y[v0 + L.Q_ZN]
    x_p, y_p, th_p = y[L.Q_XP], y[L.Q_YP], y[L.Q_THP]
    vx_p, vy_p, w_p = y[v0 + L.Q_XP], y[v0 + L.Q_YP], y[v0 + L.Q_THP]

    orbit = p[L.P_ORBIT_R]
    cot_b = p[L.P_COT_BETA]
    sin_b = p[L.P_SIN_BETA]
    lead_s, lead_r, lead_n = p[L.P_LEAD_S], p[L.P_LEAD_R], p[L.P_LEAD_N]
    rb_ring, rb_roller = p[L.P_RB_RING], p[L.P_RB_ROLLER]
    cos_a0, sin_a0 = p[L.P_COS_A0], p[L.P_SIN_A0]
    r_s, r_n = p[L.P_R_SCREW], p[L.P_R_NUT]
    k_ts, k_tn = p[L.P_K_THREAD_S], p[L.P_K_THREAD_N]
    c_ts, c_tn, c_mesh = p[L.P_C_THREAD_S], p[L.P_C_THREAD_N], p[L.P_C_MESH]
    expo = p[L.P_EXPONENT]
    k_cp, c_cp = p[L.P_K_CP], p[L.P_C_CP]
    fscale = p[L.P_FRICTION_SCALE]
    mu_c, mu_v = p[L.P_MU_COUL] * fscale, p[L.P_MU_VISC] * fscale
    k_tan, c_tan = p[L.P_K_TAN], p[L.P_C_TAN]
    mu_r = p[L.P_MU_ROLL] * fscale
    v_axial, w_roll, lead_eff = p[L.P_V_AXIAL], p[L.P_W_ROLL], p[L.P_LEAD_EFF]
    g1 = 1.0 - p[L.P_LEAD_SLOPE]  # cumulative lead error: axial closure per axial travel
    spalled = p[L.P_HAS_SPALLS] == 1.0
    toothed = p[L.P_HAS_TOOTH_DAMAGE] == 1.0
    stribeck = p[L.P_STRIBECK] == 1.0
    s0 = 2 * nq + L.N_EXTRA  # offset of the traction states (screw side, then nut side)
    a0 = L.N_AUX  # offset of the per-roller auxiliary blocks
    z_ring = p[L.P_Z_RING]

    cos_p = math.cos(th_p)
    sin_p = math.sin(th_p)
    # Reciprocals once per call: IEEE arithmetic forbids the compiler to turn the loop's
    # 18 divisions per roller into products (a division costs ≈ 8 products).
    inv_orbit, inv_sin_b = 1.0 / orbit, 1.0 / sin_b
    inv_v_axial, inv_w_roll = 1.0 / v_axial, 1.0 / w_roll

    torque_screw = 0.0  # contact torque acting on the screw [N·m]
    force_screw_axial = 0.0  # contact force on the screw along z [N]
    friction_torque = 0.0  # friction part of the screw torque, paper 02's reduction [N·m]
    p_diss = 0.0
    p_fric = 0.0
    engaged = 0.0  # rollers in contact with both screw and nut (load path closed)

    for i in range(n_rollers):
        b = L.Q_ROLLER0 + L.ROLLER_DOF * i
        xr, yr, th_c, z_c = y[b], y[b + 1], y[b + 2], y[b + 3]
        vxr, vyr, w_c, vz_c = y[v0 + b], y[v0 + b + 1], y[v0 + b + 2], y[v0 + b + 3]
        cps, sps = rollers[i, L.R_COS_PSI], rollers[i, L.R_SIN_PSI]
        c = cos_p * cps - sin_p * sps  # e_r of the pocket (rotation by angle addition)
        s = sin_p * cps + cos_p * sps
        # Deformations are measured from the assembled position (each roller's threads and
        # teeth are assembled in phase at its pocket), so the revolution angle enters as θ_p;
        # the pocket angle ψ_i sets the mesh phase and where the roller touches screw and nut.
        psi = rollers[i, L.R_PSI]
        phi = th_p + psi
        # Roller thread runout ε about its spin axis, at spin angle χ = θ_c − θ_rev: the flank
        # facing the screw recedes by ε·cos χ, the one facing the nut advances by as much.
        runout = rollers[i, L.R_RUNOUT]

        # ---------------- screw–roller thread
        rho, tau, rho_dot, tau_dot = _roller_frame(
            xr, yr, vxr, vyr, x_s, y_s, vx_s, vy_s, c, s, w_p
        )
        th_rev = th_p + tau * inv_orbit
        w_rev = w_p + tau_dot * inv_orbit
        u = th_rev + psi - th_s
        e_ax, de_ax = _wave(errors, L.ERR_SCREW_AXIAL, u)
        e_rad, de_rad = _wave(errors, L.ERR_SCREW_RADIAL, u)
        chi = th_c - th_rev + rollers[i, L.R_RUNOUT_PHASE]
        cos_chi, minus_sin_chi = _wave(errors, L.ERR_UNIT_COSINE, chi)
        ro_c, ro_s = runout * cos_chi, -runout * minus_sin_chi
        th_rev_screw = th_rev  # the nut side's χ is this one's plus th_rev_screw − th_rev_nut
        lead_local = lead_s - de_ax  # the error's slope acts as a local lead change
        d_ax = (
            lead_s * (th_s - th_rev)
            - lead_r * (th_c - th_rev)
            - g1 * (z_c - z_s)
            + rollers[i, L.R_E_S]
            + e_ax
        )
        d_ax_dot = lead_local * (w_s - w_rev) - lead_r * (w_c - w_rev) - g1 * (vz_c - vz_s)
        approach = orbit - rho + e_rad - ro_c
        approach_dot = -rho_dot + de_rad * (w_rev - w_s) + ro_s * (w_c - w_rev)
        # Spalls: a depression of one thread turn (share 1/n_t) on the flanks they are on; the
        # screw spall only while the roller's threads span its axial position (gate).
        if spalled:
            h, dh = _wave(errors, L.ERR_SCREW_SPALL, u)
            gate, dgate = _gate(z_c - z_s - p[L.P_SPALL_Z], p[L.P_SPALL_HALF], p[L.P_SPALL_RAMP])
            h_r, dh_r = _wave(errors, L.ERR_ROLLER_SPALL, th_c - th_rev + math.pi)
            h_r *= rollers[i, L.R_SPALL]
            dh_r *= rollers[i, L.R_SPALL]
            on_plus, on_minus = p[L.P_SPALL_PLUS_S], p[L.P_SPALL_MINUS_S]
            # depth rates: dh·u̇ (u̇ = w_rev − w_s) gated, the gate's own, dh_r·χ̇
            rate = dh * gate * (w_rev - w_s) + h * dgate * (vz_c - vz_s)
            rate_r = dh_r * (w_c - w_rev)
            spall = (
                p[L.P_SPALL_SHARE],
                h * gate * on_plus + h_r,
                rate * on_plus + rate_r,
                h * gate * on_minus + h_r,
                rate * on_minus + rate_r,
            )
            f_plus, f_minus, diss, pit_plus, pit_minus = _pitted_pair(
                d_ax, d_ax_dot, approach, approach_dot, rollers[i, L.R_B_S], cot_b, k_ts, c_ts,
                expo, spall,
            )  # fmt: skip
            f_dh = (pit_plus * on_plus + pit_minus * on_minus) * gate  # times dh
            f_dhr = pit_plus + pit_minus  # times dh_r
            f_gate = (pit_plus * on_plus + pit_minus * on_minus) * h * dgate  # along z_c − z_s
        else:
            f_plus, f_minus, diss = _thread_pair(
                d_ax, d_ax_dot, approach, approach_dot, rollers[i, L.R_B_S], cot_b, k_ts, c_ts,
                expo,
            )  # fmt: skip
            dh = dh_r = f_dh = f_dhr = f_gate = 0.0
        p_diss += diss
        screw_contact = f_plus + f_minus > 0.0
        f_ax = f_plus - f_minus  # axial force of the screw on the roller (+z)
        f_rad = (f_plus + f_minus) * cot_b  # pushes roller outward, screw inward
        # along e_t of the roller, from θ_rev (helix, radial error slope, runout, spall slopes)
        g_tan = (
            f_ax * (lead_local - lead_r) - f_rad * de_rad + f_rad * ro_s + f_dh * dh - f_dhr * dh_r
        ) * inv_orbit
        # Screw–roller traction (_traction: Mindlin stick up to μN, rolling relaxation), plus
        # viscous drag. v_slide = 0 is rolling at the screw's pitch circle and the roller's
        # effective rolling radius r_rs on the screw.
        r_rs = rollers[i, L.R_ROLL_S]
        v_roll = r_rs * (w_c - w_rev)  # roller surface speed through the contact
        v_slide = r_s * (w_s - w_rev) + v_roll
        if stribeck:  # the lubrication regime at this contact's entrainment speed
            u_e = 0.5 * abs(r_s * (w_s - w_rev) - v_roll)
            mu_c = _clamped(errors, L.ERR_COULOMB, u_e) * fscale
        cap = mu_c * (f_plus + f_minus) * inv_sin_b
        aux[a0 + i] = cap
        f_fric, dy[s0 + i], pf = _traction(
            y[s0 + i], v_slide, cap, k_tan, c_tan, abs(v_roll) * rollers[i, L.R_RELAX_S]
        )
        p_fric += pf
        aux[a0 + L.AR_TRACTION_S * n_rollers + i] = f_fric
        f_fric += mu_v * v_slide
        p_fric += mu_v * v_slide * v_slide
        # Paper 02's steady losses: Coulomb friction μ2·N against the roller's axial sliding on
        # the screw and the differential-sliding torque μ3·N on the screw, reacted by the
        # roller's revolution.
        normal = (f_plus + f_minus) * inv_sin_b
        v_ax_slide = vz_c - vz_s
        f_axial = -mu_c * normal * _tanh(v_ax_slide * inv_v_axial)
        p_fric -= f_axial * v_ax_slide
        w_rel = w_s - w_rev
        m_diff = mu_r * normal * _tanh(w_rel * inv_w_roll)
        p_fric += m_diff * w_rel
        friction_torque += r_s * f_fric - f_axial * lead_eff + m_diff
        torque_screw += -f_ax * lead_local + f_rad * de_rad - r_s * f_fric - m_diff - f_dh * dh
        force_screw_axial -= g1 * f_ax + f_axial + f_gate
        # on the roller: radial push f_rad·e_r, helix reaction, traction (through θ_rev, whose
        # coefficient in v_slide is −(r_s + r_rs)) and the reaction of the differential-sliding
        # torque along e_t
        tangential = g_tan + (f_fric * (r_s + r_rs) + m_diff) * inv_orbit
        fx_r = f_rad * c - tangential * s
        fy_r = f_rad * s + tangential * c
        dy[v0 + L.Q_XS] -= fx_r
        dy[v0 + L.Q_YS] -= fy_r
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + b + 2] += f_ax * lead_r - r_rs * f_fric - f_rad * ro_s + f_dhr * dh_r
        dy[v0 + b + 3] += g1 * f_ax + f_axial + f_gate

        # ---------------- roller–nut thread
        rho, tau, rho_dot, tau_dot = _roller_frame(
            xr, yr, vxr, vyr, x_n, y_n, vx_n, vy_n, c, s, w_p
        )
        th_rev = th_p + tau * inv_orbit
        w_rev = w_p + tau_dot * inv_orbit
        e_ax, de_ax = _wave(errors, L.ERR_NUT_AXIAL, th_rev + psi - th_n)
        lead_local = lead_n + de_ax
        d_ax = (
            z_c
            - z_n
            + lead_r * (th_c - th_rev)
            - lead_n * (th_n - th_rev)
            + rollers[i, L.R_E_N]
            + e_ax
        )
        d_ax_dot = vz_c - vz_n + lead_r * (w_c - w_rev) - lead_local * (w_n - w_rev)
        # cos and −sin of χ by angle addition from the screw side's (no second lookup): the two
        # revolution angles differ by the screw–nut lateral offset over the orbit radius,
        # δ ≲ 1e-2 rad, where cos δ ≈ 1 − δ²/2 and sin δ ≈ δ miss by ≤ δ³/6 ≈ 2e-7 of the
        # runout. −sin χ is still the table's slope, to 2π/N of the runout as before (N its
        # points), now that of the screw side's segment: the nut acceleration moves by ≈ 4e-5.
        delta = th_rev_screw - th_rev
        cos_d, sin_d = 1.0 - 0.5 * delta * delta, delta
        cos_chi, minus_sin_chi = (
            cos_chi * cos_d + minus_sin_chi * sin_d,
            minus_sin_chi * cos_d - cos_chi * sin_d,
        )
        ro_c, ro_s = runout * cos_chi, -runout * minus_sin_chi
        u_n = th_rev + psi - th_n
        if spalled:
            h, dh = _wave(errors, L.ERR_NUT_SPALL, u_n)
            h_r, dh_r = _wave(errors, L.ERR_ROLLER_SPALL, th_c - th_rev)
            h_r *= rollers[i, L.R_SPALL]
            dh_r *= rollers[i, L.R_SPALL]
            on_plus, on_minus = p[L.P_SPALL_PLUS_N], p[L.P_SPALL_MINUS_N]
            rate = dh * (w_rev - w_n)
            rate_r = dh_r * (w_c - w_rev)
            spall = (
                p[L.P_SPALL_SHARE],
                h * on_plus + h_r,
                rate * on_plus + rate_r,
                h * on_minus + h_r,
                rate * on_minus + rate_r,
            )
            f_plus, f_minus, diss, pit_plus, pit_minus = _pitted_pair(
                d_ax, d_ax_dot, rho - orbit + ro_c, rho_dot - ro_s * (w_c - w_rev),
                rollers[i, L.R_B_N], cot_b, k_tn, c_tn, expo, spall,
            )  # fmt: skip
            f_dh = pit_plus * on_plus + pit_minus * on_minus
            f_dhr = pit_plus + pit_minus
        else:
            f_plus, f_minus, diss = _thread_pair(
                d_ax, d_ax_dot, rho - orbit + ro_c, rho_dot - ro_s * (w_c - w_rev),
                rollers[i, L.R_B_N], cot_b, k_tn, c_tn, expo,
            )  # fmt: skip
            dh = dh_r = f_dh = f_dhr = 0.0
        p_diss += diss
        if screw_contact and f_plus + f_minus > 0.0:
            engaged += 1.0
        f_ax = f_plus - f_minus  # axial force of the roller on the nut (+z)
        f_rad = (f_plus + f_minus) * cot_b  # pushes roller inward, nut outward
        g_tan = (
            -f_ax * (lead_local - lead_r) - f_rad * ro_s + f_dh * dh - f_dhr * dh_r
        ) * inv_orbit
        # Roller–nut traction, the same law as the screw side's with the nut side's stiffness
        # and normal load: the roller also rolls on the nut, so with its gear in mesh it is
        # over-constrained, and a mismatch ε between the gear ratio and the threads' rolling
        # ratio (r_rn = r_r/(1 + ε), model._roller_params) is shared between creep here and the
        # gear's load (Jones & Velinsky 2012). v_nut is the nut surface's speed over the roller's.
        r_rn = rollers[i, L.R_ROLL_N]
        v_roll = r_rn * (w_c - w_rev)
        v_nut = r_n * (w_n - w_rev) - v_roll
        cap = mu_c * (f_plus + f_minus) * inv_sin_b
        aux[a0 + L.AR_CAP_N * n_rollers + i] = cap
        f_tn, dy[s0 + n_rollers + i], pf = _traction(
            y[s0 + n_rollers + i],
            v_nut,
            cap,
            rollers[i, L.R_K_TAN_N],
            rollers[i, L.R_C_TAN_N],
            abs(v_roll) * rollers[i, L.R_RELAX_N],
        )
        p_fric += pf
        aux[a0 + L.AR_TRACTION_N * n_rollers + i] = f_tn
        # −∂v_nut/∂q̇ times f_tn: e_t of the roller through θ_rev (coefficient r_rn − r_n),
        # its spin r_rn, the nut's rotation −r_n
        g_tan += f_tn * (r_n - r_rn) * inv_orbit
        fx_r = -f_rad * c + g_tan * (-s)
        fy_r = -f_rad * s + g_tan * c
        dy[v0 + L.Q_XN] -= fx_r
        dy[v0 + L.Q_YN] -= fy_r
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + b + 2] += -f_ax * lead_r + f_rad * ro_s + f_dhr * dh_r + r_rn * f_tn
        dy[v0 + b + 3] -= f_ax
        dy[v0 + L.Q_ZN] += f_ax
        dy[v0 + L.Q_THN] += f_ax * lead_local - f_dh * dh - r_n * f_tn

        # ---------------- roller gear – ring gear mesh (line of action n = cos α0 e_t − sin α0 e_r)
        phase = z_ring * (phi - th_n) * INV_TWO_PI + rollers[i, L.R_MESH_PHASE]
        k_mesh = _mesh_stiffness(mesh_table, phase) * rollers[i, L.R_MESH_SCALE]
        if toothed:  # a damaged ring tooth meets every roller, a roller's own tooth its ring
            ring, _ = _wave(errors, L.ERR_RING_TOOTH, phase)
            own, _ = _wave(errors, L.ERR_ROLLER_TOOTH, phase)
            k_mesh *= 1.0 + ring + rollers[i, L.R_TOOTH] * own
        e_g, de_g = _wave(errors, L.ERR_GEAR, phi - th_n)
        d_g = (
            rb_ring * th_n
            - rb_roller * th_c
            - cos_a0 * (orbit * th_p + tau)
            + sin_a0 * (rho - orbit)
            + rollers[i, L.R_E_G]
            + e_g
        )
        d_g_dot = (
            (rb_ring - de_g) * w_n
            - rb_roller * w_c
            - cos_a0 * (orbit * w_p + tau_dot)
            + sin_a0 * rho_dot
            + de_g * w_p
        )
        bg = rollers[i, L.R_B_G]
        f_drive, d1 = _flank(d_g - bg, d_g_dot, k_mesh, c_mesh, 1.0)
        f_coast, d2 = _flank(-d_g - bg, -d_g_dot, k_mesh, c_mesh, 1.0)
        p_diss += d1 + d2
        f_g = f_drive - f_coast
        aux[a0 + L.AR_GEAR * n_rollers + i] = f_g
        # −∂V/∂q with ∂d_g/∂(X, Y) = −n, ∂d_g/∂θ_N = r_bN − e', ∂d_g/∂θ_c = −r_br, ∂d_g/∂θ_p ∋ e'
        fx_r = f_g * (cos_a0 * (-s) - sin_a0 * c)
        fy_r = f_g * (cos_a0 * c - sin_a0 * s)
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + L.Q_XN] -= fx_r
        dy[v0 + L.Q_YN] -= fy_r
        dy[v0 + L.Q_THN] -= f_g * (rb_ring - de_g)
        dy[v0 + L.Q_THP] -= f_g * de_g
        dy[v0 + b + 2] += f_g * rb_roller

        # ---------------- carrier pocket
        rad = rollers[i, L.R_POCKET_R]
        ex = xr - (x_p + rad * c)
        ey = yr - (y_p + rad * s)
        evx = vxr - (vx_p - rad * s * w_p)
        evy = vyr - (vy_p + rad * c * w_p)
        fx = -k_cp * ex - c_cp * evx
        fy = -k_cp * ey - c_cp * evy
        p_diss += c_cp * (evx * evx + evy * evy)
        dy[v0 + b] += fx
        dy[v0 + b + 1] += fy
        dy[v0 + L.Q_XP] -= fx
        dy[v0 + L.Q_YP] -= fy
        dy[v0 + L.Q_THP] += rad * (s * fx - c * fy)

    # ---------------- supports and couplings
    dy[v0 + L.Q_XS] += -p[L.P_K_S] * x_s - p[L.P_C_S] * vx_s
    dy[v0 + L.Q_YS] += -p[L.P_K_S] * y_s - p[L.P_C_S] * vy_s
    dy[v0 + L.Q_XN] += -p[L.P_K_N] * x_n - p[L.P_C_N] * vx_n
    dy[v0 + L.Q_YN] += -p[L.P_K_N] * y_n - p[L.P_C_N] * vy_n
    dy[v0 + L.Q_THN] += -p[L.P_K_ND] * th_n - p[L.P_C_ND] * w_n
    fx = -p[L.P_K_PN] * (x_p - x_n) - p[L.P_C_PN] * (vx_p - vx_n)
    fy = -p[L.P_K_PN] * (y_p - y_n) - p[L.P_C_PN] * (vy_p - vy_n)
    dy[v0 + L.Q_XP] += fx
    dy[v0 + L.Q_YP] += fy
    dy[v0 + L.Q_XN] -= fx
    dy[v0 + L.Q_YN] -= fy
    t_pn = -p[L.P_C_PND] * (w_p - w_n)
    dy[v0 + L.Q_THP] += t_pn
    dy[v0 + L.Q_THN] -= t_pn
    p_diss += (
        p[L.P_C_S] * (vx_s * vx_s + vy_s * vy_s)
        + p[L.P_C_N] * (vx_n * vx_n + vy_n * vy_n)
        + p[L.P_C_ND] * w_n * w_n
        + p[L.P_C_PN] * ((vx_p - vx_n) ** 2 + (vy_p - vy_n) ** 2)
        + p[L.P_C_PND] * (w_p - w_n) ** 2
        + p[L.P_C_SD] * w_s * w_s
    )

    # Lubricant squeeze film of the loaded thread contacts: damps the nut's axial motion relative
    # to the screw's kinematic position (through the rollers, whose own modes are far faster),
    # in proportion to the rollers whose load path is closed — not across an open gap, where
    # the film is thick and its damping negligible (it scales as 1/h³).
    v_film = vz_n - vz_s - lead_eff * w_s
    f_film = p[L.P_C_FILM] * engaged / n_rollers * v_film
    dy[v0 + L.Q_ZN] -= f_film
    force_screw_axial += f_film
    torque_screw += f_film * lead_eff
    p_diss += f_film * v_film

    # ---------------- load: on the payload through the linkage, or ideal on the nut
    load = axial_load(t, load_knots, p[L.P_LOAD_SIN_AMP], p[L.P_LOAD_SIN_FREQ])
    dv_nut = vz_n - p[L.P_V_NUT_REF]
    dy[v0 + L.Q_ZN] -= p[L.P_C_NA] * dv_nut
    p_diss += p[L.P_C_NA] * dv_nut * vz_n
    if on_payload:
        v_link = vz_n - y[v0 + L.Q_ZL]
        link = p[L.P_K_LINK] * (z_n - y[L.Q_ZL]) + p[L.P_C_LINK] * v_link
        dy[v0 + L.Q_ZN] -= link
        dy[v0 + L.Q_ZL] = (link - load) / p[L.P_M_L]
        p_diss += p[L.P_C_LINK] * v_link * v_link
        p_load = -load * y[v0 + L.Q_ZL]
    else:
        link = load
        dy[v0 + L.Q_ZN] -= load
        p_load = -load * vz_n

    # ---------------- screw axial: thrust bearing with play (or held)
    if axial_free:
        play = p[L.P_BEAR_PLAY]
        k_b, c_b = p[L.P_K_BEAR], p[L.P_C_BEAR]
        f_up, d1 = _flank(-z_s - play, -vz_s, k_b, c_b, 1.0)
        f_down, d2 = _flank(z_s - play, vz_s, k_b, c_b, 1.0)
        p_diss += d1 + d2
        dy[v0 + L.Q_ZS] = (force_screw_axial + f_up - f_down) / p[L.P_M_S]
    else:
        dy[v0 + L.Q_ZS] = 0.0

    # ---------------- motor, coupling and drive
    j_m, j_s = p[L.P_J_M], p[L.P_J_S]
    if geared:
        # Reduction: output angle θ_m/N + e(θ_m), e the transmission error at the mesh order;
        # gear mesh and coupling in series (one spring, P_K_COUP) with the gear's backlash as
        # dead band. `transmitted` is the loss-free torque the output asks of the motor shaft.
        if coupled:
            order, te = p[L.P_MESH_ORDER], p[L.P_GEAR_TE]
            gain = 1.0 / ratio + te * order * math.cos(order * th_m)  # ∂(output)/∂θ_m
            twist = th_m / ratio + te * math.sin(order * th_m) - th_s
            twist_rate = gain * w_m - w_s
            play = p[L.P_GEAR_BACKLASH]
            t_coup = 0.0
            if twist > play or twist < -play:
                edge = play if twist > 0.0 else -play
                t_coup = p[L.P_K_COUP] * (twist - edge) + p[L.P_C_COUP] * twist_rate
                p_diss += p[L.P_C_COUP] * twist_rate * twist_rate
            dy[v0 + L.Q_THS] = (t_coup + torque_screw - p[L.P_C_SD] * w_s) / j_s
            transmitted = t_coup * gain
            j_drive = j_m
        else:
            transmitted = (-torque_screw + p[L.P_C_SD] * w_s) / ratio
            j_drive = j_m + j_s / (ratio * ratio)
        # Mesh loss ∝ transmitted torque (ISO/TR 14179-1's load-dependent loss): the motor
        # gives T/η when it drives and receives T·η when driven back; always dissipated, its
        # sign switch at zero motor speed regularised.
        eta = p[L.P_GEAR_EFFICIENCY]
        share = 1.0 / eta - 1.0 if transmitted * w_m > 0.0 else 1.0 - eta
        loss = abs(transmitted) * share * _tanh(w_m / p[L.P_W_GEAR])
        p_diss += loss * w_m
        load_torque = transmitted + loss
    elif coupled:
        t_coup = p[L.P_K_COUP] * (th_m - th_s) + p[L.P_C_COUP] * (w_m - w_s)
        p_diss += p[L.P_C_COUP] * (w_m - w_s) ** 2
        dy[v0 + L.Q_THS] = (t_coup + torque_screw - p[L.P_C_SD] * w_s) / j_s
        load_torque = t_coup  # what the motor shaft must deliver beside its own inertia
        j_drive = j_m
    else:
        load_torque = -torque_screw + p[L.P_C_SD] * w_s
        j_drive = j_m + j_s
    if prescribed:
        drive = j_drive * alpha_ref + load_torque
        alpha_m = alpha_ref
    else:
        w_cmd = w_ref
        if mode == L.DRIVE_POSITION_LOOP:
            w_cmd = w_ref + p[L.P_KP_POS] * (th_ref - th_m)
        drive = p[L.P_KP] * (w_cmd - w_m) + p[L.P_KI] * y[2 * nq + L.X_SPEED_INT]
        limit = p[L.P_TORQUE_LIMIT]
        if drive > limit:
            drive = limit
        elif drive < -limit:
            drive = -limit
        alpha_m = (drive - load_torque) / j_drive
        dy[2 * nq + L.X_SPEED_INT] = w_cmd - w_m
    dy[v0 + L.Q_THM] = alpha_m
    if not coupled:
        dy[v0 + L.Q_THS] = alpha_m / ratio if geared else alpha_m

    # ---------------- accelerations
    m_s, m_n, m_p, m_c = p[L.P_M_S], p[L.P_M_N], p[L.P_M_P], p[L.P_M_C]
    dy[v0 + L.Q_XS] /= m_s
    dy[v0 + L.Q_YS] /= m_s
    dy[v0 + L.Q_XN] /= m_n
    dy[v0 + L.Q_YN] /= m_n
    dy[v0 + L.Q_THN] /= p[L.P_J_N]
    dy[v0 + L.Q_ZN] /= m_n
    dy[v0 + L.Q_XP] /= m_p
    dy[v0 + L.Q_YP] /= m_p
    dy[v0 + L.Q_THP] /= p[L.P_J_P]
    if not on_payload:  # the payload coordinate follows the nut
        dy[v0 + L.Q_ZL] = dy[v0 + L.Q_ZN]
    inv_m_c, inv_j_c = 1.0 / m_c, 1.0 / p[L.P_J_C]
    for i in range(n_rollers):
        b = v0 + L.Q_ROLLER0 + L.ROLLER_DOF * i
        dy[b] *= inv_m_c
        dy[b + 1] *= inv_m_c
        dy[b + 2] *= inv_j_c
        dy[b + 3] *= inv_m_c

    e0 = 2 * nq
    p_drive = drive * w_m
    dy[e0 + L.X_W_DRIVE] = p_drive
    dy[e0 + L.X_W_LOAD] = p_load
    dy[e0 + L.X_W_DISS] = p_diss + p_fric
    dy[e0 + L.X_W_FRIC] = p_fric
    aux[L.A_MOTOR_TORQUE] = drive
    aux[L.A_FRICTION_TORQUE] = friction_torque
    aux[L.A_AXIAL_LOAD] = link
    aux[L.A_LOAD_FORCE] = load
    aux[L.A_P_DRIVE] = p_drive
    aux[L.A_P_LOAD] = p_load
    aux[L.A_P_DISS] = p_diss + p_fric
    aux[L.A_P_FRIC] = p_fric


@njit(cache=True, fastmath=FAST)
def _record(y, dy, aux, p, nq, out_row):
    v0 = nq
    out_row[L.C_MOTOR_ANGLE] = y[L.Q_THM]
    out_row[L.C_MOTOR_SPEED] = y[v0 + L.Q_THM]
    out_row[L.C_MOTOR_TORQUE] = aux[L.A_MOTOR_TORQUE]
    out_row[L.C_SCREW_ANGLE] = y[L.Q_THS]
    out_row[L.C_SCREW_SPEED] = y[v0 + L.Q_THS]
    out_row[L.C_CARRIER_SPEED] = y[v0 + L.Q_THP]
    out_row[L.C_NUT_POSITION] = y[L.Q_ZN]
    out_row[L.C_NUT_AXIAL_ACCEL] = dy[v0 + L.Q_ZN]
    out_row[L.C_NUT_TANGENTIAL_ACCEL] = p[L.P_R_NUT] * dy[v0 + L.Q_THN]
    out_row[L.C_NUT_RADIAL_X_ACCEL] = dy[v0 + L.Q_XN]
    out_row[L.C_NUT_RADIAL_Y_ACCEL] = dy[v0 + L.Q_YN]
    out_row[L.C_FRICTION_TORQUE] = aux[L.A_FRICTION_TORQUE]
    out_row[L.C_AXIAL_LOAD] = aux[L.A_AXIAL_LOAD]
    out_row[L.C_PAYLOAD_POSITION] = y[L.Q_ZL]
    out_row[L.C_SCREW_AXIAL_POSITION] = y[L.Q_ZS]
    out_row[L.C_LOAD_FORCE] = aux[L.A_LOAD_FORCE]


@njit(cache=True, inline="always", fastmath=FAST)
def _clamp_one(y, j, cap, k, e0):
    # A stuck contact cannot hold more than its Coulomb limit: when the normal load drops, the
    # elastic tangential displacement resets to the limit and its released energy is dissipated.
    limit = cap / k
    slip = y[j]
    if slip > limit or slip < -limit:
        new = limit if slip > 0.0 else -limit
        released = 0.5 * k * (slip * slip - new * new)
        y[j] = new
        y[e0 + L.X_W_DISS] += released
        y[e0 + L.X_W_FRIC] += released


@njit(cache=True, fastmath=FAST)
def _clamp_traction(y, p, rollers, nq, aux):
    # Both traction states of every roller: screw side (stiffness P_K_TAN), nut side (R_K_TAN_N).
    n = rollers.shape[0]
    s0 = 2 * nq + L.N_EXTRA
    k_tan = p[L.P_K_TAN]
    for i in range(n):
        _clamp_one(y, s0 + i, aux[L.N_AUX + L.AR_CAP_S * n + i], k_tan, 2 * nq)
        _clamp_one(
            y, s0 + n + i, aux[L.N_AUX + L.AR_CAP_N * n + i], rollers[i, L.R_K_TAN_N], 2 * nq
        )


@njit(cache=True, inline="always", fastmath=FAST)
def _hold_prescribed(y, t, p, motion, nq):
    # The prescribed angle is not integrated: set it (and the rigidly coupled screw) exactly.
    # The knots are the screw's: through a reduction the motor turns N times as far.
    th, w, _ = screw_motion(t, motion)
    if p[L.P_GEARED] == 1.0:
        y[L.Q_THM] = p[L.P_RATIO] * th
        y[nq + L.Q_THM] = p[L.P_RATIO] * w
    else:
        y[L.Q_THM] = th
        y[nq + L.Q_THM] = w
    if p[L.P_COUPLED] != 1.0:
        y[L.Q_THS] = th
        y[nq + L.Q_THS] = w


@njit(cache=True, fastmath=FAST)
def integrate(
    y,
    t0,
    h,
    n_steps,
    record_every,
    p,
    rollers,
    mesh_table,
    motion,
    load_knots,
    errors,
    out,
    k1,
    k2,
    k3,
    k4,
    tmp,
    aux,
):
    """Advance ``y`` in place by ``n_steps`` RK4 steps of ``h``; record every ``record_every``.

    Records the truth signals at the start of each recorded step into ``out`` (rows). Returns
    (status, step): status 0 = done, 1 = non-finite state detected at ``step``.
    Work arrays k1…k4, tmp, aux are passed in so the loop allocates nothing.
    """
    n_state = y.shape[0]
    nq = L.Q_ROLLER0 + L.ROLLER_DOF * rollers.shape[0]
    prescribed = p[L.P_DRIVE_MODE] == L.DRIVE_PRESCRIBED
    row = 0
    half = 0.5 * h
    for step in range(n_steps):
        t = t0 + step * h
        if prescribed:
            _hold_prescribed(y, t, p, motion, nq)
        rhs(t, y, p, rollers, mesh_table, motion, load_knots, errors, k1, aux)
        if step % record_every == 0:
            ok = True
            for j in range(2 * nq):
                if not math.isfinite(y[j]):
                    ok = False
                    break
            if not ok:
                return 1, step
            _record(y, k1, aux, p, nq, out[row])
            row += 1
        for j in range(n_state):
            tmp[j] = y[j] + half * k1[j]
        rhs(t + half, tmp, p, rollers, mesh_table, motion, load_knots, errors, k2, aux)
        for j in range(n_state):
            tmp[j] = y[j] + half * k2[j]
        rhs(t + half, tmp, p, rollers, mesh_table, motion, load_knots, errors, k3, aux)
        for j in range(n_state):
            tmp[j] = y[j] + h * k3[j]
        rhs(t + h, tmp, p, rollers, mesh_table, motion, load_knots, errors, k4, aux)
        for j in range(n_state):
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        _clamp_traction(y, p, rollers, nq, aux)
    if prescribed:
        _hold_prescribed(y, t0 + n_steps * h, p, motion, nq)
    for j in range(2 * nq):
        if not math.isfinite(y[j]):
            return 1, n_steps
    return 0, n_steps
