"""Index layout of the flat float64 arrays shared by the dynamics kernel and its Python side.

Plain integers only, so numba folds them as compile-time constants. The physical meaning of
every entry is documented in :mod:`prsm_health.simulation.dynamics.model`, which fills them.
"""

# ----------------------------------------------------------------- generalised coordinates q
# Screw: lateral x, y and rotation θ_s.
Q_XS, Q_YS, Q_THS = 0, 1, 2
# Nut (with ring gear): lateral x, y, rotation θ_N, axial z_N.
Q_XN, Q_YN, Q_THN, Q_ZN = 3, 4, 5, 6
# Carrier: lateral x, y, rotation θ_p.
Q_XP, Q_YP, Q_THP = 7, 8, 9
# Drive train: motor rotor angle θ_m, screw axial z_s (on its thrust bearing), payload z_L.
Q_THM, Q_ZS, Q_ZL = 10, 11, 12
# Roller i occupies Q_ROLLER0 + 4·i + (0: X, 1: Y absolute centre position, 2: spin θ, 3: axial z).
Q_ROLLER0 = 13
ROLLER_DOF = 4


def n_coordinates(n_rollers: int) -> int:
    return Q_ROLLER0 + ROLLER_DOF * n_rollers


# Extra integrated quantities appended after [q, q̇]: cumulative energies [J] for the power
# balance and the speed-loop integrator state. After them, two traction states per roller: the
# elastic tangential displacements [m] of its screw–roller contacts (rollers 0…n−1), then of its
# roller–nut contacts (n…2n−1).
X_W_DRIVE, X_W_LOAD, X_W_DISS, X_W_FRIC, X_SPEED_INT = 0, 1, 2, 3, 4
N_EXTRA = 5
#: The extra states that are the energy book (a run starts its own at 0).
ENERGY_STATES = (X_W_DRIVE, X_W_LOAD, X_W_DISS, X_W_FRIC)
#: Traction states per roller: screw side, nut side.
N_TRACTION = 2


def n_state(n_rollers: int) -> int:
    return 2 * n_coordinates(n_rollers) + N_EXTRA + N_TRACTION * n_rollers


