"""Recirculating PRSM (paper 03): threadless-area design rules, carrier/cam-ring checks,
kinematics with roller resets, and the cam-ring/roller reset force as a signal.

A recirculating PRSM has grooved rollers (no helix, no gears). Relative to the nut each roller
drifts back by one lead per carrier revolution (eq. 31); in the nut's threadless area the
convex platform of a cam ring lifts it over one screw thread and pushes it forward by that
lead again ("reset"). Each roller resets once per carrier revolution, so the mechanism has
N reset events per carrier revolution, at N·f_c (:func:`~prsm_health.kinematics.
characteristic_frequencies`, ``roller_reset``).

Readings of the paper (Tables 1–2 and the figures are not in the text)
----------------------------------------------------------------------
- **Reset stroke = one lead.** §2.3 makes the platform "one lead n_s·p_s" thick and eq. (17)
  reserves 2·n_s·p_s of groove travel, while eqs. (9), (31), (33) and (34) write p_s: the paper
  only treats single-start screws, where lead = pitch. Here lead = n_s·p is used throughout
  (arc DE, β, L_r1, the reset jump, l_i); for n_s = 1 this is the paper's formula exactly.
- **Eq. (14) is twice what eqs. (11)–(13) give.** β = 2·p_s/(d_c·tan(α/2)) [rad] (eq. 11) and
  β < φ/2 = π/N (eq. 13) give N < π·d_c·tan(α/2)/(2p_s); the printed eq. (14) drops the 2
  (it is β < φ). :class:`~prsm_health.design.PRSMDesign` enforces the printed eq. (14);
  :func:`check_recirculating` enforces eq. (13) itself — at most one roller in the 2β
  threadless area — with the reset stroke of one lead: N < π·d_c·tan(α/2)/(2·n_s·p).
- **Eq. (34) misprint.** As printed, l_i = m + s1 + (N − i − 1)/N·p_s gives l_1 = m + s1 +
  (N − 2)/N·p_s, contradicting eqs. (35)–(37) (l_1 = m + s1 + p_s, l_2 = … (N − 1)/N,
  l_12 = … (N − 11)/N). The coefficient consistent with all three is (N − i + 1)/N, used here.
- **"Orbital angle 1.62π"** in §4.2 is not eq. (11)'s β (0.0161π for the reconstructed
  geometry) but the carrier angle φ_c of eq. (30) over the 0.1 s run (screw turned 4π):
  4π·d_s/(2d_c) = 1.6203π. :func:`motion` returns it as ``carrier_angle``.
- **Roller numbering and start angle.** Roller i sits (i − 1)·φ behind roller 1, which starts
  against the cam platform at the entrance of the threadless area (§3.2 steps 4–6). This is
  the only order consistent with §4.2–4.3: roller 7 resets after half a carrier turn (model
  0.062 s, paper "0.06–0.07 s") and rollers 11, 12 have not reset by 0.1 s.
- **Threadless-area layout.** The area spans 2β centred on angle 0 of the nut frame; forward
  rotation (ω_s > 0) crosses [−β, 0], reverse rotation [+β, 0] ("operated in forward and
  reverse rotation, so the angle … is 2β", §2.1).
- **Carrier arc FG / cam arc IJ (eq. 22).** Read as the central angle of one carrier groove
  (width 2R_b) at the carrier outer diameter, matched by the platform arc: the carrier groove
  centre line is assembled on the platform centre line (§3.2 step 3).

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
damping (C = 50 N·s/mm against a 20 g roller) the impact is damping-dominated; the axial
momentum it transfers lies between m_r·v0 and 2·m_r·v0 (restitution 0…1) whatever the contact
law, the peak does not. The sampled series keeps the
momentum exactly (each sample is the mean force over its interval), so it can be added to a
nut acceleration at any sample rate.

References
----------
Paper 03: ../shared/papers/03-recirculating-prsm-design-dynamics.txt — eqs. (1)–(22) design,
(23)–(33) motion, (34)–(37) assembly, (38) and §4.1 contact parameters, §4.2–4.3 results.
MSC ADAMS/Solver, IMPACT and STEP functions (cubic STEP: h0 + (h1 − h0)·Δ²(3 − 2Δ)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from scipy.integrate import solve_ivp

from .design import PRSMDesign, recirculating_roller_limit
from .errors import require, require_positive
from .kinematics import characteristic_frequencies, speed_ratios

TWO_PI = 2.0 * math.pi

#: Relative allowance of the paper's design *equalities* that are sliding fits — eq. (17)
#: groove length, (18) groove end radius, (20) platform bore on the carrier: the paper's own
#: simulation shows "a small gap between the roller and the carrier" (§4.3), so the part may
#: be larger than the nominal value by up to 2 % (80 µm on a 4 mm groove radius), never smaller.
FIT_TOLERANCE = 2e-2

#: Relative tolerance of eq. (22), φ_b = φ_t1, an equality of two machined arcs.
ANGLE_TOLERANCE = 1e-3


# ------------------------------------------------------------------------- helpers
def _require_recirculating(design: PRSMDesign) -> None:
    require(
        isinstance(design, PRSMDesign) and design.variant == "recirculating",
        "design.variant",
        getattr(design, "variant", design),
        "must be 'recirculating' (paper 03 design rules and resets apply to grooved rollers)",
    )


def _require_speed(screw_speed) -> float:
    require(
        isinstance(screw_speed, (int, float, np.floating, np.integer))
        and math.isfinite(screw_speed),
        "screw_speed",
        screw_speed,
        "must be a finite number [rad/s] (sign = direction of rotation)",
    )
    return float(screw_speed)


def _require_times(time) -> np.ndarray:
    t = np.asarray(time, dtype=float)
    require(
        t.ndim <= 1 and bool(np.all(np.isfinite(t))) and bool(np.all(t >= 0.0)),
        "time",
        f"array of shape {t.shape}" if t.ndim else float(t),
        "must be finite times ≥ 0 [s] from run start (scalar or 1-D)",
    )
    return np.atleast_1d(t)


# ------------------------------------------------------------------------- eqs (5)–(12)
def roller_arc_radius(design: PRSMDesign) -> float:
    """Radius of the roller's circular thread profile R_r2 = d_r/(2 sin(α/2)).

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.

    Returns
    -------
    float [m]
        Equal to the design's default ``roller_thread_radius`` (sin(α/2) = cos β).

    References
    ----------
    Paper 03, eq. (5).
    """
    _require_recirculating(design)
    return design.roller_diameter / (2.0 * math.sin(design.roller_tooth_angle / 2))


def radial_lift(design: PRSMDesign) -> float:
    """Maximum radial lift of the roller centre while crossing the screw thread, h_r.

    h_r = (d_r3 − d_r)/2 + (d_s3 − d_s)/2: the roller crest must clear the screw crest.

    Returns
    -------
    float [m]

    References
    ----------
    Paper 03, eq. (7).
    """
    _require_recirculating(design)
    return (design.roller_major_diameter - design.roller_diameter) / 2 + (
        design.screw_major_diameter - design.screw_diameter
    ) / 2


def lift_radius(design: PRSMDesign) -> float:
    """Distance of the roller centre from the screw axis at its highest point A′, R_r3.

    Returns
    -------
    float [m]
        d_r/2 + d_s/2 + h_r.

    References
    ----------
    Paper 03, eq. (6).
    """
    return design.roller_diameter / 2 + design.screw_diameter / 2 + radial_lift(design)


def threadless_radius(design: PRSMDesign) -> float:
    """Radius of the nut threadless area R_r1 (clears the lifted roller's crest).

    Returns
    -------
    float [m]
        d_s/2 + d_r + (d_r3 − d_r)/2 + h_r, i.e. R_r3 + d_r3/2.

    References
    ----------
    Paper 03, eq. (8).
    """
    return (
        design.screw_diameter / 2
        + design.roller_diameter
        + (design.roller_major_diameter - design.roller_diameter) / 2
        + radial_lift(design)
    )


def reset_stroke(design: PRSMDesign) -> float:
    """Axial jump of a roller relative to the nut in one reset: one lead n_s·p [m].

    References
    ----------
    Paper 03 §2.3 (platform thickness one lead n_s·p_s), eq. (33) (+p for n_s = 1).
    """
    _require_recirculating(design)
    return design.screw_lead


def arc_de(design: PRSMDesign) -> float:
    """Arc DE of the threadless area on the roller orbit that one crossing takes [m].

    DE = lead / tan(α/2): the platform chamfer α/2 raises the roller by one lead.

    References
    ----------
    Paper 03, eq. (9) (p_s there; lead for multi-start, see module docstring).
    """
    return reset_stroke(design) / math.tan(design.roller_tooth_angle / 2)


def orbital_angle(design: PRSMDesign) -> float:
    """Orbital angle β a roller needs to cross one screw thread [rad].

    β = DE/(d_c/2) = 2·lead/(d_c·tan(α/2)); eq. (11) gives it in degrees. Divide by π for the
    paper's "multiple of π" form (``ThreadlessArea.orbital_angle_over_pi``).

    References
    ----------
    Paper 03, eqs. (10)–(11).
    """
    return 2.0 * arc_de(design) / design.orbit_diameter


def threadless_angle(design: PRSMDesign) -> float:
    """Angle of the nut threadless area, 2β (one β per direction of rotation) [rad].

    References
    ----------
    Paper 03 §2.1, after eq. (11).
    """
    return 2.0 * orbital_angle(design)


def roller_spacing(design: PRSMDesign) -> float:
    """Angle between neighbouring rollers φ = 2π/N [rad].

    References
    ----------
    Paper 03, eq. (12).
    """
    _require_recirculating(design)
    return TWO_PI / design.n_rollers


@dataclass(frozen=True)
class ThreadlessArea:
    """The threadless-area quantities of paper 03 eqs. (5)–(12) for one design.

    Attributes
    ----------
    roller_arc_radius : float [m]
        R_r2, eq. (5).
    radial_lift : float [m]
        h_r, eq. (7).
    lift_radius : float [m]
        R_r3, eq. (6).
    radius : float [m]
        R_r1, eq. (8).
    arc_de : float [m]
        Eq. (9).
    orbital_angle : float [rad]
        β, eq. (11).
    angle : float [rad]
        2β.
    roller_spacing : float [rad]
        φ, eq. (12).
    reset_stroke : float [m]
        One lead.
    """

    roller_arc_radius: float
    radial_lift: float
    lift_radius: float
    radius: float
    arc_de: float
    orbital_angle: float
    angle: float
    roller_spacing: float
    reset_stroke: float

    @property
    def orbital_angle_over_pi(self) -> float:
        """β/π [-], the paper's "multiple of π" form."""
        return self.orbital_angle / math.pi

    @property
    def orbital_angle_deg(self) -> float:
        """β in degrees, eq. (11)'s form [°]."""
        return math.degrees(self.orbital_angle)


def threadless_area(design: PRSMDesign) -> ThreadlessArea:
    """All threadless-area quantities of a recirculating design.

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    ThreadlessArea

    References
    ----------
    Paper 03, eqs. (5)–(12).
    """
    beta = orbital_angle(design)
    return ThreadlessArea(
        roller_arc_radius=roller_arc_radius(design),
        radial_lift=radial_lift(design),
        lift_radius=lift_radius(design),
        radius=threadless_radius(design),
        arc_de=arc_de(design),
        orbital_angle=beta,
        angle=2.0 * beta,
        roller_spacing=roller_spacing(design),
        reset_stroke=reset_stroke(design),
    )


# ------------------------------------------------------------------------- carrier, cam ring
def groove_length(
    design: PRSMDesign, roller_half_length_1: float, roller_half_length_2: float, end_radius: float
) -> float:
    """Length of the carrier's straight groove l_b = 2R_b + 2·n_s·p_s + s1 + s2 [m].

    Parameters
    ----------
    design : PRSMDesign
    roller_half_length_1, roller_half_length_2 : float [m]
        s1, s2.
    end_radius : float [m]
        R_b, radius of the groove's end arcs.

    References
    ----------
    Paper 03, eq. (17).
    """
    _require_recirculating(design)
    return 2.0 * end_radius + 2.0 * design.screw_lead + roller_half_length_1 + roller_half_length_2


@dataclass(frozen=True)
class RecirculatingGeometry:
    """Carrier, cam-ring and assembly dimensions that paper 03 adds to a recirculating design.

    Build it with :meth:`for_design`, which fills every dimension the paper leaves open
    (Table 1 is not printed) from the design and checks eqs. (13)–(22) against it. The
    constructor itself only checks that each value is a finite positive number.

    Parameters
    ----------
    carrier_outer_diameter : float [m]
        D_B. Default: middle of eq. (15)'s interval (d_s3 + d_r1, d_n1), the largest margin
        to both the screw/roller crests and the nut crest.
    carrier_inner_diameter : float [m]
        d_b. Default: middle of (d_s3, d_c), so the carrier wall straddles the roller-centre
        orbit and the groove flanks push the roller at its axis height.
    groove_length : float [m]
        l_b. Default: eq. (17) with the values below.
    groove_end_radius : float [m]
        R_b. Default: d_r3/2 (eq. 18).
    roller_half_length_1, roller_half_length_2 : float [m]
        s1, s2. Default: engaged_threads·pitch/2 each (a roller as long as its grooves).
    cam_inner_diameter : float [m]
        d_t. Default: the carrier bore d_b (same running clearance to the screw crest).
    platform_inner_diameter : float [m]
        d_t1. Default: D_B (eq. 20; the platform bore runs on the carrier).
    platform_outer_radius : float [m]
        R_t1. Default: middle of (d_t1/2, d_n1/2) (eq. 21 and a platform of positive width).
    cam_step_thickness : float [m]
        z_t1. Default: R_b (paper silent; an end step as thick as the carrier groove radius).
    carrier_arc_angle : float [rad]
        φ_b, central angle of one groove (width 2R_b) at the carrier outer diameter,
        2·asin(2R_b/D_B) (reading of Figure 5, not printed).
    platform_arc_angle : float [rad]
        φ_t1. Default: φ_b (eq. 22).
    axial_offset : float [m]
        m of eq. (34). Default: z_t1, which makes eq. (35)'s l_1 = m + s1 + p_s coincide with
        the carrier plane b1 at z_t1 + n_s·p_s + s1 (§2.2) when carrier and cam ring end
        faces are flush.

    References
    ----------
    Paper 03, eqs. (13)–(22), (34)–(35), §2.2–2.3 and §3.2.
    """

    carrier_outer_diameter: float
    carrier_inner_diameter: float
    groove_length: float
    groove_end_radius: float
    roller_half_length_1: float
    roller_half_length_2: float
    cam_inner_diameter: float
    platform_inner_diameter: float
    platform_outer_radius: float
    cam_step_thickness: float
    carrier_arc_angle: float
    platform_arc_angle: float
    axial_offset: float

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "axial_offset":
                require(
                    isinstance(value, (int, float)) and math.isfinite(value) and value >= 0,
                    f"geometry.{f.name}",
                    value,
                    "must be a finite number ≥ 0 [m]",
                )
            else:
                require_positive(f"geometry.{f.name}", value)

    @classmethod
    def for_design(cls, design: PRSMDesign, **overrides) -> RecirculatingGeometry:
        """Geometry with the documented defaults, some overridden, checked against the design.

        Defaults that depend on an overridden value follow it (e.g. ``groove_length`` follows
        ``groove_end_radius``).

        Parameters
        ----------
        design : PRSMDesign
            Recirculating design.
        **overrides : float
            Any field of :class:`RecirculatingGeometry` [m or rad].

        Raises
        ------
        ParameterError
            Unknown field, or a value that violates eqs. (13)–(22).
        """
        _require_recirculating(design)
        _check_names(overrides)
        o = dict(overrides)

        def get(name, default):
            return o[name] if name in o else default()

        d_s3, d_r1, d_n1 = (
            design.screw_major_diameter,
            design.roller_root_diameter,
            design.nut_minor_diameter,
        )
        outer = get("carrier_outer_diameter", lambda: 0.5 * (d_s3 + d_r1 + d_n1))
        inner = get("carrier_inner_diameter", lambda: 0.5 * (d_s3 + design.orbit_diameter))
        r_b = get("groove_end_radius", lambda: design.roller_major_diameter / 2)
        half = design.engaged_threads * design.pitch / 2
        s1 = get("roller_half_length_1", lambda: half)
        s2 = get("roller_half_length_2", lambda: half)
        l_b = get("groove_length", lambda: groove_length(design, s1, s2, r_b))
        d_t = get("cam_inner_diameter", lambda: inner)
        d_t1 = get("platform_inner_diameter", lambda: outer)
        r_t1 = get("platform_outer_radius", lambda: 0.25 * (d_t1 + d_n1))
        z_t1 = get("cam_step_thickness", lambda: r_b)
        phi_b = get("carrier_arc_angle", lambda: 2.0 * math.asin(min(1.0, 2.0 * r_b / outer)))
        phi_t1 = get("platform_arc_angle", lambda: phi_b)
        m = get("axial_offset", lambda: z_t1)
        geometry = cls(
            carrier_outer_diameter=outer,
            carrier_inner_diameter=inner,
            groove_length=l_b,
            groove_end_radius=r_b,
            roller_half_length_1=s1,
            roller_half_length_2=s2,
            cam_inner_diameter=d_t,
            platform_inner_diameter=d_t1,
            platform_outer_radius=r_t1,
            cam_step_thickness=z_t1,
            carrier_arc_angle=phi_b,
            platform_arc_angle=phi_t1,
            axial_offset=m,
        )
        check_recirculating(design, geometry)
        return geometry

    def with_(self, **changes) -> RecirculatingGeometry:
        """A copy with some fields changed (positivity checked; call
        :func:`check_recirculating` to check it against a design)."""
        _check_names(changes)
        return replace(self, **changes)


def _check_names(names) -> None:
    known = {f.name for f in fields(RecirculatingGeometry)}
    for name in names:
        require(
            name in known,
            "geometry",
            name,
            f"unknown field; known fields: {', '.join(sorted(known))}",
        )


def _fit(field: str, value: float, nominal: float, eq: str, what: str) -> None:
    """A sliding-fit equality: value ∈ [nominal, nominal·(1 + FIT_TOLERANCE)]."""
    require(
        nominal <= value <= nominal * (1.0 + FIT_TOLERANCE),
        field,
        value,
        f"must equal {what} = {nominal:.6g} within +{FIT_TOLERANCE:.0%} running clearance, "
        f"i.e. lie in [{nominal:.6g}, {nominal * (1 + FIT_TOLERANCE):.6g}] (paper 03 {eq})",
    )


def eq13_roller_limit(design: PRSMDesign) -> float:
    """Roller-count bound of eq. (13), β < φ/2: N < π·d_c·tan(α/2)/(2·n_s·p) [-].

    The bound :class:`~prsm_health.design.PRSMDesign` enforces at construction
    (:func:`~prsm_health.design.recirculating_roller_limit`); half the printed eq. (14).

    References
    ----------
    Paper 03, eqs. (11)–(14).
    """
    _require_recirculating(design)
    return recirculating_roller_limit(design)


def check_recirculating(design: PRSMDesign, geometry: RecirculatingGeometry) -> None:
    """Check a recirculating design and its carrier/cam-ring geometry against paper 03.

    The roller count (eq. 13, β < φ/2: N < π·d_c·tan(α/2)/(2·n_s·p), half the printed
    eq. 14) is already enforced when the design is built.

    Parameters
    ----------
    design : PRSMDesign
    geometry : RecirculatingGeometry

    Raises
    ------
    ParameterError
        Naming the violated field, its value and the allowed range.

    References
    ----------
    Paper 03, eqs. (13)–(22); a ring's bore must be smaller than its outside (d_b < D_B,
    d_t < d_t1, d_t1/2 < R_t1) and a groove narrower than the roller spacing (φ_b < φ).
    """
    _require_recirculating(design)
    require(
        isinstance(geometry, RecirculatingGeometry),
        "geometry",
        type(geometry).__name__,
        "must be a RecirculatingGeometry",
    )
    g = geometry
    # eq. (13) (the roller count) is enforced when the design is built
    d_s3, d_r1, d_n1 = (
        design.screw_major_diameter,
        design.roller_root_diameter,
        design.nut_minor_diameter,
    )
    low = d_s3 + d_r1
    require(
        low < g.carrier_outer_diameter < d_n1,
        "geometry.carrier_outer_diameter",
        g.carrier_outer_diameter,
        f"must lie in (d_s3 + d_r1, d_n1) = ({low:.6g}, {d_n1:.6g}) m (paper 03 eq. 15)",
    )
    require(
        d_s3 < g.carrier_inner_diameter < g.carrier_outer_diameter,
        "geometry.carrier_inner_diameter",
        g.carrier_inner_diameter,
        f"must lie in (d_s3, D_B) = ({d_s3:.6g}, {g.carrier_outer_diameter:.6g}) m "
        "(paper 03 eq. 16)",
    )
    _fit(
        "geometry.groove_end_radius",
        g.groove_end_radius,
        design.roller_major_diameter / 2,
        "eq. 18",
        "d_r3/2",
    )
    _fit(
        "geometry.groove_length",
        g.groove_length,
        groove_length(design, g.roller_half_length_1, g.roller_half_length_2, g.groove_end_radius),
        "eq. 17",
        "2R_b + 2n_s·p_s + s1 + s2",
    )
    require(
        d_s3 < g.cam_inner_diameter < g.platform_inner_diameter,
        "geometry.cam_inner_diameter",
        g.cam_inner_diameter,
        f"must lie in (d_s3, d_t1) = ({d_s3:.6g}, {g.platform_inner_diameter:.6g}) m "
        "(paper 03 eq. 19)",
    )
    _fit(
        "geometry.platform_inner_diameter",
        g.platform_inner_diameter,
        g.carrier_outer_diameter,
        "eq. 20",
        "D_B",
    )
    require(
        g.platform_inner_diameter / 2 < g.platform_outer_radius < d_n1 / 2,
        "geometry.platform_outer_radius",
        g.platform_outer_radius,
        f"must lie in (d_t1/2, d_n1/2) = ({g.platform_inner_diameter / 2:.6g}, "
        f"{d_n1 / 2:.6g}) m (paper 03 eq. 21)",
    )
    spacing = roller_spacing(design)
    require(
        g.carrier_arc_angle < spacing,
        "geometry.carrier_arc_angle",
        g.carrier_arc_angle,
        f"must be < the roller spacing φ = 2π/N = {spacing:.6g} rad",
    )
    require(
        abs(g.platform_arc_angle - g.carrier_arc_angle) <= ANGLE_TOLERANCE * g.carrier_arc_angle,
        "geometry.platform_arc_angle",
        g.platform_arc_angle,
        f"must equal φ_b = {g.carrier_arc_angle:.6g} rad within {ANGLE_TOLERANCE:.1%} "
        "(paper 03 eq. 22)",
    )


def roller_axial_offsets(design: PRSMDesign, geometry: RecirculatingGeometry) -> np.ndarray:
    """Distance l_i from each roller's centre plane to the left end face of the cam ring.

    l_i = m + s1 + (N − i + 1)/N·lead, i = 1 … N: neighbouring rollers, φ apart on the nut
    helix, sit lead/N apart axially.

    Returns
    -------
    numpy.ndarray [m], shape (N,)
        l_1 … l_N.

    References
    ----------
    Paper 03, eqs. (34)–(37); eq. (34) as printed, (N − i − 1)/N, contradicts eqs. (35)–(37)
    (module docstring); the coefficient (N − i + 1)/N satisfies all three.
    """
    check_recirculating(design, geometry)
    n = design.n_rollers
    i = np.arange(1, n + 1)
    return (
        geometry.axial_offset
        + geometry.roller_half_length_1
        + (n - i + 1) / n * reset_stroke(design)
    )


def cam_ring_spacing(design: PRSMDesign, geometry: RecirculatingGeometry) -> float:
    """Axial spacing of the two cam rings h = s1 + s2 + lead/N + lead [m].

    References
    ----------
    Paper 03 §3.2, assembly step (1) (p_s there; lead for multi-start).
    """
    check_recirculating(design, geometry)
    lead = reset_stroke(design)
    return (
        geometry.roller_half_length_1
        + geometry.roller_half_length_2
        + lead / design.n_rollers
        + lead
    )


# ------------------------------------------------------------------------- kinematics
def carrier_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Carrier (roller revolution) speed ω_c = d_s/(2d_c)·ω_s [rad/s], signed like ω_s.

    References
    ----------
    Paper 03, eq. (25), via :func:`prsm_health.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).carrier * _require_speed(screw_speed)


def roller_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Absolute roller spin ω_r = −d_s/(2d_r)·ω_s [rad/s] (opposite to the screw).

    References
    ----------
    Paper 03, eqs. (26)–(27), via :func:`prsm_health.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).roller_spin * _require_speed(screw_speed)


