"""Recirculating PRSM geometry (paper 03): threadless-area design rules, carrier/cam-ring
checks and assembly offsets.

A recirculating PRSM has grooved rollers (no helix, no gears). In the nut's threadless area the
convex platform of a cam ring lifts each roller over one screw thread and pushes it forward by
one lead (a "reset", :mod:`prsm_health.physics.recirculating.travel`). This module holds the
dimensions that make that possible: the threadless area (eqs. 5–12), the carrier and cam-ring
design rules (eqs. 13–22) and the axial roller offsets of the assembly (eqs. 34–37).

Readings of the paper (Tables 1–2 and the figures are not in the text)
----------------------------------------------------------------------
- **Reset stroke = one lead.** §2.3 makes the platform "one lead n_s·p_s" thick and eq. (17)
  reserves 2·n_s·p_s of groove travel, while eqs. (9), (31), (33) and (34) write p_s: the paper
  only treats single-start screws, where lead = pitch. Here lead = n_s·p is used throughout
  (arc DE, β, L_r1, the reset jump, l_i); for n_s = 1 this is the paper's formula exactly.
- **Eq. (14) is twice what eqs. (11)–(13) give.** β = 2·p_s/(d_c·tan(α/2)) [rad] (eq. 11) and
  β < φ/2 = π/N (eq. 13) give N < π·d_c·tan(α/2)/(2p_s); the printed eq. (14) drops the 2
  (it is β < φ). :class:`~prsm_health.actuator.design.PRSMDesign` enforces the printed eq. (14);
  :func:`check_recirculating` enforces eq. (13) itself — at most one roller in the 2β
  threadless area — with the reset stroke of one lead: N < π·d_c·tan(α/2)/(2·n_s·p).
- **Eq. (34) misprint.** As printed, l_i = m + s1 + (N − i − 1)/N·p_s gives l_1 = m + s1 +
  (N − 2)/N·p_s, contradicting eqs. (35)–(37) (l_1 = m + s1 + p_s, l_2 = … (N − 1)/N,
  l_12 = … (N − 11)/N). The coefficient consistent with all three is (N − i + 1)/N, used here.
- **Threadless-area layout.** The area spans 2β centred on angle 0 of the nut frame; forward
  rotation (ω_s > 0) crosses [−β, 0], reverse rotation [+β, 0] ("operated in forward and
  reverse rotation, so the angle … is 2β", §2.1).
- **Carrier arc FG / cam arc IJ (eq. 22).** Read as the central angle of one carrier groove
  (width 2R_b) at the carrier outer diameter, matched by the platform arc: the carrier groove
  centre line is assembled on the platform centre line (§3.2 step 3).

References
----------
Paper 03 (docs/references.md) — eqs. (1)–(22) design, (34)–(37) assembly, §3.2 assembly steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from prsm_health.actuator.design import PRSMDesign, recirculating_roller_limit
from prsm_health.actuator.recirculation_spec import RecirculationSpec
from prsm_health.core.errors import ParameterError, require, require_positive

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

        What the design's ``[recirculation]`` table sets (``design.recirculation``) replaces
        the defaults, and ``overrides`` replace both. Defaults that depend on an overridden
        value follow it (e.g. ``groove_length`` follows ``groove_end_radius``).

        Parameters
        ----------
        design : PRSMDesign
            Recirculating design.
        **overrides : float
            Any field of :class:`RecirculatingGeometry` [m or rad].

        Raises
        ------
        ParameterError
            Unknown field, or a value that violates eqs. (13)–(22); a value the design's
            table set is named as its field there (``design.recirculation.groove_length``).
        """
        _require_recirculating(design)
        _check_names(overrides)
        given = design.recirculation.given() if design.recirculation is not None else {}
        try:
            return cls._built(design, {**given, **overrides})
        except ParameterError as exc:
            name = exc.field.removeprefix("geometry.")
            if name in given and name not in overrides:
                raise ParameterError(
                    f"design.recirculation.{name}", exc.value, exc.allowed
                ) from None
            raise

    @classmethod
    def _built(cls, design: PRSMDesign, o: dict) -> RecirculatingGeometry:

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


def with_explicit_geometry(design: PRSMDesign) -> PRSMDesign:
    """The design with every field of its checked geometry written out in its
    ``recirculation`` table (what ``design template --variant recirculating`` prints, so a
    user sees and edits the numbers paper 03's rules give)."""
    geometry = RecirculatingGeometry.for_design(design)
    values = {f.name: getattr(geometry, f.name) for f in fields(geometry)}
    return replace(design, recirculation=RecirculationSpec(**values))


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

    The bound :class:`~prsm_health.actuator.design.PRSMDesign` enforces at construction
    (:func:`~prsm_health.actuator.design.recirculating_roller_limit`); half the printed eq. (14).

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


def platform_contact_offset(design: PRSMDesign, geometry: RecirculatingGeometry) -> float:
    """Radial offset of the platform's contact on a roller's end face from the roller's axis
    [m], outward positive: the middle of the platform's annulus, d_t1/2 … R_t1 (eqs. 20–21),
    less the orbit radius d_c/2 — an engineering choice where the paper prints no contact point
    (the sign decides which way the platform's friction turns the spin: outside the axis the
    face slips forward and the spin speeds up)."""
    middle = 0.5 * (geometry.platform_inner_diameter / 2 + geometry.platform_outer_radius)
    return middle - design.orbit_diameter / 2


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
