"""numba kernels of the PRSM lumped-parameter model: right-hand side and fixed-step RK4.

Only float64 arrays and scalars cross this boundary; the layout of every array is in
:mod:`.layout`, its physics in :mod:`.model` (which documents every term and cites paper 01).

Force laws derive from one energy function (docs/validation.md, paper 01 dynamics): each
thread engagement has an axial closure with the helix built in and a radial closure coupled
through cot β, contact on either flank beyond a per-roller half-clearance b; the gear mesh has a
time-varying stiffness looked up in a table over one mesh cycle. Roller centres are absolute
positions, so the carrier pocket springs supply the centripetal force (no separate
centrifugal term, which would double count).
"""

from __future__ import annotations

import math

from numba import njit

from .layout import (
    A_AXIAL_LOAD,
    A_DRIVE_TORQUE,
    A_FRICTION_TORQUE,
    A_P_DISS,
    A_P_DRIVE,
    A_P_FRIC,
    A_P_LOAD,
    C_AXIAL_LOAD,
    C_CARRIER_SPEED,
    C_DRIVE_TORQUE,
    C_FRICTION_TORQUE,
    C_NUT_AXIAL_ACCEL,
    C_NUT_POSITION,
    C_NUT_RADIAL_X_ACCEL,
    C_NUT_RADIAL_Y_ACCEL,
    C_NUT_TANGENTIAL_ACCEL,
    C_SCREW_ANGLE,
    C_SCREW_SPEED,
    DRIVE_PRESCRIBED,
    N_AUX,
    N_EXTRA,
    P_C_CP,
    P_C_MESH,
    P_C_N,
    P_C_NA,
    P_C_ND,
    P_C_PN,
    P_C_PND,
    P_C_S,
    P_C_SD,
    P_C_TAN,
    P_C_THREAD_N,
    P_C_THREAD_S,
    P_COS_A0,
    P_COT_BETA,
    P_DRIVE_MODE,
    P_EXPONENT,
    P_FRICTION_SCALE,
    P_J_C,
    P_J_N,
    P_J_P,
    P_J_S,
    P_K_CP,
    P_K_N,
    P_K_ND,
    P_K_PN,
    P_K_S,
    P_K_TAN,
    P_K_THREAD_N,
    P_K_THREAD_S,
    P_KI,
    P_KP,
    P_LEAD_EFF,
    P_LEAD_N,
    P_LEAD_R,
    P_LEAD_S,
    P_LOAD_SIN_AMP,
    P_LOAD_SIN_FREQ,
    P_M_C,
    P_M_N,
    P_M_P,
    P_M_S,
    P_MU_COUL,
    P_MU_ROLL,
    P_MU_VISC,
    P_ORBIT_R,
    P_R_NUT,
    P_R_ROLLER,
    P_R_SCREW,
    P_RB_RING,
    P_RB_ROLLER,
    P_SIN_A0,
    P_SIN_BETA,
    P_TORQUE_LIMIT,
    P_V_AXIAL,
    P_V_NUT_REF,
    P_W_ROLL,
    P_Z_RING,
    Q_ROLLER0,
    Q_THN,
    Q_THP,
    Q_THS,
    Q_XN,
    Q_XP,
    Q_XS,
    Q_YN,
    Q_YP,
    Q_YS,
    Q_ZN,
    R_B_G,
    R_B_N,
    R_B_S,
    R_COS_PSI,
    R_E_G,
    R_E_N,
    R_E_S,
    R_MESH_PHASE,
    R_MESH_SCALE,
    R_POCKET_R,
    R_PSI,
    R_SIN_PSI,
    ROLLER_DOF,
    X_SPEED_INT,
    X_W_DISS,
    X_W_DRIVE,
    X_W_FRIC,
    X_W_LOAD,
)

TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
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
    k = 0
    while motion[0, k + 1] <= t:
        k += 1
    dt = t - motion[0, k]
    slope = (motion[1, k + 1] - motion[1, k]) / (motion[0, k + 1] - motion[0, k])
    return (
        motion[2, k] + motion[1, k] * dt + 0.5 * slope * dt * dt,
        motion[1, k] + slope * dt,
        slope,
    )


