"""Cam-ring/roller reset force of a recirculating PRSM (paper 03, eq. 38) as a signal.

Reset force model (the paper's impact function, eq. 38, in a stated 1-DOF setting)
-----------------------------------------------------------------------------------
The chamfer of the platform rises one lead over the orbital angle β (its flank is inclined at
α/2 to the cam end face, eqs. 9–11), so while the carrier carries the roller across it the
chamfer surface advances axially, relative to the nut, at v_cam = lead·|ω_c|/β. Just before
contact the roller drifts the other way at lead·|ω_c|/2π (eq. 31). The roller (mass m_r,
free to slide axially in its carrier groove, screw and nut threads disengaged) is driven
through the compliant contact: with z the axial interference of chamfer and roller, the
normal penetration is x = z·cos(α/2) and m_r·z̈ = −F_n(x, ẋ)·cos(α/2) + F_res, z(0) = 0,
ż(0) = v_cam + v_drift, for the crossing time τ = β/|ω_c|. F_n is ADAMS IMPACT (eq. 38)
with the paper's contact parameters. F_res is an optional constant axial force resisting
the reset (carrier-groove friction, drag of the disengaging thread; the paper gives none).
Neglected, and why the peak is an idealisation: the radial lift h_r over the screw thread,
friction on the chamfer, roller spin, any transition curve at the chamfer foot (a sharp foot
makes the contact start at the full v_cam, ≈ 1 m/s here), and the re-engagement of the
threads at the end of arc DE (a thread contact, not a cam-ring one). With the paper's large
damping (C = 50 N·s/mm against the preset's 3.5 g roller) the impact is damping-dominated; the axial
momentum it transfers lies between m_r·v0 and 2·m_r·v0 (restitution 0…1) whatever the contact
law, the peak does not. The sampled series keeps the
momentum exactly (each sample is the mean force over its interval), so it can be added to a
nut acceleration at any sample rate.

References
----------
Paper 03 (docs/references.md) — eqs. (9)–(11) (chamfer), (31) (drift), (38) and §4.1 contact
parameters, §4.3 results.
MSC ADAMS/Solver, IMPACT and STEP functions (cubic STEP: h0 + (h1 − h0)·Δ²(3 − 2Δ)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import ConvergenceError, require, require_positive

from .geometry import (
    TWO_PI,
    RecirculatingGeometry,
    _require_recirculating,
    check_recirculating,
    orbital_angle,
    reset_stroke,
)
from .travel import ResetEvents, _require_speed, carrier_speed, reset_events


# ------------------------------------------------------------------------- impact (eq. 38)
@dataclass(frozen=True)
class ImpactContact:
    """Parameters of the ADAMS IMPACT contact function, in SI.

    Parameters
    ----------
    stiffness : float [N/m^exponent]
        K.
    exponent : float [-]
        e (> 1 keeps the force smooth at first contact).
    max_damping : float [N·s/m]
        C′, reached at penetration ``depth``.
    depth : float [m]
        d, penetration at which damping is fully on.

    References
    ----------
    Paper 03, eq. (38) and §4.1 (K = 1e5 N/mm, e = 1.5, C = 50 N·s/mm, d = 0.1 mm).
    """

    stiffness: float
    exponent: float
    max_damping: float
    depth: float

    def __post_init__(self):
        require_positive("contact.stiffness", self.stiffness)
        require(
            isinstance(self.exponent, (int, float)) and 1.0 <= self.exponent <= 3.0,
            "contact.exponent",
            self.exponent,
            "must lie in [1, 3]",
        )
        require(
            isinstance(self.max_damping, (int, float))
            and math.isfinite(self.max_damping)
            and self.max_damping >= 0,
            "contact.max_damping",
            self.max_damping,
            "must be a finite number ≥ 0 [N·s/m]",
        )
        require_positive("contact.depth", self.depth)

    @classmethod
    def from_adams_mm(
        cls, stiffness: float, exponent: float, max_damping: float, depth: float
    ) -> ImpactContact:
        """From ADAMS values in an mm model: K [N/mm^e], C [N·s/mm], d [mm].

        K·(x/mm)^e with x in metres is K·1000^e·x^e, hence the 1000^e.
        """
        return cls(stiffness * 1e3**exponent, exponent, max_damping * 1e3, depth * 1e-3)


#: The paper's contact parameters (§4.1), converted to SI: K = 3.162e9 N/m^1.5.
PAPER03_CONTACT = ImpactContact.from_adams_mm(1e5, 1.5, 50.0, 0.1)


def _step_on(penetration: np.ndarray, depth: float) -> np.ndarray:
    """ADAMS STEP(q, q0 − d, 1, q0, 0) written in the penetration x = q0 − q: 3u² − 2u³."""
    u = np.clip(penetration / depth, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def impact_force(penetration, penetration_rate, contact: ImpactContact = PAPER03_CONTACT):
    """Normal contact force of the ADAMS IMPACT function.

    F = max{0, K·x^e + C′·ẋ·STEP(x; 0 → 0, d → 1)} for x > 0, 0 otherwise, where x = q0 − q
    is the penetration and ẋ = −dq/dt its rate (positive while approaching). The cubic STEP
    ramps the damping in so the force is continuous at first contact; the outer max stops
    the damping from pulling the bodies together while they separate.

    Parameters
    ----------
    penetration : float or array_like [m]
        x; ≤ 0 means no contact.
    penetration_rate : float or array_like [m/s]
        ẋ.
    contact : ImpactContact

    Returns
    -------
    float or numpy.ndarray [N]

    References
    ----------
    Paper 03, eq. (38); MSC ADAMS/Solver IMPACT and STEP.
    """
    require(isinstance(contact, ImpactContact), "contact", contact, "must be an ImpactContact")
    x = np.asarray(penetration, dtype=float)
    v = np.asarray(penetration_rate, dtype=float)
    require(
        bool(np.all(np.isfinite(x))) and bool(np.all(np.isfinite(v))),
        "penetration",
        "non-finite value",
        "penetration and penetration_rate must be finite [m, m/s]",
    )
    xp = np.maximum(x, 0.0)
    force = contact.stiffness * xp**contact.exponent + contact.max_damping * v * _step_on(
        xp, contact.depth
    )
    force = np.where(x > 0.0, np.maximum(force, 0.0), 0.0)
    return float(force) if force.ndim == 0 else force


@dataclass(frozen=True)
class ResetPulse:
    """Cam-ring/roller contact during one reset (time from first contact).

    Attributes
    ----------
    time : numpy.ndarray [s]
        Solver steps over [0, τ], clustered at the impact.
    penetration : numpy.ndarray [m]
        Normal penetration x (negative: separated).
    normal_force : numpy.ndarray [N]
        F_n, eq. (38).
    impulse : numpy.ndarray [N·s]
        ∫F_n dt from 0, cumulative.
    approach_speed : float [m/s]
        Axial closing speed at first contact, v_cam + v_drift.
    crossing_time : float [s]
        τ = β/|ω_c|.
    chamfer_angle : float [rad]
        α/2.
    """

    time: np.ndarray
    penetration: np.ndarray
    normal_force: np.ndarray
    impulse: np.ndarray
    approach_speed: float
    crossing_time: float
    chamfer_angle: float

    @property
    def peak_force(self) -> float:
        """Largest normal force [N]."""
        return float(self.normal_force.max()) if self.normal_force.size else 0.0

    @property
    def axial_impulse(self) -> float:
        """Axial momentum given to the roller by the chamfer, ∫F_n·cos(α/2) dt [N·s]."""
        return float(self.impulse[-1]) * math.cos(self.chamfer_angle)


def reset_pulse(
    design: PRSMDesign,
    screw_speed: float,
    *,
    contact: ImpactContact = PAPER03_CONTACT,
    resisting_force: float = 0.0,
    roller_mass: float | None = None,
) -> ResetPulse:
    """Contact force between the cam-ring chamfer and a roller during one reset.

    The 1-DOF model of the module docstring: the roller, free axially, is driven through
    the IMPACT contact by the chamfer advancing at v_cam = lead·|ω_c|/β; it closes at
    v_cam + lead·|ω_c|/2π. Integrated with LSODA (stiff once damping is on) over τ = β/|ω_c|.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    screw_speed : float [rad/s]
        Non-zero; the sign does not change the pulse.
    contact : ImpactContact
        Default: the paper's §4.1 parameters.
    resisting_force : float [N]
        Constant axial force opposing the reset (≥ 0); 0: none.
    roller_mass : float or None [kg]
        None: ``design.masses.roller_mass``.

    Returns
    -------
    ResetPulse

    References
    ----------
    Paper 03, eqs. (9)–(11) (chamfer α/2 over β), (31) (drift), (38) and §4.1 (contact).
    """
    _require_recirculating(design)
    w_s = _require_speed(screw_speed)
    require(w_s != 0.0, "screw_speed", w_s, "must be non-zero: no reset happens at standstill")
    require(
        isinstance(resisting_force, (int, float))
        and math.isfinite(resisting_force)
        and resisting_force >= 0,
        "resisting_force",
        resisting_force,
        "must be a finite number ≥ 0 [N]",
    )
    mass = design.masses.roller_mass if roller_mass is None else roller_mass
    require_positive("roller_mass", mass)
    require(isinstance(contact, ImpactContact), "contact", contact, "must be an ImpactContact")

    lead = reset_stroke(design)
    beta = orbital_angle(design)
    w_c = abs(carrier_speed(design, w_s))
    tau = beta / w_c
    v0 = lead * w_c / beta + lead * w_c / TWO_PI
    gamma = design.roller_tooth_angle / 2
    cg = math.cos(gamma)
    k, e, c, depth = contact.stiffness, contact.exponent, contact.max_damping, contact.depth

    def normal(z: float, zd: float) -> float:
        x = z * cg
        if x <= 0.0:
            return 0.0
        u = min(x / depth, 1.0)
        return max(0.0, k * x**e + c * zd * cg * u * u * (3.0 - 2.0 * u))

    def rhs(_t, y):
        f = normal(y[0], y[1])
        return (y[1], -(f * cg - resisting_force) / mass, f)

    # Scales: undamped Hertz interference (5m·v0²/4k_eff)^(2/5) and its impulse 2m·v0.
    z_scale = (5 * mass * v0**2 / (4 * k * cg ** (e + 1))) ** (1 / (e + 1))
    sol = solve_ivp(
        rhs,
        (0.0, tau),
        (0.0, v0, 0.0),
        method="LSODA",
        rtol=1e-8,
        atol=(1e-6 * z_scale, 1e-8 * v0, 1e-8 * mass * v0),
        max_step=tau / 200,
    )
    if not sol.success:  # pragma: no cover - LSODA on this smooth 3-state system
        raise ConvergenceError(
            f"reset pulse: LSODA integration of the cam-ring/roller contact did not converge "
            f"for screw_speed = {w_s:.6g} rad/s, roller_mass = {mass:.6g} kg, "
            f"resisting_force = {resisting_force:.6g} N, contact = {contact}: {sol.message}"
        )
    z, zd, impulse = sol.y
    force = np.array([normal(a, b) for a, b in zip(z, zd)])
    return ResetPulse(sol.t, z * cg, force, impulse, v0, tau, gamma)


@dataclass(frozen=True)
class ResetForceSeries:
    """Cam-ring/roller contact force sampled over a run.

    Attributes
    ----------
    time : numpy.ndarray [s]
        k/sample_rate.
    normal_force : numpy.ndarray [N]
        Mean normal contact force over each sample's interval [t − Δt/2, t + Δt/2), summed
        over rollers: Σ samples·Δt equals the impulse of all pulses, at any sample rate.
    axial_force : numpy.ndarray [N]
        Its axial component acting on the nut (the cam ring is fixed to it), −sign(ω_s)·
        F_n·cos(α/2): the roller is pushed forward along the nut's travel, the nut back.
    events : ResetEvents
    pulse : ResetPulse or None
        The single-reset pulse (None at zero speed).
    """

    time: np.ndarray
    normal_force: np.ndarray
    axial_force: np.ndarray
    events: ResetEvents
    pulse: ResetPulse | None

    @property
    def peak_force(self) -> float:
        """Peak normal force of one reset, before sampling [N] (0 at zero speed)."""
        return 0.0 if self.pulse is None else self.pulse.peak_force


def reset_force_series(
    design: PRSMDesign,
    geometry: RecirculatingGeometry | None,
    screw_speed: float,
    duration: float,
    sample_rate: float,
    *,
    roller1_angle: float | None = None,
    contact: ImpactContact = PAPER03_CONTACT,
    resisting_force: float = 0.0,
    roller_mass: float | None = None,
) -> ResetForceSeries:
    """Time series of the roller-reset contact force: one pulse per roller per carrier turn.

    Every reset is the same pulse (:func:`reset_pulse`) placed at its event time
    (:func:`reset_events`); each sample is the pulse's impulse over the sample interval
    divided by the interval, so a pulse shorter than a sample is neither lost nor aliased.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    geometry : RecirculatingGeometry or None
        Checked against the design (eqs. 13–22); None: ``RecirculatingGeometry.for_design``.
    screw_speed : float [rad/s]
        Constant, signed; 0 gives a zero signal.
    duration : float [s]
    sample_rate : float [Hz]
    roller1_angle : float or None [rad]
        See :func:`reset_events`.
    contact, resisting_force, roller_mass
        See :func:`reset_pulse`.

    Returns
    -------
    ResetForceSeries

    References
    ----------
    Paper 03 §2.3–2.4 (reset by the platform chamfer α/2, one per carrier revolution),
    eq. (38) and §4.1 (contact).
    """
    _require_recirculating(design)
    if geometry is None:
        geometry = RecirculatingGeometry.for_design(design)
    else:
        check_recirculating(design, geometry)
    w_s = _require_speed(screw_speed)
    require_positive("duration", duration)
    require_positive("sample_rate", sample_rate)
    n = int(math.floor(duration * sample_rate + 1e-9))
    require(n >= 1, "duration·sample_rate", duration * sample_rate, "must give ≥ 1 sample")
    time = np.arange(n) / sample_rate
    events = reset_events(design, w_s, duration, roller1_angle=roller1_angle)
    normal = np.zeros(n)
    pulse = None
    if w_s != 0.0:
        pulse = reset_pulse(
            design, w_s, contact=contact, resisting_force=resisting_force, roller_mass=roller_mass
        )
        dt = 1.0 / sample_rate
        edges = np.append(time - 0.5 * dt, time[-1] + 0.5 * dt)
        total = pulse.impulse[-1]
        for when in events.times:
            lo = np.searchsorted(edges, when, side="right") - 1
            hi = np.searchsorted(edges, when + pulse.crossing_time, side="right") + 1
            lo, hi = max(lo, 0), min(hi, n + 1)
            if hi - lo < 2:
                continue
            cumulative = np.interp(edges[lo:hi] - when, pulse.time, pulse.impulse, 0.0, total)
            normal[lo : hi - 1] += np.diff(cumulative) / dt
    sign = math.copysign(1.0, w_s) if w_s != 0.0 else 0.0
    axial = -sign * normal * math.cos(design.roller_tooth_angle / 2)
    return ResetForceSeries(time, normal, axial, events, pulse)
