"""Friction torque and transmission efficiency of a PRSM under start/stop motion (paper 02).

Two generalised coordinates, the screw angle θ_s (prescribed motion) and the roller revolution
angle θ_R (free), with roller spin tied to revolution by the ring gear, θ̇_r = G·θ̇_R,
G = −(r_n0 − r_r0)/r_r0. Three friction sources at the screw–roller contacts:

* lubricant viscous drag F_fs1 = −μ1·n_R·n_t·v_sr0,
* Coulomb friction of spin sliding, μ2·F_n per contact along −v_sr0 (regularised),
* differential-sliding torque M_fs3 = −μ3·F_n per contact on the screw,

with F_n = F_out/(n_R·n_t·cos ψ_s·cos β_s) and v_sr0 the relative sliding velocity at the
initial contact point P0.

Readings of ambiguous terms (stated in docs/validation.md):

* The Coulomb force and M_fs3 are summed over **all n_R·n_t contacts** (read literally as one
  contact they are 15× smaller than the paper's own steady torque).
* The contact offset angles θ_sc, θ_rc default to **0** (the paper gives no value).
* The Coulomb force acts against the sliding velocity v_sr0 (unit vector, regularised with
  ``coulomb_velocity``); the paper's sign "+μ1 n_R n_t v_sr0" is read as opposing motion.
* Inertias the table omits: solid-cylinder screw and rollers, thin-ring carriers at the orbit
  radius; two carriers (paper: "two carriers (typical)").
* ``drag_torque``: an optional load-independent loss (seals, churning). The paper's model has
  none, so its steady efficiency is the same at every load; "efficiency rises with load" needs
  such a term. Default 0 (the paper's model).

References
----------
Paper 02 (docs/references.md) — sliding velocity v_sr0, F_fs1,
F_fs2, M_fs3, Lagrangian L, generalised forces Q_s, Q_R, efficiencies η(t) and η_overall,
parameter and results tables.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import ConvergenceError, require, require_positive, require_range

from .lubrication import StribeckCurve


@dataclass(frozen=True)
class FrictionParameters:
    """Geometry, masses and friction coefficients of paper 02's model (SI).

    Parameters
    ----------
    screw_radius, roller_radius, nut_radius : float [m]
        Nominal thread contact radii r_s0, r_r0, r_n0.
    pitch : float [m]
    screw_starts : int
        z_s; the lead per radian is p_s = z_s·p/2π.
    n_rollers : int
        n_R.
    threads_per_roller : int
        n_t, engaged thread rounds per roller.
    viscous : float [N·s/m]
        μ1.
    sliding : float [-]
        μ2.
    rolling : float [m]
        μ3.
    nut_mass, roller_mass, carrier_mass, screw_mass : float [kg]
    flank_angle : float [rad]
        β_s, between the contact normal and the radial plane … read as the paper's β_s with
        F_af = F_nf cos ψ_s cos β_s (at 45° either convention gives the same numbers).
    screw_offset_angle, roller_offset_angle : float [rad]
        Contact offset angles θ_sc, θ_rc (0: contact in the axial plane).
    n_carriers : int
    drag_torque : float [N·m]
        Load-independent loss torque (0 in the paper).
    friction_scale : float [-]
        Multiplies μ1, μ2, μ3 (lubricant state; 1 = new).
    coulomb_velocity : float [m/s]
        Regularisation speed of the Coulomb direction.
    """

    screw_radius: float = 10e-3
    roller_radius: float = 5e-3
    nut_radius: float = 15e-3
    pitch: float = 5e-3
    screw_starts: int = 1
    n_rollers: int = 5
    threads_per_roller: int = 3
    viscous: float = 0.01
    sliding: float = 0.1
    rolling: float = 1.5e-6
    nut_mass: float = 0.5
    roller_mass: float = 0.05
    carrier_mass: float = 0.1
    screw_mass: float = 0.8
    flank_angle: float = math.radians(45.0)
    screw_offset_angle: float = 0.0
    roller_offset_angle: float = 0.0
    n_carriers: int = 2
    drag_torque: float = 0.0
    friction_scale: float = 1.0
    coulomb_velocity: float = 1e-7

    def __post_init__(self):
        for name in (
            "screw_radius",
            "roller_radius",
            "nut_radius",
            "pitch",
            "nut_mass",
            "roller_mass",
            "carrier_mass",
            "screw_mass",
            "coulomb_velocity",
        ):
            require_positive(f"friction.{name}", getattr(self, name))
        for name in ("screw_starts", "n_rollers", "threads_per_roller", "n_carriers"):
            value = getattr(self, name)
            require(
                isinstance(value, int) and value >= 1,
                f"friction.{name}",
                value,
                "must be an integer ≥ 1",
            )
        require(
            self.nut_radius > self.roller_radius,
            "friction.nut_radius",
            self.nut_radius,
            f"must exceed roller_radius = {self.roller_radius:g} m",
        )
        require_range("friction.viscous", self.viscous, 0.0, 1e4, unit="N·s/m")
        require_range("friction.sliding", self.sliding, 0.0, 1.0)
        require_range("friction.rolling", self.rolling, 0.0, 1e-3, unit="m")
        require_range(
            "friction.flank_angle", self.flank_angle, math.radians(5), math.radians(85), unit="rad"
        )
        require_range("friction.drag_torque", self.drag_torque, 0.0, 1e3, unit="N·m")
        require_range("friction.friction_scale", self.friction_scale, 0.0, 20.0)

    @classmethod
    def paper02(cls) -> FrictionParameters:
        """The paper-02 parameter table, printed radii included (r_n0 = 15 mm)."""
        return cls()

    @classmethod
    def from_design(cls, design: PRSMDesign, **overrides) -> FrictionParameters:
        """Parameters for a design: its pitch radii, lead, rollers, engaged threads, masses."""
        m = design.masses
        lead_per_start = design.screw_lead / design.screw_starts
        values = dict(
            screw_radius=design.screw_diameter / 2,
            roller_radius=design.roller_diameter / 2,
            nut_radius=design.nut_diameter / 2,
            pitch=lead_per_start,
            screw_starts=design.screw_starts,
            n_rollers=design.n_rollers,
            threads_per_roller=design.engaged_threads,
            nut_mass=m.nut_mass,
            roller_mass=m.roller_mass,
            carrier_mass=m.carrier_mass,
            screw_mass=m.screw_mass,
            flank_angle=design.contact_angle,
        )
        values.update(overrides)
        return cls(**values)

    # ------------------------------------------------------------------ derived
    @property
    def lead_per_radian(self) -> float:
        """p_s = z_s·p/2π [m/rad]."""
        return self.screw_starts * self.pitch / (2 * math.pi)

    @property
    def lead_angle(self) -> float:
        """ψ_s = atan(p_s/r_s0) [rad] (paper: 4.550° for its table)."""
        return math.atan(self.lead_per_radian / self.screw_radius)

    @property
    def gear_ratio(self) -> float:
        """G = −(r_n0 − r_r0)/r_r0: roller spin per revolution [-]."""
        return -(self.nut_radius - self.roller_radius) / self.roller_radius

    @property
    def contacts(self) -> int:
        return self.n_rollers * self.threads_per_roller

    def normal_load(self, load: float) -> float:
        """F_n per contact = F_out/(n_R n_t cos ψ_s cos β_s) [N]."""
        return load / (self.contacts * math.cos(self.lead_angle) * math.cos(self.flank_angle))

    @property
    def screw_inertia_total(self) -> float:
        """A = I_s + (m_N + n_R m_R + n_c m_c)·p_s² [kg·m²] (coefficient of θ̇_s² in 2L)."""
        i_s = 0.5 * self.screw_mass * self.screw_radius**2
        axial_mass = (
            self.nut_mass + self.n_rollers * self.roller_mass + self.n_carriers * self.carrier_mass
        )
        return i_s + axial_mass * self.lead_per_radian**2

    @property
    def revolution_inertia(self) -> float:
        """B = n_R I_r G² + n_c I_c + n_R m_R (r_s0 + r_r0)² [kg·m²]."""
        orbit = self.screw_radius + self.roller_radius
        i_r = 0.5 * self.roller_mass * self.roller_radius**2
        i_c = self.carrier_mass * orbit**2
        return (
            self.n_rollers * i_r * self.gear_ratio**2
            + self.n_carriers * i_c
            + self.n_rollers * self.roller_mass * orbit**2
        )

    @property
    def rolling_ratio(self) -> float:
        """θ̇_R/θ̇_s at which the tangential sliding vanishes (0.400 for paper 02) [-]."""
        dvs, dvr = self._partials()
        return -dvs[1] / dvr[1]

    def _partials(self) -> tuple[np.ndarray, np.ndarray]:
        # ∂v_sr0/∂θ̇_s and ∂v_sr0/∂θ̇_R (paper 02's v_sr0 at θ_R = 0).
        r_s, r_r, g = self.screw_radius, self.roller_radius, self.gear_ratio
        a_s, a_r = self.screw_offset_angle, self.roller_offset_angle
        orbit = self.screw_radius + self.roller_radius
        d_s = np.array([-r_s * math.sin(a_s), r_s * math.cos(a_s), self.lead_per_radian])
        d_r = np.array([r_r * g * math.sin(a_r), r_r * g * math.cos(a_r) - orbit, 0.0])
        return d_s, d_r


def steady_friction_torque(
    params: FrictionParameters,
    load: float,
    speed: float = 1.0,
    stribeck: StribeckCurve | None = None,
) -> float:
    """Steady rolling friction torque F(μ2 p_s + μ3)/(cos ψ cos β)·scale + drag [N·m].

    At steady speed the roller rolls (tangential sliding 0) and the only sliding is the axial
    p_s·θ̇_s, so the Coulomb force of all contacts acts axially (closed form of the model).
    With a ``stribeck`` curve, μ2 is its coefficient at the steady entrainment speed of screw
    ``speed`` [rad/s].
    """
    require(load >= 0, "load", load, "must be ≥ 0 N")
    total_normal = params.contacts * params.normal_load(load)
    sliding = _sliding(params, stribeck, speed, params.rolling_ratio * speed)
    rolling = params.rolling * params.friction_scale
    return total_normal * (sliding * params.lead_per_radian + rolling) + params.drag_torque


def _sliding(params: FrictionParameters, stribeck, w_s: float, w_r: float) -> float:
    """μ2 (times the friction scale): constant, or the lubrication regime's coefficient at the
    entrainment speed r_s·|θ̇_s − θ̇_R| of the screw–roller contacts (pure rolling)."""
    if stribeck is None:
        return params.sliding * params.friction_scale
    u_e = params.screw_radius * abs(w_s - w_r)
    return float(np.interp(u_e, stribeck.speed, stribeck.coefficient)) * params.friction_scale


@dataclass(frozen=True)
class FrictionResult:
    """Time histories and summary numbers of one start-up (SI).

    Attributes
    ----------
    time, screw_speed [rad/s], revolution_speed [rad/s], friction_torque [N·m],
    input_torque [N·m], efficiency [-] (instantaneous F_out·p_s/T_in) : ndarray
    peak_friction_torque, steady_friction_torque [N·m]
    min_efficiency, overall_efficiency, steady_efficiency [-]
    """

    time: np.ndarray
    screw_speed: np.ndarray
    revolution_speed: np.ndarray
    friction_torque: np.ndarray
    input_torque: np.ndarray
    efficiency: np.ndarray
    peak_friction_torque: float
    steady_friction_torque: float
    min_efficiency: float
    overall_efficiency: float
    steady_efficiency: float

    def summary(self) -> dict:
        return {
            "peak_friction_torque": self.peak_friction_torque,
            "steady_friction_torque": self.steady_friction_torque,
            "min_efficiency": self.min_efficiency,
            "overall_efficiency": self.overall_efficiency,
            "steady_efficiency": self.steady_efficiency,
        }


def _ramp(t, speed, accel_time):
    if accel_time <= 0 or t >= accel_time:
        return speed, 0.0
    return speed * t / accel_time, speed / accel_time


def simulate_friction(
    params: FrictionParameters,
    load: float,
    speed: float = 1.0,
    accel_time: float = 0.02,
    duration: float | None = None,
    n_points: int = 2001,
    stribeck: StribeckCurve | None = None,
) -> FrictionResult:
    """Start the screw from rest to ``speed`` over ``accel_time`` under a constant load.

    Parameters
    ----------
    params : FrictionParameters
    load : float [N]
        Output axial force F_out (resisting).
    speed : float [rad/s]
        Final screw speed (paper 02: 1 rad/s).
    accel_time : float [s]
        Linear ramp time t_acc.
    duration : float or None [s]
        Simulated interval [0, duration], over which η_overall is computed; None:
        t_acc + 0.1 s (the paper does not state its interval).
    n_points : int
        Output samples.
    stribeck : StribeckCurve or None
        The lubrication regime (:func:`prsm_health.physics.lubrication.stribeck_curve`): μ2 follows
        it at the contacts' entrainment speed, so the start-up crosses boundary and mixed
        friction. None: paper 02's constant μ2.

    Returns
    -------
    FrictionResult

    References
    ----------
    Paper 02: Lagrange equations with Q_s, Q_R; η(t) = F_out·p_s/T_in(t); η_overall as the
    ratio of output to input work.
    """
    require_range("load", load, 0.0, 1e6, unit="N")
    require_range("speed", speed, 1e-6, 1e4, unit="rad/s")
    require_range("accel_time", accel_time, 0.0, 100.0, unit="s")
    duration = accel_time + 0.1 if duration is None else duration
    require(
        duration > accel_time, "duration", duration, f"must exceed accel_time = {accel_time:g} s"
    )
    d_s, d_r = params._partials()
    n = params.contacts
    f_n = params.normal_load(load)
    s = params.friction_scale
    mu1, mu3 = params.viscous * s, params.rolling * s
    eps = params.coulomb_velocity
    b_inertia = params.revolution_inertia
    a_inertia = params.screw_inertia_total
    p_s = params.lead_per_radian

    def friction_force(w_s, w_r):
        v = d_s * w_s + d_r * w_r
        mu2 = _sliding(params, stribeck, w_s, w_r)
        return -(mu1 * n * v + mu2 * f_n * n * v / math.sqrt(float(v @ v) + eps * eps))

    def rhs(t, y):
        w_s, _ = _ramp(t, speed, accel_time)
        return [y[1], float(friction_force(w_s, y[1]) @ d_r) / b_inertia]

    # Stiff (regularised Coulomb): an implicit method; the ramp corner is a step boundary.
    time = np.linspace(0.0, duration, n_points)
    w_r = np.empty_like(time)
    y0 = [0.0, 0.0]
    for t0, t1 in ((0.0, accel_time), (accel_time, duration)):
        if t1 <= t0:
            continue
        sol = solve_ivp(
            rhs,
            (t0, t1),
            y0,
            method="Radau",
            dense_output=True,
            rtol=1e-8,
            atol=1e-10,
            max_step=(t1 - t0) / 50,
        )
        if not sol.success:  # pragma: no cover - Radau on a 2-state system does not fail
            raise ConvergenceError(
                f"friction: Radau integration of the roller revolution speed did not converge "
                f"on t = [{t0:.6g}, {t1:.6g}] s for load = {load:.6g} N, speed = {speed:.6g} "
                f"rad/s, accel_time = {accel_time:.6g} s: {sol.message}"
            )
        # each sample belongs to one segment; the ramp corner starts the second one
        mask = (time >= t0) & ((time < t1) | (t1 == duration))
        w_r[mask] = sol.sol(time[mask])[1]
        y0 = sol.y[:, -1]
    w_s = np.array([_ramp(t, speed, accel_time)[0] for t in time])
    alpha_s = np.array([_ramp(t, speed, accel_time)[1] for t in time])
    friction = np.array([-(friction_force(a, b) @ d_s) for a, b in zip(w_s, w_r)])
    friction += mu3 * f_n * n * np.tanh(w_s / 1e-3) + params.drag_torque * np.tanh(w_s / 1e-3)
    input_torque = a_inertia * alpha_s + friction + load * p_s
    moving = w_s > 0
    efficiency = np.where(
        moving & (input_torque > 0),
        load * p_s / np.where(input_torque > 0, input_torque, 1.0),
        np.nan,
    )
    work_out = np.trapezoid(load * p_s * w_s, time)
    work_in = np.trapezoid(input_torque * w_s, time)
    steady = steady_friction_torque(params, load, speed, stribeck)
    out_steady = load * p_s
    return FrictionResult(
        time=time,
        screw_speed=w_s,
        revolution_speed=w_r,
        friction_torque=friction,
        input_torque=input_torque,
        efficiency=efficiency,
        peak_friction_torque=float(np.max(friction)),
        steady_friction_torque=steady,
        min_efficiency=float(np.nanmin(efficiency)) if np.any(moving) else float("nan"),
        overall_efficiency=float(work_out / work_in) if work_in > 0 else float("nan"),
        steady_efficiency=out_steady / (out_steady + steady)
        if out_steady + steady > 0
        else float("nan"),
    )


def with_scale(params: FrictionParameters, friction_scale: float) -> FrictionParameters:
    """The same parameters with another lubricant state."""
    return replace(params, friction_scale=friction_scale)