@njit(cache=True, inline="always")
def axial_load(t, load_knots, amp, freq):
    """Resisting axial load [N] at time t: piecewise-linear knots plus a sinusoid."""
    n = load_knots.shape[1]
    if t <= load_knots[0, 0]:
        base = load_knots[1, 0]
    elif t >= load_knots[0, n - 1]:
        base = load_knots[1, n - 1]
    else:
        k = 0
        while load_knots[0, k + 1] <= t:
            k += 1
        w = (t - load_knots[0, k]) / (load_knots[0, k + 1] - load_knots[0, k])
        base = load_knots[1, k] + w * (load_knots[1, k + 1] - load_knots[1, k])
    return base + amp * math.sin(TWO_PI * freq * t)


@njit(cache=True, inline="always")
def _spring(closure, k, exponent):
    # Elastic part of a flank force: linear or Hertzian F = k·x^1.5.
    if closure <= 0.0:
        return 0.0
    if exponent == 1.0:
        return k * closure
    return k * closure * math.sqrt(closure)


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def _roller_frame(xr, yr, vxr, vyr, xb, yb, vxb, vyb, c, s, w_p):
    # Roller centre relative to a body centre in the pocket frame (e_r, e_t): radial and
    # tangential offsets and their rates (the frame turns with the carrier at w_p).
    dx, dy = xr - xb, yr - yb
    dvx, dvy = vxr - vxb, vyr - vyb
    rho = dx * c + dy * s
    tau = -dx * s + dy * c
    return rho, tau, dvx * c + dvy * s + tau * w_p, -dvx * s + dvy * c - rho * w_p


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def _mesh_stiffness(table, phase):
    n = table.shape[0]
    x = (phase - math.floor(phase)) * n
    i0 = int(x)
    if i0 >= n:
        i0 = n - 1
    w = x - i0
    i1 = i0 + 1
    if i1 == n:
        i1 = 0
    return table[i0] * (1.0 - w) + table[i1] * w


