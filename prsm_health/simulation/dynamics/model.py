"""The PRSM lumped-parameter model of paper 01: parameters, state layout and initial state.

Degrees of freedom (:mod:`.layout`): screw x, y, θ_s (axially fixed; θ_s prescribed or driven
by a speed loop); nut with ring gear x, y, θ_N, z_N; carrier x, y, θ_p; each roller i its
absolute centre position X_i, Y_i, spin θ_i and axial z_i — 10 + 4·n_r coordinates, as in
paper 01 §1.1 (screw z constrained).

Force laws (one energy function; kernel in :mod:`._kernels`):

* **Threads** (paper 01 §1.2.2 with the helix built into the deformation,
  docs/validation.md): with θ_rev the angular position of the roller centre
  about the screw (nut) axis and L the leads,
  screw side δ_s = L_s/2π·(θ_s − θ_rev) − L_r/2π·(θ_i − θ_rev) − z_i,
  nut side δ_N = z_i − z_N + L_r/2π·(θ_i − θ_rev) − L_N/2π·(θ_N − θ_rev).
  Each flank closes by ±δ + cot β·a, with a the radial approach of roller and screw (nut), and
  carries F = k·(closure − b) (linear) or k·(closure − b)^1.5 (Hertzian) beyond the per-roller
  half-clearance b (paper 01's f(δ, b)). Axial, tangential (helix) and radial forces, and the
  torques, are the derivatives of that one energy, so torque balance and the rigid-body speed
  ratio r_s/(2(r_s + r_r)) hold exactly. Departure: paper 01 imposes F_sd = f(F_sa·tan λ) as a
  given force, which breaks torque balance (speed ratio 4.0 at 1 rad/s) — docs/validation.md.
* **Gear mesh** (paper 01 δ_Nci): δ_g = r_bN θ_N − r_br θ_i − cos α0 (R φ_i + τ_i)
  + sin α0 (ρ_i − R) along the line of action Ψ_Ng = π/2 + α0 + φ_i, with the time-varying mesh
  stiffness of :mod:`prsm_health.physics.stiffness.gear_mesh` tabulated over one mesh cycle at phase
  z_ring·(φ_i − θ_N)/2π — each roller at its geometric mesh phase — and backlash b_g.
* **Friction** at the screw–roller contact: regularised Coulomb μ·N·tanh(v/v_reg) plus viscous
  μ_sc·v (paper 01 table: μ_sc = 25 N·s/m) on the sliding speed
  v = r_s(ω_s − ω_rev) + r_r(ω_i − ω_rev), times the health state's friction scale. Both thread
  contacts carry a creeping traction (Mindlin stiffness, relaxation length from Kalker's linear
  theory, capped at μN); the gear takes the pitch mismatch between its ratio and the nut
  thread's rolling ratio (:mod:`prsm_health.physics.rolling_mismatch`; Jones & Velinsky 2012).
* **Supports** (paper 01 K_s, K_N, K_pN, K_cp; values not given — engineering defaults
  below), linear with damping set by damping ratios.
* **Drive train** (:mod:`prsm_health.actuator.drive_train`, beyond paper 01): motor rotor θ_m driving
  the screw through a torsional coupling; screw axial z_s on its thrust bearing (stiffness,
  optional play); nut anti-rotation guide; the load acting on a payload z_L tied to the nut by
  a linkage spring–damper. ``DriveTrain.paper01()`` restores the paper's rigid screw drive,
  axially fixed screw and ideal force on the nut.
* **Contact damping**: each flank carries material (hysteretic) damping at
  ``contact_damping_ratio`` of the nut axial mode; the lubricant film in the thread gaps adds a
  squeeze-film damper on the nut's axial motion relative to the screw's kinematic position,
  sized so that a nut impact on its threads rebounds with the coefficient of restitution
  ``contact_restitution`` e: ζ = −ln e / √(π² + ln² e) of the nut axial mode. Dry steel at
  low speed has e ≈ 0.9 (Goldsmith, *Impact*, 1960); a lubricant film lowers it, the more the
  slower the impact (Davis, Serayssol & Hinch 1986, J. Fluid Mech. 163; Joseph et al. 2001,
  J. Fluid Mech. 433): range 0.3–0.9, default 0.6 (engineering estimate). The film damper acts
  on the nut alone because the rollers' own modes are 30× faster: putting the same damping in
  each flank would make them stiff for the explicit integrator (docs/performance.md).
* **Geometric errors along the screw** (:class:`~prsm_health.actuator.states.ManufacturingVariation`):
  cumulative and periodic lead error (ISO 3408-3 grade), screw and roller runout, ring-gear
  pitch and profile error (transmission-error harmonics), flank waviness; each enters the
  closures as a function of where the roller touches the part.

References
----------
Paper 01 (docs/references.md), §1.2–1.3 (equations of
motion), §2 (stiffness), §3 parameter table.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from functools import lru_cache

import numpy as np

from prsm_health.actuator.assembly import RollerDraws, variation_stream
from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.faults import FATIGUE
from prsm_health.actuator.states import HealthState, ManufacturingVariation, OperatingProfile
from prsm_health.core.errors import require, require_positive, require_range
from prsm_health.physics.friction import FrictionParameters
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.lubrication import DEFAULT_LUBRICANT, lubricant

from . import layout as L
from .tables import coulomb_table, error_terms, spall_params, tooth_tables

CONTACT_LAWS = ("linear", "hertz")
LUBRICATION_MODELS = ("regime", "constant")

#: The automatic RK4 step [s] stays below both of these: a fraction of the model's stable step
#: (itself 0.9 of RK4's limit) and an absolute bound. Near the limit RK4 damps and detunes the
#: stiff contact modes. Measured on a kicked, lightly damped nut (tests/dynamics, the axial-mode
#: case): its axial RMS moved +2 % at 0.60 of the stable step, +22 % at 0.71, +130 % at 0.85;
#: with impacts and noise the indicators at ≤ 0.71 stayed within their seed-to-seed scatter of
#: a 0.5 µs reference (docs/performance.md, ``python tools/studies/step_accuracy.py``).
AUTO_STABLE_FRACTION = 0.6
AUTO_MAX_STEP = 10e-6
#: Paper 02's friction table, the one source of the simulator's Coulomb and rolling defaults.
_PAPER02_FRICTION = FrictionParameters.paper02()


@dataclass(frozen=True)
class SimulationOptions:
    """Numerical and modelling options (defaults documented where the paper is silent).

    Parameters
    ----------
    max_step : float [s] or "auto"
        Largest RK4 step; the step used is the largest 1/(m·f_s) below it, refused when above
        the model's stable step. ``"auto"`` (default): the largest 1/(m·f_s) below both
        :data:`AUTO_STABLE_FRACTION` of the stable step
        (:func:`~prsm_health.simulation.dynamics.simulate.max_stable_step`) and :data:`AUTO_MAX_STEP` — as fast as the model allows, and it survives stiff damping
        (docs/performance.md: the indicators it gives against a 0.5 µs reference).
    contact_law : {"linear", "hertz"}
        Thread flank law: linearised at the operating load, or Hertzian F = c·δ^1.5.
    variation : ManufacturingVariation
        As-built roller scatter (``ManufacturingVariation.ideal()`` to switch it off).
    contact_damping_ratio : float [-]
        Material damping of the contacts: ratio of the nut axial mode given by the thread
        flanks (stiffness-proportional) and of the gear mesh (c = 2ζ√(k·J_r/r_b²)).
    contact_restitution : float [-]
        Coefficient of restitution of a nut impact on its threads, set by the lubricant film
        (module docstring): 0.3–0.9.
    settle_time : float [s]
        Simulated before t = 0 at the initial speed and load and discarded, so the start-up
        transient of the as-built rollers finding their load share is not in the run. The motor
        follows the prescribed motion meanwhile; a speed or position loop takes over at t = 0
        holding the settling's mean drive torque.
    support_damping_ratio : float [-]
        Damping ratio of bearings, guides and pockets.
    lubrication : {"regime", "constant"}
        "regime": the Coulomb coefficient of the screw–roller contacts follows the lubrication
        regime at each contact's entrainment speed (:mod:`prsm_health.physics.lubrication`: film
        thickness, asperity load share, boundary and film friction; the health state's
        lubricant degradation and starvation, the profile's temperature). "constant":
        ``friction_coefficient`` throughout (papers 01 and 02's model).
    lubricant : str
        Built-in lubricant (:data:`prsm_health.physics.lubrication.LUBRICANTS`) for "regime".
    friction_coefficient : float [-]
        Coulomb coefficient of screw–roller sliding with ``lubrication = "constant"`` (paper
        02: μ2 = 0.1), for the traction limit and the axial sliding of the rollers on the screw.
    rolling_friction : float [m]
        Differential-sliding coefficient μ3 of paper 02 (1.5e-6 m).
    viscous_friction : float [N·s/m]
        Paper 01 table: μ_sc = 25 N·s/m.
    traction_stiffness_ratio : float [-]
        Tangential stiffness of the screw–roller traction over its normal stiffness; Mindlin's
        2(1 − ν)/(2 − ν) = 0.82 for steel. It holds the rollers rolling on the screw while the
        traction stays below μN, as creep does on real hardware.
    screw_support_stiffness, nut_guide_stiffness, carrier_nut_stiffness, pocket_stiffness : float [N/m]
    nut_guide_damping : float [N·s/m]
        Viscous friction of the nut's linear guide against the ground (paper 01's C_Na).
    threaded_tooth : bool
        Use paper 01's threaded roller tooth in the gear mesh stiffness.
    operating_load : float or None [N]
        Load at which the linear thread law is linearised; None: the profile's peak load
        (at least 20 N, so an unloaded run keeps a finite stiffness).
    """

    max_step: float | str = "auto"
    settle_time: float = 0.03
    contact_law: str = "linear"
    variation: ManufacturingVariation = field(default_factory=ManufacturingVariation)
    contact_damping_ratio: float = 0.03
    contact_restitution: float = 0.6
    support_damping_ratio: float = 0.05
    lubrication: str = "regime"
    lubricant: str = DEFAULT_LUBRICANT
    friction_coefficient: float = _PAPER02_FRICTION.sliding
    rolling_friction: float = _PAPER02_FRICTION.rolling
    viscous_friction: float = 25.0
    traction_stiffness_ratio: float = 0.82
    screw_support_stiffness: float = 1e8
    nut_guide_stiffness: float = 1e8
    carrier_nut_stiffness: float = 1e7
    pocket_stiffness: float = 1e8
    nut_guide_damping: float = 5.0
    threaded_tooth: bool = True
    operating_load: float | None = None

    def __post_init__(self):
        if self.max_step != "auto":
            step = self.max_step
            require(
                isinstance(step, (int, float))
                and not isinstance(step, bool)
                and 1e-8 <= step <= 1e-4,
                "options.max_step",
                step,
                '"auto" or a step in [1e-08, 0.0001] s',
            )
        require_range("options.settle_time", self.settle_time, 0.0, 10.0, unit="s")
        require(
            self.contact_law in CONTACT_LAWS,
            "options.contact_law",
            self.contact_law,
            f"must be one of {', '.join(CONTACT_LAWS)}",
        )
        require_range("options.contact_damping_ratio", self.contact_damping_ratio, 0.0, 1.0)
        require_range("options.contact_restitution", self.contact_restitution, 0.05, 1.0)
        require_range("options.support_damping_ratio", self.support_damping_ratio, 0.0, 1.0)
        require(
            self.lubrication in LUBRICATION_MODELS,
            "options.lubrication",
            self.lubrication,
            f"must be one of {', '.join(LUBRICATION_MODELS)}",
        )
        lubricant(self.lubricant)  # a known name, or the error naming the choices
        require_range("options.friction_coefficient", self.friction_coefficient, 0.0, 1.0)
        require_range("options.rolling_friction", self.rolling_friction, 0.0, 1e-3, unit="m")
        require_range("options.viscous_friction", self.viscous_friction, 0.0, 1e5, unit="N·s/m")
        require_range("options.traction_stiffness_ratio", self.traction_stiffness_ratio, 0.01, 1.0)
        for name in (
            "screw_support_stiffness",
            "nut_guide_stiffness",
            "carrier_nut_stiffness",
            "pocket_stiffness",
        ):
            require_positive(f"options.{name}", getattr(self, name))
        require_range("options.nut_guide_damping", self.nut_guide_damping, 0.0, 1e5, unit="N·s/m")
        if self.operating_load is not None:
            require_positive("options.operating_load", self.operating_load)

    def as_dict(self) -> dict:
        d = asdict(self)
        d["variation"] = self.variation.as_dict()
        return d


@dataclass
class Model:
    """Everything the kernel needs, as flat float64 arrays, plus what built them."""

    design: PRSMDesign
    health: HealthState
    profile: OperatingProfile
    options: SimulationOptions
    drive_train: DriveTrain
    params: np.ndarray  # (N_PARAMS,)
    rollers: np.ndarray  # (n_rollers, N_ROLLER_PARAMS)
    mesh_table: np.ndarray  # (n_points,) mesh stiffness over one cycle [N/m]
    motion: np.ndarray  # (3, K) screw speed knots
    load_knots: np.ndarray  # (2, K)
    errors: np.ndarray  # (N_ERROR_KINDS, 1 + N_ERROR_POINTS) geometric error tables
    thread_stiffness: tuple[float, float]  # linearised axial stiffness per roller side [N/m]
    roller_load: float  # per-roller axial load the laws are built around [N]

    @property
    def n_rollers(self) -> int:
        return self.rollers.shape[0]

    @property
    def n_coordinates(self) -> int:
        return L.n_coordinates(self.n_rollers)

    @property
    def n_state(self) -> int:
        return L.n_state(self.n_rollers)


def _thread_laws(
    design: PRSMDesign, roller_load: float, law: str
) -> tuple[list[float], list[float]]:
    """Per roller side: the law coefficient for the kernel and the tangent stiffness [N/m]."""
    from prsm_health.physics.stiffness.thread_load import roller_side_stiffness

    coefficients, tangents = [], []
    for side in ("screw", "nut"):
        k_tan = float(roller_side_stiffness(design, roller_load, side))
        tangents.append(k_tan)
        if law == "linear":
            coefficients.append(k_tan)
        else:
            # Least-squares c of F = c·δ^1.5 over 0.1…3 × the operating load (log-spaced).
            loads = np.geomspace(0.1, 3.0, 25) * roller_load
            deflections = np.interp(loads, _force_curve(design, side), _DEFLECTION_GRID)
            basis = deflections**1.5
            coefficients.append(float(np.dot(basis, loads) / np.dot(basis, basis)))
    return coefficients, tangents


#: Deflections [m] at which a roller side's force–deflection curve is tabulated (inverted by
#: interpolation: the curve is monotone).
_DEFLECTION_GRID = np.geomspace(1e-10, 1e-3, 400)


@lru_cache(maxsize=32)
def _force_curve(design: PRSMDesign, side: str) -> np.ndarray:
    """Force [N] of one roller side at :data:`_DEFLECTION_GRID`, per design (a frozen,
    hashable dataclass): ≈ 45 ms of thread-load solves that every run of a dataset repeated."""
    from prsm_health.physics.stiffness.thread_load import roller_side_force

    forces = np.asarray(roller_side_force(design, _DEFLECTION_GRID, side), dtype=float)
    forces.flags.writeable = False  # shared by every caller of the cache
    return forces


@lru_cache(maxsize=32)
def _mesh_table(design: PRSMDesign, threaded_tooth: bool) -> np.ndarray:
    """Healthy mesh stiffness over one cycle [N/m], per design: ≈ 20 ms of tooth compliance
    integrals that every run of a dataset repeated. Read-only (shared by every caller; the
    kernel's signature already has it so)."""
    from prsm_health.physics.stiffness.gear_mesh import design_mesh_stiffness

    table = np.array(
        design_mesh_stiffness(
            design, threaded_tooth=threaded_tooth, n_points=L.MESH_POINTS
        ).stiffness,
        dtype=float,
    )
    table.flags.writeable = False
    return table


def build_model(
    design: PRSMDesign,
    health: HealthState,
    profile: OperatingProfile,
    options: SimulationOptions,
    seed: int,
    drive_train: DriveTrain | None = None,
) -> Model:
    """Pack design, health state, profile, options and drive train into kernel arrays.

    Parameters
    ----------
    design : PRSMDesign
    health : HealthState
    profile : OperatingProfile
    options : SimulationOptions
    seed : int
        Seeds the manufacturing variation and the uneven wear.
    drive_train : DriveTrain, default DriveTrain()
    """
    drive_train = drive_train or DriveTrain()
    require(
        design.gear is not None,
        "design",
        design.name,
        "the dynamic model needs a standard PRSM with gears",
    )
    n = design.n_rollers
    load_knots, amp, freq = profile.load_knots()
    peak_load = float(np.max(np.abs(load_knots[1]))) + amp
    operating = options.operating_load or max(peak_load, 20.0)
    roller_load = operating / n
    coefficients, tangents = _thread_laws(design, roller_load, options.contact_law)
    mesh = _mesh_table(design, options.threaded_tooth)

    m = design.masses
    gear = design.gear
    r_s, r_r, r_n = design.screw_diameter / 2, design.roller_diameter / 2, design.nut_diameter / 2
    orbit = r_s + r_r
    zeta_c, zeta_s = options.contact_damping_ratio, options.support_damping_ratio
    rb_roller = r_r * math.cos(gear.pressure_angle)

    p = np.zeros(L.N_PARAMS)
    p[L.P_M_S], p[L.P_J_S] = m.screw_mass, m.screw_inertia
    p[L.P_M_N], p[L.P_J_N] = m.nut_mass, m.nut_inertia
    p[L.P_M_P], p[L.P_J_P] = m.carrier_mass, m.carrier_inertia
    p[L.P_M_C], p[L.P_J_C] = m.roller_mass, m.roller_inertia
    p[L.P_ORBIT_R] = orbit
    p[L.P_RB_RING] = r_n * math.cos(gear.pressure_angle)
    p[L.P_RB_ROLLER] = rb_roller
    p[L.P_COS_A0], p[L.P_SIN_A0] = math.cos(gear.pressure_angle), math.sin(gear.pressure_angle)
    p[L.P_COT_BETA] = 1.0 / math.tan(design.contact_angle)
    p[L.P_SIN_BETA] = math.sin(design.contact_angle)
    p[L.P_LEAD_S] = design.screw_lead / (2 * math.pi)
    p[L.P_LEAD_R] = design.roller_lead / (2 * math.pi)
    p[L.P_LEAD_N] = design.nut_lead / (2 * math.pi)
    p[L.P_Z_RING] = gear.ring_teeth
    p[L.P_R_NUT], p[L.P_R_SCREW], p[L.P_R_ROLLER] = r_n, r_s, r_r
    p[L.P_K_THREAD_S], p[L.P_K_THREAD_N] = coefficients
    p[L.P_EXPONENT] = 1.0 if options.contact_law == "linear" else 1.5
    # Thread contact damping proportional to stiffness, c = 2ζk/ω_ax, so the nut axial mode
    # ω_ax = √(k_axial/m_N) has the damping ratio ζ and the stiffer local roller modes more.
    k_axial = n * tangents[0] * tangents[1] / (tangents[0] + tangents[1])
    omega_axial = math.sqrt(k_axial / m.nut_mass)
    p[L.P_C_THREAD_S] = 2 * zeta_c * tangents[0] / omega_axial
    p[L.P_C_THREAD_N] = 2 * zeta_c * tangents[1] / omega_axial
    p[L.P_C_MESH] = 2 * zeta_c * math.sqrt(float(np.mean(mesh)) * m.roller_inertia / rb_roller**2)
    p[L.P_K_S] = options.screw_support_stiffness
    p[L.P_C_S] = 2 * zeta_s * math.sqrt(p[L.P_K_S] * m.screw_mass)
    p[L.P_K_N] = options.nut_guide_stiffness
    p[L.P_C_N] = 2 * zeta_s * math.sqrt(p[L.P_K_N] * m.nut_mass)
    p[L.P_K_ND] = drive_train.anti_rotation_stiffness
    p[L.P_C_ND] = 2 * zeta_s * math.sqrt(p[L.P_K_ND] * m.nut_inertia)
    p[L.P_K_PN] = options.carrier_nut_stiffness
    p[L.P_C_PN] = 2 * zeta_s * math.sqrt(p[L.P_K_PN] * m.carrier_mass)
    p[L.P_C_PND] = 1e-5
    p[L.P_K_CP] = options.pocket_stiffness
    p[L.P_C_CP] = 2 * zeta_s * math.sqrt(p[L.P_K_CP] * m.roller_mass)
    p[L.P_C_NA] = options.nut_guide_damping
    p[L.P_C_SD] = 1e-4
    p[L.P_MU_VISC] = options.viscous_friction
    p[L.P_MU_COUL] = options.friction_coefficient
    p[L.P_MU_ROLL] = options.rolling_friction
    # Regularisation speeds of the sliding laws: far below running speeds, wide enough for a
    # 5 µs step at kN loads (the step guard checks the combination).
    p[L.P_V_AXIAL] = 0.01
    p[L.P_W_ROLL] = 0.1
    p[L.P_LEAD_EFF] = speed_ratios(design).nut
    # Normal-direction stiffness of one roller's screw side is k_axial / sin²β.
    p[L.P_K_TAN] = (
        options.traction_stiffness_ratio * tangents[0] / math.sin(design.contact_angle) ** 2
    )
    p[L.P_C_TAN] = 2 * zeta_c * math.sqrt(p[L.P_K_TAN] * m.roller_inertia / r_r**2)
    p[L.P_FRICTION_SCALE] = health.friction_scale
    p[L.P_DRIVE_MODE] = {
        "prescribed": L.DRIVE_PRESCRIBED,
        "speed_loop": L.DRIVE_SPEED_LOOP,
        "position_loop": L.DRIVE_POSITION_LOOP,
    }[profile.drive]
    # PI speed loop on the motor speed, gains from the inertia it drives: motor, reduction and
    # the screw reflected to the motor (J_s/N²; J_m + J_s without a reduction).
    j_drive = drive_train.reflected_inertia(m.screw_inertia)
    omega_bw = 2 * math.pi * profile.speed_loop_bandwidth
    p[L.P_KP] = j_drive * omega_bw * 2.0
    p[L.P_KI] = j_drive * omega_bw**2
    p[L.P_KP_POS] = profile.position_loop_gain
    # Saturation of the speed loop: the motor's peak torque k_t·I_peak when the drive train
    # gives its current limit (physics wins), else the profile's torque_limit (older scenarios).
    p[L.P_TORQUE_LIMIT] = drive_train.peak_torque or profile.torque_limit
    p[L.P_LOAD_SIN_AMP], p[L.P_LOAD_SIN_FREQ] = amp, freq
    _drive_train_params(p, drive_train, design, k_axial, options.contact_restitution)

    rng = variation_stream(seed)
    rollers = _roller_params(design, health, options.variation, orbit, rng)
    _rolling_params(rollers, design, options, rng, roller_load, tangents)
    _place_fatigue_spall(rollers, health, p, operating, rng)
    errors, p[L.P_LEAD_SLOPE] = error_terms(design, options.variation, rng, health.spalls)
    p[L.P_HAS_SPALLS] = spall_params(p, design, health, profile, options)
    p[L.P_STRIBECK] = coulomb_table(errors, design, health, profile, options)
    p[L.P_HAS_TOOTH_DAMAGE] = tooth_tables(errors, rollers, design, health, options)
    return Model(
        design=design,
        health=health,
        profile=profile,
        options=options,
        drive_train=drive_train,
        params=p,
        rollers=rollers,
        mesh_table=mesh,
        motion=np.ascontiguousarray(profile.motion_knots()),
        load_knots=np.ascontiguousarray(load_knots),
        errors=errors,
        thread_stiffness=(tangents[0], tangents[1]),
        roller_load=roller_load,
    )


def _drive_train_params(p, drive_train, design, k_axial, restitution) -> None:
    """Motor, coupling, thrust bearing, linkage, payload and the squeeze-film damper."""
    dt, m = drive_train, design.masses
    zeta_film = -math.log(restitution) / math.sqrt(math.pi**2 + math.log(restitution) ** 2)
    p[L.P_C_FILM] = 2 * zeta_film * math.sqrt(k_axial * m.nut_mass)
    p[L.P_COUPLED] = 1.0 if dt.coupled else 0.0
    p[L.P_RATIO] = 1.0
    if dt.geared:
        # The reduction's input inertia turns with the motor; its mesh stiffness is in series
        # with the coupling (no inertia between them: the catalogue's J_1 is at the input).
        p[L.P_GEARED] = 1.0
        p[L.P_RATIO] = dt.gear_ratio
        p[L.P_J_M] = dt.motor_inertia + dt.gear_inertia
        k = dt.coupling_stiffness
        if dt.gear_stiffness:
            k = k * dt.gear_stiffness / (k + dt.gear_stiffness)
        p[L.P_K_COUP] = k
        p[L.P_GEAR_EFFICIENCY] = dt.gear_efficiency
        p[L.P_GEAR_BACKLASH] = dt.gear_backlash
        p[L.P_MESH_ORDER] = dt.mesh_order
        p[L.P_GEAR_TE] = dt.transmission_error if dt.mesh_order else 0.0
        # 1 rad/s at the motor: far below running speeds (the loss is then fully on), wide
        # enough that the loss's sign change at a reversal is smooth for a µs step.
        p[L.P_W_GEAR] = 1.0
    else:
        p[L.P_J_M] = dt.motor_inertia
        p[L.P_K_COUP] = dt.coupling_stiffness
    j_pair = dt.coupling_pair_inertia(m.screw_inertia)
    p[L.P_C_COUP] = 2 * dt.coupling_damping_ratio * math.sqrt(p[L.P_K_COUP] * j_pair)
    p[L.P_AXIAL_FREE] = 0.0 if dt.rigid_thrust_bearing else 1.0
    p[L.P_K_BEAR] = dt.thrust_bearing_stiffness
    p[L.P_C_BEAR] = (
        2 * dt.thrust_bearing_damping_ratio * math.sqrt(dt.thrust_bearing_stiffness * m.screw_mass)
    )
    p[L.P_BEAR_PLAY] = dt.thrust_bearing_play
    p[L.P_ON_PAYLOAD] = 1.0 if dt.load_application == "payload" else 0.0
    p[L.P_M_L] = dt.payload_mass
    p[L.P_K_LINK] = dt.linkage_stiffness
    p[L.P_C_LINK] = 2 * dt.linkage_damping_ratio * math.sqrt(dt.linkage_stiffness * dt.payload_mass)


def geared_motor_state(model: Model, y: np.ndarray) -> None:
    """Put the motor of a geared drive train on the kinematic solution, in place.

    :func:`initial_state` sets the motor angle and speed as the gearbox output's (θ_s plus the
    coupling twist, ω_s); through a reduction the motor turns N times as far, and a loaded
    coupling takes up the gear's half-backlash first. No-op without a reduction.
    """
    p = model.params
    if p[L.P_GEARED] != 1.0:
        return
    nq = model.n_coordinates
    load0 = float(model.load_knots[1, 0])
    output = y[L.Q_THM]
    if p[L.P_COUPLED] == 1.0 and load0:
        output += math.copysign(p[L.P_GEAR_BACKLASH], load0)
    y[L.Q_THM] = p[L.P_RATIO] * output
    y[nq + L.Q_THM] = p[L.P_RATIO] * y[nq + L.Q_THM]


def _roller_params(design, health, variation, orbit, rng) -> np.ndarray:
    n = design.n_rollers
    draws = RollerDraws.draw(rng, n)
    z = draws.normal
    psi = 2 * math.pi * np.arange(n) / n + variation.position_error * z[0]
    r = np.zeros((n, L.N_ROLLER_PARAMS))
    r[:, L.R_PSI] = psi
    r[:, L.R_COS_PSI] = np.cos(psi)
    r[:, L.R_SIN_PSI] = np.sin(psi)
    r[:, L.R_POCKET_R] = orbit + variation.eccentricity * z[1]
    scale = 1.0 + health.wear_spread * draws.wear
    r[:, L.R_E_S], r[:, L.R_E_N] = draws.pitch_errors(variation)
    r[:, L.R_E_G] = variation.transmission_error * z[4]
    # As assembled, the clearance takes up each roller's pitch errors (RollerDraws.take_up)
    # and its transmission error (|Δe_g| more backlash). Preload is not a clearance of zero
    # but a parameter of its own.
    take_up = draws.take_up(variation)
    # a preload is interference on both flanks: a negative half-clearance
    preload = health.effective_preload
    r[:, L.R_B_S] = health.clearance_screw * scale + take_up - preload
    r[:, L.R_B_N] = health.clearance_nut * scale + take_up - preload
    r[:, L.R_B_G] = health.clearance_gear + np.abs(r[:, L.R_E_G] - np.mean(r[:, L.R_E_G]))
    r[:, L.R_MESH_PHASE] = 0.0
    r[:, L.R_MESH_SCALE] = np.clip(1.0 + variation.mesh_stiffness_spread * z[5], 0.5, 1.5)
    r[:, L.R_RUNOUT] = variation.roller_runout * draws.runout
    r[:, L.R_RUNOUT_PHASE] = draws.runout_phase
    for spall in health.spalls:
        if spall.location == "roller" and spall.roller != FATIGUE:
            require(
                spall.roller < n,
                "faults.roller",
                spall.roller,
                f"must be below the design's {n} rollers",
            )
            r[spall.roller, L.R_SPALL] = 1.0
    return r


def _rolling_params(rollers, design, options, rng, roller_load, tangents) -> None:
    """Fill the thread-rolling columns (layout ``R_ROLL_*``, ``R_K_TAN_N``, ``R_C_TAN_N``,
    ``R_RELAX_*``, ``R_MISMATCH``): each roller's rolling radii on screw and nut, the nut-side
    traction and the pitch mismatch ε = nominal + tolerance + elastic
    (:func:`prsm_health.physics.rolling_mismatch.rolling_mismatch_terms`)."""
    from prsm_health.physics.rolling_mismatch import rolling_mismatch_terms

    v = options.variation
    n = design.n_rollers
    r_r, r_n = design.roller_diameter / 2, design.nut_diameter / 2
    # A stream of its own, jumped off the variation stream without advancing it, so the
    # draws of every other tolerance stay what they were for a seed.
    extra = np.random.Generator(rng.bit_generator.jumped())
    z = extra.standard_normal(n + 1)
    d_roller = v.rolling_radius_error * z[:n]  # each roller's rolling radius error [m]
    d_nut = v.rolling_radius_error * z[n]  # the nut thread's, against its ring gear [m]
    nominal, elastic, (l_screw, l_nut) = rolling_mismatch_terms(design, roller_load)
    eps = nominal + d_nut / r_n - d_roller / r_r + elastic
    sin_b = math.sin(design.contact_angle)
    # The screw side: the roller's own radius error. The elastic shift there is common to all
    # rollers and only moves the carrier speed (by ~1e-4): not modelled.
    rollers[:, L.R_ROLL_S] = r_r + d_roller
    rollers[:, L.R_ROLL_N] = r_r / (1.0 + eps)
    k_tan_n = options.traction_stiffness_ratio * tangents[1] / sin_b**2
    rollers[:, L.R_K_TAN_N] = k_tan_n
    # as the screw side's P_C_TAN: the contact damping ratio on the roller's spin
    m = design.masses
    rollers[:, L.R_C_TAN_N] = (
        2 * options.contact_damping_ratio * math.sqrt(k_tan_n * m.roller_inertia / r_r**2)
    )
    rollers[:, L.R_RELAX_S] = 1.0 / l_screw
    rollers[:, L.R_RELAX_N] = 1.0 / l_nut
    rollers[:, L.R_MISMATCH] = eps


def static_roller_loads(rollers: np.ndarray, p: np.ndarray, load: float) -> np.ndarray:
    """Each roller's axial load [N] when together they carry ``load`` [N] on the flanks a
    positive load presses, statically: roller i's two thread contacts close in series once the
    common axial approach u exceeds its gap b_s + b_n − (e_s + e_n) (its half-clearances less
    its pitch errors, as the kernel's closures have them), each with the kernel's law
    (P_K_THREAD_*, P_EXPONENT); u by bisection. On eight fresh units the shares agree with the
    dynamic runs' mean contact loads within 0.03 (docs/faults.md, roller spalls)."""
    gap = rollers[:, L.R_B_S] + rollers[:, L.R_B_N] - (rollers[:, L.R_E_S] + rollers[:, L.R_E_N])
    exponent = p[L.P_EXPONENT]  # F = k·δ^e per contact: in series δ = Σ (F/k)^(1/e)
    compliance = p[L.P_K_THREAD_S] ** (-1.0 / exponent) + p[L.P_K_THREAD_N] ** (-1.0 / exponent)
    lo, hi = float(gap.min()), float(gap.max()) + 1e-3
    for _ in range(100):  # to the float resolution of u
        mid = 0.5 * (lo + hi)
        total = np.sum((np.maximum(mid - gap, 0.0) / compliance) ** exponent)
        lo, hi = (lo, mid) if total > load else (mid, hi)
    return (np.maximum(0.5 * (lo + hi) - gap, 0.0) / compliance) ** exponent


def _place_fatigue_spall(rollers, health, p, load: float, rng) -> None:
    """Put a roller spall whose roller is ``"fatigue"`` on a roller drawn with probability ∝
    its static load cubed (faults.Spall: fatigue life ∝ (C/P)³ for point contacts), from a
    stream jumped off the variation stream (its other draws unchanged for a seed)."""
    if not any(s.location == "roller" and s.roller == FATIGUE for s in health.spalls):
        return
    weight = static_roller_loads(rollers, p, load) ** 3
    if not np.any(weight > 0.0):
        weight = np.ones(len(rollers))
    stream = np.random.Generator(rng.bit_generator.jumped(2))
    rollers[stream.choice(len(rollers), p=weight / weight.sum()), L.R_SPALL] = 1.0


def realised_clearances(model: Model) -> dict[str, float]:
    """Run labels of the as-built half-clearances [m]: mean, min and max over the rollers of
    each engagement (uneven wear, the assembly's take-up of pitch errors and the preload
    included: negative is interference)."""
    out = {}
    for name, column in (("screw", L.R_B_S), ("nut", L.R_B_N), ("gear", L.R_B_G)):
        values = model.rollers[:, column]
        for stat in ("mean", "min", "max"):
            out[f"clearance_{name}_realised_{stat}"] = float(getattr(np, stat)(values))
    return out


def static_closure(model: Model, side: int) -> float:
    """Flank closure beyond the clearance that carries the per-roller load on one side [m]."""
    k = model.params[L.P_K_THREAD_S if side == 0 else L.P_K_THREAD_N]
    if model.params[L.P_EXPONENT] == 1.0:
        return model.roller_load / k
    return (model.roller_load / k) ** (2.0 / 3.0)


def _gear_flank_offset(model: Model, i: int, w_s: float, load0: float) -> float:
    """Roller spin offset [rad] that puts roller i's gear on the flank it runs on in steady
    state, at its steady force: in service the gear has long crossed its backlash (at ε = 3e-4
    that takes ~0.2 s, longer than most runs), so a run starts there, not in the backlash.

    Steady gear force (signed with the screw speed): the nut traction's creep force at the
    pitch mismatch ε (Kalker's linear law, capped at μN) over cos α0, less the spin torque
    μN·L_r/2π that the roller's axial sliding on the screw (paper 02's μ2 term) puts on it
    through the helix (the gear, stiffer than the creeping threads, takes it)."""
    p, r = model.params, model.rollers
    if w_s == 0.0:
        return 0.0
    normal = p[L.P_MU_COUL] * p[L.P_FRICTION_SCALE] * abs(load0) / model.n_rollers
    normal /= p[L.P_SIN_BETA]  # μN of one roller side
    eps = r[i, L.R_MISMATCH]
    creep = min(r[i, L.R_K_TAN_N] / r[i, L.R_RELAX_N] * abs(eps), normal) if eps else 0.0
    force = math.copysign(creep, eps) / p[L.P_COS_A0] - normal * p[L.P_LEAD_R] / p[L.P_RB_ROLLER]
    if force == 0.0:
        return 0.0
    direction = math.copysign(1.0, force * w_s)  # > 0: the drive flank, d_g > 0
    k_mesh = float(np.mean(model.mesh_table)) * r[i, L.R_MESH_SCALE]
    # d_g = … − r_br·θ_i: closing d_g to ±(b_g + F/k) turns the roller back by as much
    return -direction * (r[i, L.R_B_G] + abs(force) / k_mesh) / p[L.P_RB_ROLLER]


def initial_state(model: Model, t0: float = 0.0) -> np.ndarray:
    """Rigid-body motion at the profile's initial speed, contacts at their static load.

    Starting on the kinematic solution with the static thread, bearing, linkage and coupling
    deflections avoids a start-up transient that would otherwise dominate short runs.
    """
    d = model.design
    n = model.n_rollers
    nq = model.n_coordinates
    y = np.zeros(model.n_state)
    p, r = model.params, model.rollers
    w_s = float(model.motion[1, 0])
    ratios = speed_ratios(d)
    w_c = ratios.carrier * w_s
    w_r = ratios.roller_spin * w_s
    v_nut = ratios.nut * w_s
    load0 = float(model.load_knots[1, 0])
    sign = 1.0 if load0 >= 0 else -1.0
    # Static deflections: coupling twist under the ideal screw torque, screw pushed back on its
    # bearing, linkage stretched by the load.
    twist = load0 * ratios.nut / p[L.P_K_COUP] if p[L.P_COUPLED] == 1.0 else 0.0
    z_s = 0.0
    if p[L.P_AXIAL_FREE] == 1.0 and load0:
        z_s = -sign * (p[L.P_BEAR_PLAY] + abs(load0) / p[L.P_K_BEAR])
    # Rigid-body positions at t0 (negative when settling): every angle and axial position on
    # the kinematic solution, so no deformation comes from the start time itself.
    th_m = w_s * t0
    th_s = th_m - twist
    y[L.Q_THM] = th_m
    y[nq + L.Q_THM] = w_s
    y[L.Q_THS] = th_s
    y[L.Q_THP] = ratios.carrier * th_s
    y[L.Q_ZS] = z_s
    y[nq + L.Q_THS] = w_s
    y[nq + L.Q_THP] = w_c
    y[nq + L.Q_ZN] = v_nut
    y[nq + L.Q_ZL] = v_nut
    # Axial offsets carrying the initial load: nut pushed back through both thread sides.
    frac = abs(load0) / max(model.roller_load * n, 1e-12)
    shape = frac if p[L.P_EXPONENT] == 1.0 else frac ** (2.0 / 3.0)
    for i in range(n):
        b = L.Q_ROLLER0 + L.ROLLER_DOF * i
        rad = r[i, L.R_POCKET_R]
        c, s = math.cos(r[i, L.R_PSI] + y[L.Q_THP]), math.sin(r[i, L.R_PSI] + y[L.Q_THP])
        y[b], y[b + 1] = rad * c, rad * s
        y[b + 2] = ratios.roller_spin * th_s
        y[nq + b], y[nq + b + 1] = -rad * s * w_c, rad * c * w_c
        y[nq + b + 2] = w_r
        y[nq + b + 3] = v_nut
        d_s = sign * (r[i, L.R_B_S] + shape * static_closure(model, 0)) if load0 else 0.0
        # δ_s = −(z_i − z_s) + e_s (+ the rigid-body terms, zero on the kinematic solution)
        y[b + 3] = z_s - d_s + r[i, L.R_E_S] + ratios.nut * th_s
        y[b + 2] += _gear_flank_offset(model, i, w_s, load0)
    z_c_mean = float(np.mean(y[L.Q_ROLLER0 + 3 : nq : L.ROLLER_DOF]))
    d_n_mean = (
        sign * (float(np.mean(r[:, L.R_B_N])) + shape * static_closure(model, 1)) if load0 else 0.0
    )
    y[L.Q_ZN] = z_c_mean - d_n_mean + float(np.mean(r[:, L.R_E_N]))
    y[L.Q_ZL] = y[L.Q_ZN]
    if p[L.P_ON_PAYLOAD] == 1.0:
        y[L.Q_ZL] -= load0 / p[L.P_K_LINK]
    geared_motor_state(model, y)
    return y