# ----------------------------------------------------------------- scalar parameters p
P_M_S, P_J_S, P_M_N, P_J_N, P_M_P, P_J_P, P_M_C, P_J_C = 0, 1, 2, 3, 4, 5, 6, 7
P_ORBIT_R = 8  # nominal roller-centre orbit radius R = r_s + r_r [m]
P_RB_RING = 9  # ring-gear base radius [m]
P_RB_ROLLER = 10  # roller-gear base radius [m]
P_COS_A0, P_SIN_A0 = 11, 12  # gear pressure angle
P_COT_BETA = 13  # radial-to-axial closure factor of a thread flank, cot β
P_LEAD_S, P_LEAD_R, P_LEAD_N = 14, 15, 16  # leads over 2π [m/rad]
P_Z_RING = 17
P_R_NUT, P_R_SCREW, P_R_ROLLER = 18, 19, 20  # pitch radii [m]
P_K_THREAD_S, P_K_THREAD_N = 21, 22  # axial contact law coefficient per roller side
P_EXPONENT = 23  # 1 (linear) or 1.5 (Hertzian) flank law
P_C_THREAD_S, P_C_THREAD_N, P_C_MESH = 24, 25, 26
P_K_S, P_C_S = 27, 28  # screw lateral support
P_K_N, P_C_N = 29, 30  # nut lateral guide
P_K_ND, P_C_ND = 31, 32  # nut anti-rotation
P_K_PN, P_C_PN = 33, 34  # carrier–nut lateral coupling
P_C_PND = 35  # carrier–nut rotational damping [N·m·s/rad]
P_K_CP, P_C_CP = 36, 37  # roller pocket in the carrier
P_C_NA = 38  # nut axial damping to ground [N·s/m]
P_C_SD = 39  # screw rotational damping [N·m·s/rad]
P_MU_VISC, P_MU_COUL, P_K_TAN, P_FRICTION_SCALE = 40, 41, 42, 43
P_DRIVE_MODE = 44  # 0 prescribed screw motion, 1 speed loop
P_KP, P_KI, P_TORQUE_LIMIT = 45, 46, 47
P_LOAD_SIN_AMP, P_LOAD_SIN_FREQ = 48, 49
P_SIN_BETA = 50
P_C_TAN = 51  # damping of the tangential contact compliance while sticking [N·s/m]
P_V_NUT_REF = 52  # reference speed of the nut axial damper (0: guide friction to ground) [m/s]
P_MU_ROLL = 53  # differential-sliding coefficient μ3 of paper 02 [m]
P_V_AXIAL = 54  # regularisation speed of the axial Coulomb sliding [m/s]
P_W_ROLL = 55  # regularisation speed of the differential-sliding torque [rad/s]
P_LEAD_EFF = 56  # effective lead per radian (nut travel per screw radian) [m/rad]
# Drive train (prsm_health.actuator.drive_train)
P_J_M = 57  # motor rotor inertia [kg·m²]
P_COUPLED = 58  # 0: screw rigidly on the motor, 1: torsional coupling
P_K_COUP, P_C_COUP = 59, 60  # coupling [N·m/rad], [N·m·s/rad]
P_AXIAL_FREE = 61  # 0: screw axially fixed, 1: on its thrust bearing
P_K_BEAR, P_C_BEAR, P_BEAR_PLAY = 62, 63, 64  # thrust bearing [N/m], [N·s/m], half play [m]
P_ON_PAYLOAD = 65  # 0: load on the nut (ideal force), 1: on the payload through the linkage
P_M_L, P_K_LINK, P_C_LINK = 66, 67, 68  # payload [kg], linkage [N/m], [N·s/m]
P_C_FILM = 69  # lubricant squeeze-film damper, nut vs screw kinematics [N·s/m]
P_KP_POS = 70  # position-loop gain [1/s]
P_LEAD_SLOPE = 71  # cumulative lead error of the screw, axial error per axial travel [-]
P_HAS_SPALLS = 72  # 1 when the health state has a spall: only then the spall tables are read
P_HAS_TOOTH_DAMAGE = 73  # 1 when a gear tooth is damaged: only then the tooth tables are read
P_STRIBECK = 74  # 1: the Coulomb coefficient follows the lubrication regime (ERR_COULOMB)
# Spalls: the share of an engagement's thread turns that the spalled turn is (1/n_t); the
# screw spall's axial gate (centre on z_c − z_s, half the engaged length, ramp of one pitch);
# which flanks carry the screw and the nut spall (1/0 for the plus and the minus flank).
P_SPALL_SHARE, P_SPALL_Z, P_SPALL_HALF, P_SPALL_RAMP = 75, 76, 77, 78
P_SPALL_PLUS_S, P_SPALL_MINUS_S, P_SPALL_PLUS_N, P_SPALL_MINUS_N = 79, 80, 81, 82
# Reduction between motor and screw (drive_train.gear_*): 1 when there is one (else the direct
# drive's code path, unchanged); ratio N (motor turns per screw turn; 1.0 without one); mesh
# efficiency η; half-backlash at the output [rad]; mesh cycles per motor revolution; amplitude of
# the transmission error at that order as an output angle [rad]; regularisation speed of the
# direction-dependent mesh loss [rad/s of the motor]. The gear's stiffness is in series with the
# coupling's in P_K_COUP, its input inertia in P_J_M.
P_GEARED, P_RATIO, P_GEAR_EFFICIENCY, P_GEAR_BACKLASH = 83, 84, 85, 86
P_MESH_ORDER, P_GEAR_TE, P_W_GEAR = 87, 88, 89
N_PARAMS = 90

DRIVE_PRESCRIBED, DRIVE_SPEED_LOOP, DRIVE_POSITION_LOOP = 0, 1, 2

# ----------------------------------------------------------------- geometric error tables
# One row per kind: column 0 the reciprocal 1/P of the error profile's period P [rad] (the
# kernel multiplies: a division per lookup was a measurable share of a step), columns 1…N its values
# [m] at u = P·k/N, interpolated linearly (the kernel's slope is that of the interpolant, so
# forces and energy stay consistent). The contact coordinate u of each kind:
#   screw axial / radial: u = θ_rev + ψ_i − θ_s (where roller i touches the screw surface),
#   nut axial: u = θ_rev + ψ_i − θ_N (where it touches the nut), gear: u = θ_p + ψ_i − θ_N.
# The last row is cos u over one turn: the roller runout's cos and −sin by one lookup, far
# cheaper than two trigonometric calls per roller and side.
ERR_SCREW_AXIAL, ERR_SCREW_RADIAL, ERR_NUT_AXIAL, ERR_GEAR, ERR_UNIT_COSINE = 0, 1, 2, 3, 4
# Localised flank defects (spalls): the depth [m] of the flank's profile depression at the
# contact coordinate, added to the local clearance of both flanks of that engagement. Screw:
# u as screw axial; nut: u as nut axial; roller: the spin angle χ = θ_c − θ_rev of the roller
# that carries it (R_SPALL), facing the nut at χ and the screw at χ + π.
ERR_SCREW_SPALL, ERR_NUT_SPALL, ERR_ROLLER_SPALL = 5, 6, 7
# Gear tooth damage: the mesh stiffness ratio − 1 (damaged over healthy) of the mesh as a
# function of its phase [cycles], over one turn of the ring gear (z_ring cycles: which ring
# tooth is in mesh) and over one turn of the roller gear (z_roller cycles: which of the roller's
# teeth), the latter only for the roller that carries the damage (R_TOOTH).
ERR_RING_TOOTH, ERR_ROLLER_TOOTH = 8, 9
# Coulomb coefficient of the screw–roller contacts vs entrainment speed [m/s], not periodic:
# column 0 holds the reciprocal of the highest tabulated speed, beyond which the last value
# holds.
ERR_COULOMB = 10
N_ERROR_KINDS = 11
#: Points per table: a power of two (the kernel wraps indices by a bit mask).
N_ERROR_POINTS = 16384
#: Points of the healthy mesh-stiffness table over one mesh cycle: a power of two, as above.
MESH_POINTS = 512