def nut_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Nut axial speed v_n = n·p·ω_s/2π [m/s], signed like ω_s.

    References
    ----------
    Paper 03, eq. (29), via :func:`prsm_health.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).nut * _require_speed(screw_speed)


def _start_angles(design: PRSMDesign, roller1_angle: float | None) -> np.ndarray:
    beta = orbital_angle(design)
    if roller1_angle is None:
        roller1_angle = -beta
    require(
        isinstance(roller1_angle, (int, float)) and math.isfinite(roller1_angle),
        "roller1_angle",
        roller1_angle,
        "must be a finite angle [rad]",
    )
    i = np.arange(design.n_rollers)
    return roller1_angle - i * roller_spacing(design)


def _first_travel(design: PRSMDesign, screw_speed: float, roller1_angle) -> np.ndarray:
    """Carrier travel [rad, ≥ 0] before each roller next enters its crossing sector."""
    beta = orbital_angle(design)
    theta0 = _start_angles(design, roller1_angle)
    # Forward rotation enters the threadless area at −β, reverse rotation at +β.
    travel = (-beta - theta0) if screw_speed > 0 else (theta0 - beta)
    travel = np.mod(travel, TWO_PI)
    return np.where(travel >= TWO_PI, travel - TWO_PI, travel)


@dataclass(frozen=True)
class ResetEvents:
    """Roller reset events of a run, sorted by time.

    Attributes
    ----------
    times : numpy.ndarray [s]
        Instants a roller enters its crossing sector (contact with the platform chamfer).
    rollers : numpy.ndarray of int
        Roller number (1 … N) of each event.
    crossing_time : float [s]
        τ = β/|ω_c|, time spent crossing arc DE (inf at zero speed).
    rate : float [Hz]
        Reset events per second, N·f_c.
    """

    times: np.ndarray
    rollers: np.ndarray
    crossing_time: float
    rate: float

    @property
    def end_times(self) -> np.ndarray:
        """Instants each crossing ends (roller re-engages at E) [s]."""
        return self.times + self.crossing_time

    def __len__(self) -> int:
        return len(self.times)


def reset_events(
    design: PRSMDesign,
    screw_speed: float,
    duration: float,
    *,
    roller1_angle: float | None = None,
) -> ResetEvents:
    """When each roller enters the threadless area during a run at constant screw speed.

    Roller i starts at θ_i = θ_1 − (i − 1)·φ (nut frame, angle 0 = centre of the threadless
    area, positive in the sense of positive screw rotation) and moves with the carrier,
    θ_i(t) = θ_i + ω_c·t. It resets each time it reaches the crossing sector's entrance, −β
    going forward, +β going backward: exactly once per carrier revolution in either
    direction. A roller already inside the sector at t = 0 is taken as having crossed.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    screw_speed : float [rad/s]
        Signed; 0 gives no events.
    duration : float [s]
        Events are reported in [0, duration).
    roller1_angle : float or None [rad]
        θ_1. None: −β, roller 1 against the cam platform at the entrance (§3.2 step 4), so
        roller 1 resets at t = 0 when turning forward.

    Returns
    -------
    ResetEvents

    References
    ----------
    Paper 03 §2.1 (2β threadless area), §3.2 (assembly angles), eq. (25) (ω_c); reset rate
    N·f_c from :func:`prsm_health.kinematics.characteristic_frequencies`.
    """
    _require_recirculating(design)
    w_s = _require_speed(screw_speed)
    require_positive("duration", duration)
    beta = orbital_angle(design)
    w_c = carrier_speed(design, w_s)
    rate = characteristic_frequencies(design, w_s).roller_reset
    if w_c == 0.0:
        _start_angles(design, roller1_angle)  # still validate the angle
        empty = np.zeros(0)
        return ResetEvents(empty, np.zeros(0, dtype=int), math.inf, 0.0)
    period = TWO_PI / abs(w_c)
    first = _first_travel(design, w_s, roller1_angle) / abs(w_c)
    n_rev = int(math.ceil(duration / period)) + 1
    times = first[:, None] + period * np.arange(n_rev)[None, :]
    rollers = np.broadcast_to(np.arange(1, design.n_rollers + 1)[:, None], times.shape)
    keep = times < duration
    t, r = times[keep], rollers[keep]
    order = np.argsort(t, kind="stable")
    return ResetEvents(t[order], r[order].astype(int), beta / abs(w_c), rate)


@dataclass(frozen=True)
class RecirculatingMotion:
    """Rigid-body motion of a recirculating PRSM at constant screw speed (all signed, SI).

    Attributes
    ----------
    time : numpy.ndarray [s]
    screw_angle : numpy.ndarray [rad]
        φ_s = ω_s·t.
    carrier_angle : numpy.ndarray [rad]
        φ_c = (ω_c/ω_s)·φ_s, eq. (30): the "orbital angle" of §4.2.
    nut : numpy.ndarray [m]
        L_n, nut displacement relative to the (axially fixed) screw, eq. (28).
    roller_drift : numpy.ndarray [m]
        L_r1 = lead·φ_c/2π, eq. (31): how far the rollers lag the nut (opposite to its travel).
    roller_threaded : numpy.ndarray [m]
        L_r2 = L_n − L_r1, eq. (32): roller relative to the screw without resets.
    roller : numpy.ndarray [m], shape (N, len(time))
        L_r3 of each roller, eq. (33) generalised: L_r2 plus one lead per completed reset,
        the jump spread linearly over the crossing time τ (the chamfer lifts at constant
        axial speed).
    resets : numpy.ndarray [-], shape (N, len(time))
        Resets completed by each roller (fractional during a crossing).
    """

    time: np.ndarray
    screw_angle: np.ndarray
    carrier_angle: np.ndarray
    nut: np.ndarray
    roller_drift: np.ndarray
    roller_threaded: np.ndarray
    roller: np.ndarray
    resets: np.ndarray

    @property
    def roller_relative_to_nut(self) -> np.ndarray:
        """Roller axial position relative to the nut, L_r3 − L_n [m], shape (N, T)."""
        return self.roller - self.nut[None, :]


def motion(
    design: PRSMDesign,
    screw_speed: float,
    time,
    *,
    roller1_angle: float | None = None,
) -> RecirculatingMotion:
    """Nut and roller displacements with one reset per roller per carrier revolution.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    screw_speed : float [rad/s]
        Constant, signed.
    time : array_like [s]
        Times ≥ 0 from run start.
    roller1_angle : float or None [rad]
        See :func:`reset_events`.

    Returns
    -------
    RecirculatingMotion

    References
    ----------
    Paper 03, eqs. (28), (30)–(33); the reset of one lead, §2.3.
    """
    _require_recirculating(design)
    w_s = _require_speed(screw_speed)
    t = _require_times(time)
    ratios = speed_ratios(design)
    lead = reset_stroke(design)
    phi_s = w_s * t
    phi_c = ratios.carrier * phi_s
    nut = ratios.nut * phi_s
    drift = lead * phi_c / TWO_PI
    threaded = nut - drift
    resets = np.zeros((design.n_rollers, t.size))
    if w_s != 0.0 and t.size:
        # Events at or after the last time contribute nothing, so [0, t_max) suffices.
        horizon = max(float(t.max()), np.finfo(float).tiny)
        events = reset_events(design, w_s, horizon, roller1_angle=roller1_angle)
        tau = events.crossing_time
        for when, roller in zip(events.times, events.rollers):
            resets[roller - 1] += np.clip((t - when) / tau, 0.0, 1.0)
    else:
        _start_angles(design, roller1_angle)
    roller = threaded[None, :] + math.copysign(lead, w_s) * resets
    return RecirculatingMotion(t, phi_s, phi_c, nut, drift, threaded, roller, resets)


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
        raise RuntimeError(f"reset pulse integration failed: {sol.message}")
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