@njit(cache=True)
def rhs(t, y, p, rollers, mesh_table, motion, load_knots, dy, aux):
    """dy/dt of the full state at time t; auxiliary outputs (torques, powers) into ``aux``.

    Allocation-free: writes into ``dy`` and ``aux`` only.
    """
    n_rollers = rollers.shape[0]
    nq = Q_ROLLER0 + ROLLER_DOF * n_rollers
    v0 = nq  # offset of velocities; generalised forces are accumulated at dy[v0 + j]
    for j in range(2 * nq + N_EXTRA + n_rollers):
        dy[j] = 0.0
    for j in range(nq):
        dy[j] = y[v0 + j]

    prescribed = p[P_DRIVE_MODE] == DRIVE_PRESCRIBED
    if prescribed:
        th_s, w_s, alpha_ref = screw_motion(t, motion)
        dy[Q_THS] = w_s
    else:
        th_s = y[Q_THS]
        w_s = y[v0 + Q_THS]
        alpha_ref = 0.0

    x_s, y_s = y[Q_XS], y[Q_YS]
    vx_s, vy_s = y[v0 + Q_XS], y[v0 + Q_YS]
    x_n, y_n, th_n, z_n = y[Q_XN], y[Q_YN], y[Q_THN], y[Q_ZN]
    vx_n, vy_n, w_n, vz_n = y[v0 + Q_XN], y[v0 + Q_YN], y[v0 + Q_THN], y[v0 + Q_ZN]
    x_p, y_p, th_p = y[Q_XP], y[Q_YP], y[Q_THP]
    vx_p, vy_p, w_p = y[v0 + Q_XP], y[v0 + Q_YP], y[v0 + Q_THP]

    orbit = p[P_ORBIT_R]
    cot_b = p[P_COT_BETA]
    sin_b = p[P_SIN_BETA]
    lead_s, lead_r, lead_n = p[P_LEAD_S], p[P_LEAD_R], p[P_LEAD_N]
    rb_ring, rb_roller = p[P_RB_RING], p[P_RB_ROLLER]
    cos_a0, sin_a0 = p[P_COS_A0], p[P_SIN_A0]
    r_s, r_r = p[P_R_SCREW], p[P_R_ROLLER]
    k_ts, k_tn = p[P_K_THREAD_S], p[P_K_THREAD_N]
    c_ts, c_tn, c_mesh = p[P_C_THREAD_S], p[P_C_THREAD_N], p[P_C_MESH]
    expo = p[P_EXPONENT]
    k_cp, c_cp = p[P_K_CP], p[P_C_CP]
    fscale = p[P_FRICTION_SCALE]
    mu_c, mu_v = p[P_MU_COUL] * fscale, p[P_MU_VISC] * fscale
    k_tan, c_tan = p[P_K_TAN], p[P_C_TAN]
    mu_r = p[P_MU_ROLL] * fscale
    v_axial, w_roll, lead_eff = p[P_V_AXIAL], p[P_W_ROLL], p[P_LEAD_EFF]
    s0 = 2 * nq + N_EXTRA  # offset of the traction states
    z_ring = p[P_Z_RING]

    cos_p = math.cos(th_p)
    sin_p = math.sin(th_p)

    torque_screw = 0.0  # contact torque acting on the screw [N·m]
    friction_torque = 0.0  # friction part of the screw torque, paper 02's reduction [N·m]
    p_diss = 0.0
    p_fric = 0.0

    for i in range(n_rollers):
        b = Q_ROLLER0 + ROLLER_DOF * i
        xr, yr, th_c, z_c = y[b], y[b + 1], y[b + 2], y[b + 3]
        vxr, vyr, w_c, vz_c = y[v0 + b], y[v0 + b + 1], y[v0 + b + 2], y[v0 + b + 3]
        cps, sps = rollers[i, R_COS_PSI], rollers[i, R_SIN_PSI]
        c = cos_p * cps - sin_p * sps  # e_r of the pocket (rotation by angle addition)
        s = sin_p * cps + cos_p * sps
        # Deformations are measured from the assembled position (each roller's threads and
        # teeth are assembled in phase at its pocket), so the revolution angle enters as θ_p;
        # the pocket angle ψ_i only sets the mesh phase.
        phi = th_p + rollers[i, R_PSI]

        # ---------------- screw–roller thread
        rho, tau, rho_dot, tau_dot = _roller_frame(
            xr, yr, vxr, vyr, x_s, y_s, vx_s, vy_s, c, s, w_p
        )
        th_rev = th_p + tau / orbit
        w_rev = w_p + tau_dot / orbit
        d_ax = lead_s * (th_s - th_rev) - lead_r * (th_c - th_rev) - z_c + rollers[i, R_E_S]
        d_ax_dot = lead_s * (w_s - w_rev) - lead_r * (w_c - w_rev) - vz_c
        f_plus, f_minus, diss = _thread_pair(
            d_ax, d_ax_dot, orbit - rho, -rho_dot, rollers[i, R_B_S], cot_b, k_ts, c_ts, expo
        )
        p_diss += diss
        f_ax = f_plus - f_minus  # axial force of the screw on the roller (+z)
        f_rad = (f_plus + f_minus) * cot_b  # pushes roller outward, screw inward
        g_tan = f_ax * (lead_s - lead_r) / orbit  # along e_t of the roller, from θ_rev
        # Screw–roller traction: elastic tangential compliance k_t (Mindlin) that sticks up to
        # the Coulomb limit μN and slides beyond it (reset integrator, Haessig & Friedland
        # 1991), plus viscous drag. v_slide = 0 is rolling at both pitch circles.
        v_slide = r_s * (w_s - w_rev) + r_r * (w_c - w_rev)
        cap = mu_c * (f_plus + f_minus) / sin_b
        aux[N_AUX + i] = cap
        slip = y[s0 + i]
        f_stick = k_tan * slip
        if f_stick > cap or f_stick < -cap:
            f_fric = cap if f_stick > 0.0 else -cap
            if f_stick * v_slide < 0.0:  # unloading back into stick
                dy[s0 + i] = v_slide
                p_fric += f_fric * v_slide - f_stick * v_slide
            else:
                p_fric += f_fric * v_slide
        else:
            f_fric = f_stick + c_tan * v_slide
            dy[s0 + i] = v_slide
            p_fric += c_tan * v_slide * v_slide
        f_fric += mu_v * v_slide
        p_fric += mu_v * v_slide * v_slide
        # Paper 02's steady losses: Coulomb friction μ2·N against the roller's axial sliding on
        # the screw (screw axially fixed) and the differential-sliding torque μ3·N on the
        # screw, reacted by the roller's revolution.
        normal = (f_plus + f_minus) / sin_b
        f_axial = -mu_c * normal * math.tanh(vz_c / v_axial)
        p_fric -= f_axial * vz_c
        w_rel = w_s - w_rev
        m_diff = mu_r * normal * math.tanh(w_rel / w_roll)
        p_fric += m_diff * w_rel
        friction_torque += r_s * f_fric - f_axial * lead_eff + m_diff
        torque_screw += -f_ax * lead_s - r_s * f_fric - m_diff
        # on the roller: radial push f_rad·e_r, helix reaction, traction and the reaction of the
        # differential-sliding torque along e_t
        tangential = g_tan + f_fric + m_diff / orbit
        fx_r = f_rad * c - tangential * s
        fy_r = f_rad * s + tangential * c
        dy[v0 + Q_XS] -= fx_r
        dy[v0 + Q_YS] -= fy_r
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + b + 2] += f_ax * lead_r - r_r * f_fric
        dy[v0 + b + 3] += f_ax + f_axial

        # ---------------- roller–nut thread
        rho, tau, rho_dot, tau_dot = _roller_frame(
            xr, yr, vxr, vyr, x_n, y_n, vx_n, vy_n, c, s, w_p
        )
        th_rev = th_p + tau / orbit
        w_rev = w_p + tau_dot / orbit
        d_ax = z_c - z_n + lead_r * (th_c - th_rev) - lead_n * (th_n - th_rev) + rollers[i, R_E_N]
        d_ax_dot = vz_c - vz_n + lead_r * (w_c - w_rev) - lead_n * (w_n - w_rev)
        f_plus, f_minus, diss = _thread_pair(
            d_ax, d_ax_dot, rho - orbit, rho_dot, rollers[i, R_B_N], cot_b, k_tn, c_tn, expo
        )
        p_diss += diss
        f_ax = f_plus - f_minus  # axial force of the roller on the nut (+z)
        f_rad = (f_plus + f_minus) * cot_b  # pushes roller inward, nut outward
        g_tan = -f_ax * (lead_n - lead_r) / orbit
        fx_r = -f_rad * c + g_tan * (-s)
        fy_r = -f_rad * s + g_tan * c
        dy[v0 + Q_XN] -= fx_r
        dy[v0 + Q_YN] -= fy_r
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + b + 2] -= f_ax * lead_r
        dy[v0 + b + 3] -= f_ax
        dy[v0 + Q_ZN] += f_ax
        dy[v0 + Q_THN] += f_ax * lead_n

        # ---------------- roller gear – ring gear mesh (line of action n = cos α0 e_t − sin α0 e_r)
        phase = z_ring * (phi - th_n) / TWO_PI + rollers[i, R_MESH_PHASE]
        k_mesh = _mesh_stiffness(mesh_table, phase) * rollers[i, R_MESH_SCALE]
        d_g = (
            rb_ring * th_n
            - rb_roller * th_c
            - cos_a0 * (orbit * th_p + tau)
            + sin_a0 * (rho - orbit)
            + rollers[i, R_E_G]
        )
        d_g_dot = (
            rb_ring * w_n - rb_roller * w_c - cos_a0 * (orbit * w_p + tau_dot) + sin_a0 * rho_dot
        )
        bg = rollers[i, R_B_G]
        f_drive, d1 = _flank(d_g - bg, d_g_dot, k_mesh, c_mesh, 1.0)
        f_coast, d2 = _flank(-d_g - bg, -d_g_dot, k_mesh, c_mesh, 1.0)
        p_diss += d1 + d2
        f_g = f_drive - f_coast
        # −∂V/∂q with ∂d_g/∂(X, Y) = −n, ∂d_g/∂θ_N = r_bN, ∂d_g/∂θ_c = −r_br
        fx_r = f_g * (cos_a0 * (-s) - sin_a0 * c)
        fy_r = f_g * (cos_a0 * c - sin_a0 * s)
        dy[v0 + b] += fx_r
        dy[v0 + b + 1] += fy_r
        dy[v0 + Q_XN] -= fx_r
        dy[v0 + Q_YN] -= fy_r
        dy[v0 + Q_THN] -= f_g * rb_ring
        dy[v0 + b + 2] += f_g * rb_roller

        # ---------------- carrier pocket
        rad = rollers[i, R_POCKET_R]
        ex = xr - (x_p + rad * c)
        ey = yr - (y_p + rad * s)
        evx = vxr - (vx_p - rad * s * w_p)
        evy = vyr - (vy_p + rad * c * w_p)
        fx = -k_cp * ex - c_cp * evx
        fy = -k_cp * ey - c_cp * evy
        p_diss += c_cp * (evx * evx + evy * evy)
        dy[v0 + b] += fx
        dy[v0 + b + 1] += fy
        dy[v0 + Q_XP] -= fx
        dy[v0 + Q_YP] -= fy
        dy[v0 + Q_THP] += rad * (s * fx - c * fy)

    # ---------------- supports and couplings
    dy[v0 + Q_XS] += -p[P_K_S] * x_s - p[P_C_S] * vx_s
    dy[v0 + Q_YS] += -p[P_K_S] * y_s - p[P_C_S] * vy_s
    dy[v0 + Q_XN] += -p[P_K_N] * x_n - p[P_C_N] * vx_n
    dy[v0 + Q_YN] += -p[P_K_N] * y_n - p[P_C_N] * vy_n
    dy[v0 + Q_THN] += -p[P_K_ND] * th_n - p[P_C_ND] * w_n
    fx = -p[P_K_PN] * (x_p - x_n) - p[P_C_PN] * (vx_p - vx_n)
    fy = -p[P_K_PN] * (y_p - y_n) - p[P_C_PN] * (vy_p - vy_n)
    dy[v0 + Q_XP] += fx
    dy[v0 + Q_YP] += fy
    dy[v0 + Q_XN] -= fx
    dy[v0 + Q_YN] -= fy
    t_pn = -p[P_C_PND] * (w_p - w_n)
    dy[v0 + Q_THP] += t_pn
    dy[v0 + Q_THN] -= t_pn
    load = axial_load(t, load_knots, p[P_LOAD_SIN_AMP], p[P_LOAD_SIN_FREQ])
    dv_nut = vz_n - p[P_V_NUT_REF]
    dy[v0 + Q_ZN] += -load - p[P_C_NA] * dv_nut
    p_diss += (
        p[P_C_S] * (vx_s * vx_s + vy_s * vy_s)
        + p[P_C_N] * (vx_n * vx_n + vy_n * vy_n)
        + p[P_C_ND] * w_n * w_n
        + p[P_C_PN] * ((vx_p - vx_n) ** 2 + (vy_p - vy_n) ** 2)
        + p[P_C_PND] * (w_p - w_n) ** 2
        + p[P_C_NA] * dv_nut * vz_n
        + p[P_C_SD] * w_s * w_s
    )

    # ---------------- screw drive
    j_s = p[P_J_S]
    if prescribed:
        drive = j_s * alpha_ref - torque_screw + p[P_C_SD] * w_s
        dy[v0 + Q_THS] = alpha_ref
    else:
        w_ref = screw_motion(t, motion)[1]
        drive = p[P_KP] * (w_ref - w_s) + p[P_KI] * y[2 * nq + X_SPEED_INT]
        limit = p[P_TORQUE_LIMIT]
        if drive > limit:
            drive = limit
        elif drive < -limit:
            drive = -limit
        dy[v0 + Q_THS] = (drive + torque_screw - p[P_C_SD] * w_s) / j_s
        dy[2 * nq + X_SPEED_INT] = w_ref - w_s

    # ---------------- accelerations
    m_s, m_n, m_p, m_c = p[P_M_S], p[P_M_N], p[P_M_P], p[P_M_C]
    dy[v0 + Q_XS] /= m_s
    dy[v0 + Q_YS] /= m_s
    dy[v0 + Q_XN] /= m_n
    dy[v0 + Q_YN] /= m_n
    dy[v0 + Q_THN] /= p[P_J_N]
    dy[v0 + Q_ZN] /= m_n
    dy[v0 + Q_XP] /= m_p
    dy[v0 + Q_YP] /= m_p
    dy[v0 + Q_THP] /= p[P_J_P]
    for i in range(n_rollers):
        b = v0 + Q_ROLLER0 + ROLLER_DOF * i
        dy[b] /= m_c
        dy[b + 1] /= m_c
        dy[b + 2] /= p[P_J_C]
        dy[b + 3] /= m_c

    e0 = 2 * nq
    p_drive = drive * w_s
    p_load = -load * vz_n
    dy[e0 + X_W_DRIVE] = p_drive
    dy[e0 + X_W_LOAD] = p_load
    dy[e0 + X_W_DISS] = p_diss + p_fric
    dy[e0 + X_W_FRIC] = p_fric
    aux[A_DRIVE_TORQUE] = drive
    aux[A_FRICTION_TORQUE] = friction_torque
    aux[A_AXIAL_LOAD] = load
    aux[A_P_DRIVE] = p_drive
    aux[A_P_LOAD] = p_load
    aux[A_P_DISS] = p_diss + p_fric
    aux[A_P_FRIC] = p_fric