# ----------------------------------------------------------------- per-roller parameters
R_COS_PSI, R_SIN_PSI = 0, 1  # angular position of the pocket on the carrier
R_POCKET_R = 2  # pocket radius (orbit radius + eccentricity) [m]
R_B_S, R_B_N, R_B_G = 3, 4, 5  # half-clearance on each flank: screw, nut threads, gear [m]
R_E_S, R_E_N = 6, 7  # axial position error of the roller thread vs screw / nut [m]
R_E_G = 8  # gear transmission error offset [m]
R_MESH_PHASE = 9  # mesh phase error added to the geometric phase [cycles]
R_MESH_SCALE = 10  # mesh stiffness scale (tooth-to-tooth variation) [-]
R_PSI = 11  # angular position of the pocket [rad]
R_RUNOUT, R_RUNOUT_PHASE = 12, 13  # roller thread runout about its spin axis [m], phase [rad]
R_SPALL = 14  # 1 for the roller carrying the roller-flank spall, else 0
R_TOOTH = 15  # 1 for the roller whose gear carries the damaged tooth, else 0
# Thread rolling (traction) of the roller on the screw and on the nut: the roller's effective
# rolling radius at each contact [m] (the nut-side one carries the roller's pitch mismatch ε
# against its gear: r_r/(1 + ε)); the nut-side tangential stiffness [N/m] and damping [N·s/m];
# the inverse relaxation length of each side's traction [1/m]; ε itself [-] (a run label).
R_ROLL_S, R_ROLL_N = 16, 17
R_K_TAN_N, R_C_TAN_N = 18, 19
R_RELAX_S, R_RELAX_N = 20, 21
R_MISMATCH = 22
N_ROLLER_PARAMS = 23

# ----------------------------------------------------------------- recorded truth signals
(
    C_MOTOR_ANGLE,
    C_MOTOR_SPEED,
    C_MOTOR_TORQUE,
    C_SCREW_ANGLE,
    C_SCREW_SPEED,
    C_CARRIER_SPEED,
    C_NUT_POSITION,
    C_NUT_AXIAL_ACCEL,
    C_NUT_TANGENTIAL_ACCEL,
    C_NUT_RADIAL_X_ACCEL,
    C_NUT_RADIAL_Y_ACCEL,
    C_FRICTION_TORQUE,
    C_AXIAL_LOAD,
    C_PAYLOAD_POSITION,
    C_SCREW_AXIAL_POSITION,
    C_LOAD_FORCE,
) = range(16)
N_CHANNELS = 16
# Names, units and meanings: prsm_health.core.channels.TRUTH_CHANNELS (same order); every measured
# channel is a sensor's reading of one of them (prsm_health.simulation.instrumentation).

# Auxiliary outputs of one right-hand-side evaluation; after them, blocks of one value per
# roller (block k at N_AUX + k·n_rollers + i): the Coulomb limit μ·N of its screw–roller
# traction [N], of its roller–nut traction [N], its gear mesh force along the line of action
# (> 0 on the drive flank) [N], its screw-side and nut-side traction forces on the roller
# (along e_t) [N].
(
    A_MOTOR_TORQUE,
    A_FRICTION_TORQUE,
    A_AXIAL_LOAD,
    A_P_DRIVE,
    A_P_LOAD,
    A_P_DISS,
    A_P_FRIC,
    A_LOAD_FORCE,
) = range(8)
N_AUX = 8


AR_CAP_S, AR_CAP_N, AR_GEAR, AR_TRACTION_S, AR_TRACTION_N = 0, 1, 2, 3, 4
N_AUX_PER_ROLLER = 5


def n_aux(n_rollers: int) -> int:
    return N_AUX + N_AUX_PER_ROLLER * n_rollers