@njit(cache=True)
def _record(y, dy, aux, p, nq, out_row):
    v0 = nq
    out_row[C_SCREW_ANGLE] = y[Q_THS]
    out_row[C_SCREW_SPEED] = y[v0 + Q_THS]
    out_row[C_CARRIER_SPEED] = y[v0 + Q_THP]
    out_row[C_NUT_POSITION] = y[Q_ZN]
    out_row[C_NUT_AXIAL_ACCEL] = dy[v0 + Q_ZN]
    out_row[C_NUT_TANGENTIAL_ACCEL] = p[P_R_NUT] * dy[v0 + Q_THN]
    out_row[C_NUT_RADIAL_X_ACCEL] = dy[v0 + Q_XN]
    out_row[C_NUT_RADIAL_Y_ACCEL] = dy[v0 + Q_YN]
    out_row[C_DRIVE_TORQUE] = aux[A_DRIVE_TORQUE]
    out_row[C_FRICTION_TORQUE] = aux[A_FRICTION_TORQUE]
    out_row[C_AXIAL_LOAD] = aux[A_AXIAL_LOAD]


@njit(cache=True)
def _clamp_traction(y, p, nq, aux, n_rollers):
    # A stuck contact cannot hold more than its Coulomb limit: when the normal load drops, the
    # elastic tangential displacement resets to the limit and its released energy is dissipated.
    k_tan = p[P_K_TAN]
    s0 = 2 * nq + N_EXTRA
    for i in range(n_rollers):
        limit = aux[N_AUX + i] / k_tan
        slip = y[s0 + i]
        if slip > limit or slip < -limit:
            new = limit if slip > 0.0 else -limit
            released = 0.5 * k_tan * (slip * slip - new * new)
            y[s0 + i] = new
            y[2 * nq + X_W_DISS] += released
            y[2 * nq + X_W_FRIC] += released


@njit(cache=True)
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
    out,
    k1,
    k2,
    k3,
    k4,
    tmp,
    aux,
):
    """Advance ``y`` in place by ``n_steps`` RK4 steps of ``h``; record every ``record_every``.

    Records the channels at the start of each recorded step into ``out`` (rows). Returns
    (status, step): status 0 = done, 1 = non-finite state detected at ``step``.
    Work arrays k1…k4, tmp, aux are passed in so the loop allocates nothing.
    """
    n_state = y.shape[0]
    nq = Q_ROLLER0 + ROLLER_DOF * rollers.shape[0]
    prescribed = p[P_DRIVE_MODE] == DRIVE_PRESCRIBED
    row = 0
    half = 0.5 * h
    for step in range(n_steps):
        t = t0 + step * h
        if prescribed:
            th, w, _ = screw_motion(t, motion)
            y[Q_THS] = th
            y[nq + Q_THS] = w
        rhs(t, y, p, rollers, mesh_table, motion, load_knots, k1, aux)
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
        rhs(t + half, tmp, p, rollers, mesh_table, motion, load_knots, k2, aux)
        for j in range(n_state):
            tmp[j] = y[j] + half * k2[j]
        rhs(t + half, tmp, p, rollers, mesh_table, motion, load_knots, k3, aux)
        for j in range(n_state):
            tmp[j] = y[j] + h * k3[j]
        rhs(t + h, tmp, p, rollers, mesh_table, motion, load_knots, k4, aux)
        for j in range(n_state):
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        _clamp_traction(y, p, nq, aux, rollers.shape[0])
    if prescribed:
        th, w, _ = screw_motion(t0 + n_steps * h, motion)
        y[Q_THS] = th
        y[nq + Q_THS] = w
    for j in range(2 * nq):
        if not math.isfinite(y[j]):
            return 1, n_steps
    return 0, n_steps
