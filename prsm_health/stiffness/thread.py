"""Thread contacts, load distribution over the engaged threads and PRSM axial stiffness.

Load path of an axial load F (nut loaded, screw held by its axial bearing)::

    nut ─┬─ roller 1: nut-side threads ── roller body ── screw-side threads ─┬─ screw shaft ─ bearing
         ├─ roller 2: …                                                     │  K = E·A/L_free
         └─ roller n_R                                                      ┘

Rollers share the load in parallel; within one roller the nut-side engagement and the
screw-side engagement are in series; within one engagement the ``engaged_threads`` thread
pairs carry load in parallel, and the compliance of the bodies between adjacent threads makes
the sharing non-uniform (deformation compatibility, paper 04). One thread pair is a Hertz
point contact (δ ∝ Q^(2/3)) in series with the two thread teeth (linear).

Geometry
    Principal curvatures come from differential geometry of the thread surfaces (paper 04):
    each flank is a helical surface r(θ, ρ) = (ρ cos θ, ρ sin θ, h·θ + f(ρ)), h = lead/2π,
    with f the axial profile — a straight flank for screw and nut, the circle of radius
    ``roller_thread_radius`` for the roller. Its first and second fundamental forms give the
    Gaussian and mean curvature, the principal curvatures and directions, evaluated at the
    nominal contact points on the pitch diameters, in the common axial plane of screw and
    roller axes. Screw, roller and nut threads have the same hand; on the roller–nut side the
    normals of the two surfaces coincide (equal lead angles), on the screw side they differ by
    ≈ sin β·(tan λ_s + tan λ_r) because the true contact point lies off the axial plane
    (:attr:`ContactGeometry.normal_misalignment` reports it). That offset is ignored here, as
    in papers 04 and 05; the principal curvatures are those at the nominal point.
Axial ↔ normal
    Q = F_axial/(sin β·cos λ) (paper 05) with λ the lead angle of the screw (screw side) or
    the nut (nut side); the axial approach is δ_n/(sin β·cos λ) by virtual work.
Thread teeth
    Yamamoto's thread-tooth formulas (bending, shear, root inclination by moment and by
    shear, radial contraction/expansion of the core), derived for a trapezoidal tooth of
    the design's pitch, contact angle and dedendum (:func:`tooth_compliances`). Yamamoto's
    load is a line load W [N/m] along an axisymmetrically loaded thread ring; here the load of
    one contact is spread over the thread length that carries it: π·d_s/n_R on the screw
    (n_R rollers load each screw thread ring), π·d_n/n_R on the nut, π·d_r on the roller (one
    contact per flank and turn). This axisymmetric reading is the one Yamamoto's bolt–nut
    theory and paper 04's annular plate both make; the concentration of a point load makes
    the real tooth somewhat more compliant. For Hertz-dominated designs the tooth share of
    the deformation is reported in :attr:`AxialStiffness.deformation_split`.
Bodies
    Screw, roller and nut cores are bars between adjacent threads (pitch p): compliance
    p/(E·A) with A on the pitch diameter (screw, roller; paper 04 uses π r_S² for the shaft)
    and the annulus between nut pitch and outer diameter (paper 05). Screw and nut are shared
    by the n_R rollers: one roller sees the sector A/n_R.
Load configuration
    The nut's external load enters at the same end of the nut as the screw's load leaves
    toward its bearing (thread 1): screw compressed, nut stretched across the engagement
    ("tension–compression", the bolt–nut case). Thread 1 then carries the most load.
Combinations (``combination``)
    ``"distributed"`` (default, physical): the compatibility system above, solved by Newton's
    method. ``"uniform"``: rigid bodies, every thread carries W/n (paper 05's F' = F/i1).
    ``"paper01_series"``: paper 01 §2.2 read literally — the n thread pairs of one roller in
    *series*, K_side = (Σ_j 1/K_pair)^(-1), each pair carrying the whole roller load W
    (Hertz + teeth + the side's bodies per pitch). Series springs carry the same force, which
    contradicts the parallel load sharing the same paper describes; it is much softer (about
    n^(5/3) for the contact part) and is offered only to document the difference.
Clearance and eccentricity
    A roller with axial gap g takes load only once the common axial approach Δ of nut and
    screw exceeds g (:func:`axial_stiffness`). A change Δr of the radial room between the
    screw and nut pitch cylinders at one roller becomes the axial gap Δr·cos β/(sin β cos λ)
    (:func:`radial_to_axial_gap`); a screw–nut eccentricity e gives each roller Δr = e·cos φ_i
    (:func:`eccentricity_to_gaps`). A roller displaced radially inside an unchanged room
    changes both of its engagements by equal and opposite amounts and, floating axially, takes
    no gap at first order.

References
----------
- Paper 04: ../shared/papers/04-axial-stiffness-experiment.txt — roller surface r_R(θ, u),
  fundamental forms, K, H, κ1,2, curvature sum/difference Θ ± χ with the angle γ_i, contact
  deformation δ_H, thread compatibility equation, body stiffnesses k_BS, k_BN, k_BR, series
  combination with K_shaft = E_S π r_S²/L_free.
- Paper 01: ../shared/papers/01-dynamics-time-varying-mesh-stiffness.txt §2.2 — K_pair and
  K_sca = (Σ 1/K_pair)^(-1)·n_r.
- Paper 05: ../shared/papers/05-electric-cylinder-accuracy.txt — principal curvatures ρ_S..,
  ρ_N.., Q = F/(i sin β cos λ), Yamamoto terms γ1…γ5.
- A. Yamamoto, *The Theory and Computation of Threads Connection*, Yokendo, Tokyo, 1980:
  thread-tooth deflections δ1…δ5 per unit line load.
- M. P. do Carmo, *Differential Geometry of Curves and Surfaces*, 1976, §3-3: shape operator,
  K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL)/(2(EG − F²)).
- K. L. Johnson, *Contact Mechanics*, CUP 1985, §4.2 (via :mod:`.hertz`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.linalg import eigh

from ..design import PRSMDesign
from ..errors import ParameterError, require
from .hertz import HertzContact, effective_modulus

#: Engagement sides of one roller.
SIDES = ("screw", "nut")
#: Ways of combining the engaged threads of one roller (module docstring).
COMBINATIONS = ("distributed", "uniform", "paper01_series")

#: Newton tolerance of the load-distribution system, on residuals scaled by the mean thread
#: load (or the approach): 1e-13 leaves equilibrium exact to ~1e-12 relative, above the
#: ~1e-15 rounding of sums over a few tens of threads.
_NEWTON_TOL = 1e-13
_NEWTON_MAXITER = 100


# ============================================================================ geometry
@dataclass(frozen=True, eq=False)
class SurfaceCurvature:
    """Differential geometry of a thread flank at one point.

    Attributes
    ----------
    point : ndarray (3,) [m]
        Point in the body's own frame (body axis = z).
    first_form : (E, F, G)
        First fundamental form in the parameters (θ [rad], ρ [m]): E [m²], F [m], G [-].
    second_form : (L, M, N)
        Second fundamental form with the normal pointing *into* the body, so convex is
        positive: L [m], M [-], N [1/m].
    gaussian : float [1/m²]
        K = (LN − M²)/(EG − F²).
    mean : float [1/m]
        H = (EN − 2FM + GL)/(2(EG − F²)).
    principal : (κ1, κ2) [1/m]
        Principal curvatures, κ1 ≥ κ2, positive where convex (paper 05 sign convention).
    directions : ndarray (2, 3)
        Unit principal directions of κ1 and κ2.
    normal : ndarray (3,)
        Outward unit normal (out of the material).

    References
    ----------
    Paper 04, K, H, κ1,2 = H ± √(H² − K); do Carmo (1976) §3-3.
    """

    point: np.ndarray
    first_form: tuple[float, float, float]
    second_form: tuple[float, float, float]
    gaussian: float
    mean: float
    principal: tuple[float, float]
    directions: np.ndarray
    normal: np.ndarray


def helical_surface_curvature(
    radius: float,
    lead: float,
    slope: float,
    profile_curvature: float,
    *,
    theta: float = 0.0,
    material: str = "below",
) -> SurfaceCurvature:
    """Curvature of the helical surface r(θ, ρ) = (ρ cos θ, ρ sin θ, lead·θ/2π + f(ρ)).

    Parameters
    ----------
    radius : float [m]
        ρ of the point (distance from the body axis), > 0.
    lead : float [m]
        Signed lead; positive for a right-hand thread. 0 for a surface of revolution.
    slope : float [-]
        f'(ρ), axial rise of the profile per unit radius.
    profile_curvature : float [1/m]
        f''(ρ).
    theta : float [rad]
        Angular position of the point.
    material : {"below", "above"}
        Side of the surface the body occupies along +z: "below" for a flank facing +z.

    Returns
    -------
    SurfaceCurvature

    Notes
    -----
    The derivatives of r are exact: r_θ = (−ρ sin θ, ρ cos θ, h), r_ρ = (cos θ, sin θ, f'),
    r_θθ = (−ρ cos θ, −ρ sin θ, 0), r_θρ = (−sin θ, cos θ, 0), r_ρρ = (0, 0, f''), h = L/2π.
    Principal curvatures and directions solve the generalised symmetric eigenproblem
    II·v = κ·I·v (well conditioned; equal roots at an umbilic are handled).

    References
    ----------
    Paper 04, roller surface r_R(θ, u) and the fundamental forms; do Carmo (1976) §3-3.
    """
    require(
        radius > 0 and math.isfinite(radius), "radius", radius, "must be a finite number > 0 [m]"
    )
    require(material in ("below", "above"), "material", material, "must be 'below' or 'above'")
    h = lead / (2.0 * math.pi)
    c, s = math.cos(theta), math.sin(theta)
    rho, fp, fpp = radius, slope, profile_curvature
    r_t = np.array([-rho * s, rho * c, h])
    r_r = np.array([c, s, fp])
    r_tt = np.array([-rho * c, -rho * s, 0.0])
    r_tr = np.array([-s, c, 0.0])
    r_rr = np.array([0.0, 0.0, fpp])
    cross = np.cross(r_t, r_r)  # z-component −ρ < 0: points to −z
    n = cross / np.linalg.norm(cross)
    # n points into the body when the body lies below (+z-facing flank): convex then positive.
    inward = n if material == "below" else -n
    e_, f_, g_ = r_t @ r_t, r_t @ r_r, r_r @ r_r
    l_, m_, n_ = r_tt @ inward, r_tr @ inward, r_rr @ inward
    det1 = e_ * g_ - f_ * f_
    gaussian = (l_ * n_ - m_ * m_) / det1
    mean = (e_ * n_ - 2.0 * f_ * m_ + g_ * l_) / (2.0 * det1)
    kappa, vecs = eigh(np.array([[l_, m_], [m_, n_]]), np.array([[e_, f_], [f_, g_]]))
    order = np.argsort(kappa)[::-1]
    kappa, vecs = kappa[order], vecs[:, order]
    directions = np.empty((2, 3))
    for i in range(2):
        t = vecs[0, i] * r_t + vecs[1, i] * r_r
        directions[i] = t / np.linalg.norm(t)
    return SurfaceCurvature(
        point=np.array([rho * c, rho * s, 0.0]),
        first_form=(float(e_), float(f_), float(g_)),
        second_form=(float(l_), float(m_), float(n_)),
        gaussian=float(gaussian),
        mean=float(mean),
        principal=(float(kappa[0]), float(kappa[1])),
        directions=directions,
        normal=-inward,
    )


def thread_surface_curvatures(design: PRSMDesign) -> dict[str, SurfaceCurvature]:
    """Curvature of the four loaded flanks at their nominal contact points.

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    dict
        ``"screw"`` (screw flank facing the roller's load, at d_s/2, θ = 0),
        ``"roller_screw_side"`` (roller flank at θ_r = π, facing the screw),
        ``"roller_nut_side"`` (roller flank at θ_r = 0, facing the nut), ``"nut"`` (at d_n/2).
        All frames have axes parallel to the screw's, so directions and normals compare
        directly.

    Notes
    -----
    Profiles: screw f = −(ρ − r_s)·cot β, nut f = −(ρ − r_n)·cot β (straight flanks at the
    contact angle β); roller f = ∓(√(R² − ρ²) − √(R² − ρ_c²)) with R = ``roller_thread_radius``
    (paper 04's r_R(θ, u) with r_p = R). The roller contact radius is ρ_c = R·cos β, where the
    roller's normal makes the angle β with the radial plane (ρ_c = r_r for R = r_r/cos β).
    All threads share one hand (right-hand, positive leads).

    References
    ----------
    Paper 04, r_R(θ, u); paper 05, the contact points S and N.
    """
    beta = design.contact_angle
    cot_b = 1.0 / math.tan(beta)
    r_s, r_n = design.screw_diameter / 2.0, design.nut_diameter / 2.0
    big_r = design.roller_thread_radius
    rho_c = big_r * math.cos(beta)
    root = math.sqrt(big_r**2 - rho_c**2)
    roller_slope = rho_c / root  # d/dρ of −(√(R² − ρ²)) : rising lower flank
    roller_curv = big_r**2 / root**3
    return {
        "screw": helical_surface_curvature(r_s, design.screw_lead, -cot_b, 0.0, material="below"),
        "roller_screw_side": helical_surface_curvature(
            rho_c, design.roller_lead, roller_slope, roller_curv, theta=math.pi, material="above"
        ),
        "roller_nut_side": helical_surface_curvature(
            rho_c, design.roller_lead, -roller_slope, -roller_curv, theta=0.0, material="below"
        ),
        "nut": helical_surface_curvature(r_n, design.nut_lead, -cot_b, 0.0, material="above"),
    }


@dataclass(frozen=True, eq=False)
class ContactGeometry:
    """One roller's thread contact on one side (screw or nut).

    Attributes
    ----------
    side : str
        ``"screw"`` or ``"nut"``.
    roller, counterpart : SurfaceCurvature
        The roller flank and the screw or nut flank at the nominal contact point.
    principal_angle : float [rad]
        γ, angle between the κ1 directions of the two bodies projected on the common tangent
        plane (paper 04's γ_i), in [0, π/2].
    normal_misalignment : float [rad]
        Angle between the roller's outward normal and the reversed outward normal of the
        counterpart; 0 where the nominal point is a true contact point.
    axial_factor : float [-]
        sin β·cos λ, axial component of the unit contact normal (λ of the screw or nut).
    contact_modulus : float [Pa]
    hertz : HertzContact
        Normal load ↔ normal approach δ_n = c·Q^(2/3).

    References
    ----------
    Paper 04, Θ ± χ, γ_i, δ_H; paper 05, Q = F/(i sin β cos λ).
    """

    side: str
    roller: SurfaceCurvature
    counterpart: SurfaceCurvature
    principal_angle: float
    normal_misalignment: float
    axial_factor: float
    contact_modulus: float
    hertz: HertzContact

    @property
    def axial_compliance_coefficient(self) -> float:
        """c_a in axial approach u = c_a·F_a^(2/3) of one contact, F_a axial [m/N^(2/3)].

        u = δ_n/(sin β cos λ) and Q = F_a/(sin β cos λ) give c_a = c·(sin β cos λ)^(-5/3)
        (paper 05's sin^(5/3) β).
        """
        return self.hertz.compliance_coefficient * self.axial_factor ** (-5.0 / 3.0)


def _principal_angle(a: SurfaceCurvature, b: SurfaceCurvature) -> tuple[float, float]:
    # Common tangent plane: normal halfway between n_a and −n_b (they are opposite at a true
    # contact). Project each body's κ1 direction on it; the angle is defined modulo π.
    n_mean = a.normal - b.normal
    n_mean /= np.linalg.norm(n_mean)
    # atan2 keeps full precision for tiny angles, where acos(≈1) loses half the digits.
    misalignment = math.atan2(
        float(np.linalg.norm(np.cross(a.normal, b.normal))), float(-a.normal @ b.normal)
    )

    def project(v):
        p = v - (v @ n_mean) * n_mean
        return p / np.linalg.norm(p)

    pa, pb = project(a.directions[0]), project(b.directions[0])
    gamma = math.atan2(float(np.linalg.norm(np.cross(pa, pb))), abs(float(pa @ pb)))
    return gamma, misalignment


def thread_contact_geometry(design: PRSMDesign) -> tuple[ContactGeometry, ContactGeometry]:
    """Screw-side and nut-side contact geometry of one roller.

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    (screw_side, nut_side) : ContactGeometry

    References
    ----------
    Paper 04, Θ ± χ with γ_i and R_E; paper 05, ρ_S.., ρ_N.., Q = F/(i sin β cos λ).
    """
    surf = thread_surface_curvatures(design)
    rm = design.roller_material
    out = []
    for side, key, mat, lam in (
        ("screw", "roller_screw_side", design.screw_material, design.screw_lead_angle),
        ("nut", "roller_nut_side", design.nut_material, design.nut_lead_angle),
    ):
        roller, counterpart = surf[key], surf[side]
        gamma, misalignment = _principal_angle(roller, counterpart)
        e_star = effective_modulus(
            rm.youngs_modulus, rm.poisson_ratio, mat.youngs_modulus, mat.poisson_ratio
        )
        hertz = HertzContact.from_curvatures(roller.principal, counterpart.principal, e_star, gamma)
        out.append(
            ContactGeometry(
                side=side,
                roller=roller,
                counterpart=counterpart,
                principal_angle=gamma,
                normal_misalignment=misalignment,
                axial_factor=math.sin(design.contact_angle) * math.cos(lam),
                contact_modulus=e_star,
                hertz=hertz,
            )
        )
    return out[0], out[1]


def thread_contacts(design: PRSMDesign) -> tuple[HertzContact, HertzContact]:
    """Hertz contacts (screw side, nut side) of one roller thread, in the *normal* direction.

    Normal load per contact ↔ axial load of that thread pair: Q = F_axial/(sin β·cos λ).

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    (screw_side, nut_side) : HertzContact

    References
    ----------
    Paper 04, δ_H; paper 05, k_S, k_N and Q = F/(i sin β cos λ).
    """
    s, n = thread_contact_geometry(design)
    return s.hertz, n.hertz


def normal_load(design: PRSMDesign, axial_load, side: str):
    """Normal contact load Q = F_a/(sin β cos λ) [N] of a thread pair carrying ``axial_load`` [N].

    References
    ----------
    Paper 05, Q = F/(i sin β cos λ) (here per contact, i.e. F already per roller and thread).
    """
    _check_side(side)
    lam = design.screw_lead_angle if side == "screw" else design.nut_lead_angle
    return np.asarray(axial_load, dtype=float) / (math.sin(design.contact_angle) * math.cos(lam))


# ============================================================================ teeth, bodies
@dataclass(frozen=True)
class ToothCompliance:
    """Axial compliance of one thread tooth per axial contact load [m/N] (Yamamoto).

    Attributes
    ----------
    bending, shear, root_bending, root_shear, radial : float [m/N]
        Yamamoto's δ1…δ5 (tooth bending, tooth shear, root inclination by the moment, root
        inclination by shear, radial contraction/expansion of the core).
    load_length : float [m]
        Thread length over which one contact's load is spread (module docstring).
    """

    bending: float
    shear: float
    root_bending: float
    root_shear: float
    radial: float
    load_length: float

    @property
    def total(self) -> float:
        """Sum of the five terms [m/N]."""
        return self.bending + self.shear + self.root_bending + self.root_shear + self.radial


def tooth_geometry(design: PRSMDesign) -> dict[str, float]:
    """Trapezoidal tooth of Yamamoto's formulas for the design's thread [m].

    Returns
    -------
    dict
        ``a`` root width, ``b`` width at the load point (pitch line) = p/2, ``c`` height from
        root to the load point, ``flank_angle`` φ = π/2 − β [rad] from the radial plane.

    Notes
    -----
    Straight flanks at the contact angle (the roller's circular flank is replaced by its
    tangent at the pitch point). The sharp-V depth is H = (p/2)·tan β with the pitch line at
    mid-depth; the flanks end at the dedendum or where adjacent teeth meet, whichever comes
    first: c = min(dedendum, H/2), a = b + 2c·tan φ (a = p for a full V).
    """
    p = design.pitch
    phi = 0.5 * math.pi - design.contact_angle
    b = 0.5 * p
    c = min(design.dedendum, 0.25 * p * math.tan(design.contact_angle))
    return {"a": b + 2.0 * c * math.tan(phi), "b": b, "c": c, "flank_angle": phi}


def _yamamoto(p, a, b, c, phi, nu, radial_factor, diameter) -> tuple[float, ...]:
    # Dimensionless δ_k·E/W. δ1, δ2: cantilever of width t(x) = a − 2x tan φ in plane strain,
    # δ1 = ∫ M·(c − x)/(E' I) with M = W(c − x) − W tan φ·b/2 (the radial load component acts
    # on the flank at b/2 from the tooth centre), δ2 = ∫ 1.2 W/(G t) — integrated in closed form
    # these are Yamamoto's expressions (checked in tests against quadrature).
    tan_p = math.tan(phi)
    cot_p = 1.0 / tan_p
    bending = (
        0.75
        * (1 - nu**2)
        * (
            (1.0 - (2.0 - b / a) ** 2 + 2.0 * math.log(a / b)) * cot_p**3
            - 4.0 * (c / a) ** 2 * tan_p
        )
    )
    shear = 1.2 * (1 + nu) * cot_p * math.log(a / b)
    root_bending = 12.0 * c * (1 - nu**2) / (math.pi * a**2) * (c - 0.5 * b * tan_p)
    root_shear = (
        2.0
        * (1 - nu**2)
        / math.pi
        * (
            (p / a) * math.log((p + 0.5 * a) / (p - 0.5 * a))
            + 0.5 * math.log(4.0 * p**2 / a**2 - 1.0)
        )
    )
    radial = radial_factor * (diameter / p) * tan_p**2 / 2.0
    return bending, shear, root_bending, root_shear, radial


def tooth_compliances(design: PRSMDesign) -> dict[str, ToothCompliance]:
    """Axial compliance of the screw, roller and nut teeth at one contact [m/N].

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    dict
        ``"screw"``, ``"roller"``, ``"nut"`` → :class:`ToothCompliance`. The roller value
        applies to each of its two contacts (screw side and nut side).

    Notes
    -----
    Yamamoto's δ_k are deflections per unit line load W [N/m]; one contact's axial load F_a
    is spread as W = F_a/ℓ with ℓ = π d_s/n_R (screw), π d_n/n_R (nut), π d_r (roller).
    Radial (Lamé) factors: screw (d² + d_b²)/(d² − d_b²) − ν (1 − ν when solid), roller
    1 − ν, nut (D² + d_n²)/(D² − d_n²) + ν with D the nut outer diameter.

    References
    ----------
    Yamamoto (1980), δ1…δ5; paper 05, γ1…γ5 (the same terms for a 45° sharp V thread);
    paper 04 names the tooth compliance k_RT, k_NT (it models the tooth as an annular plate).
    """
    g = tooth_geometry(design)
    p, a, b, c, phi = design.pitch, g["a"], g["b"], g["c"], g["flank_angle"]
    n_r = design.n_rollers
    d_s, d_r, d_n = design.screw_diameter, design.roller_diameter, design.nut_diameter
    bore, d_o = design.screw_bore_diameter, design.nut_outer_diameter
    out = {}
    for name, mat, diameter, radial_factor, length in (
        (
            "screw",
            design.screw_material,
            d_s,
            (d_s**2 + bore**2) / (d_s**2 - bore**2) - design.screw_material.poisson_ratio,
            math.pi * d_s / n_r,
        ),
        (
            "roller",
            design.roller_material,
            d_r,
            1.0 - design.roller_material.poisson_ratio,
            math.pi * d_r,
        ),
        (
            "nut",
            design.nut_material,
            d_n,
            (d_o**2 + d_n**2) / (d_o**2 - d_n**2) + design.nut_material.poisson_ratio,
            math.pi * d_n / n_r,
        ),
    ):
        terms = _yamamoto(p, a, b, c, phi, mat.poisson_ratio, radial_factor, diameter)
        scale = 1.0 / (mat.youngs_modulus * length)
        out[name] = ToothCompliance(*(t * scale for t in terms), load_length=length)
    return out


def body_compliances(design: PRSMDesign) -> dict[str, float]:
    """Tension/compression compliance of the cores over one pitch, per roller [m/N].

    Returns
    -------
    dict
        ``"screw"`` n_R·p/(E_s·π(d_s² − d_b²)/4), ``"roller"`` p/(E_r·π d_r²/4),
        ``"nut"`` n_R·p/(E_n·π(D² − d_n²)/4). Screw and nut are shared by the n_R rollers,
        hence the factor n_R (each roller loads a 1/n_R sector).

    References
    ----------
    Paper 04, k_BS = E_S A_S/L_S, k_BN, k_BR; paper 05, Δl5 (nut annulus).
    """
    p, n_r = design.pitch, design.n_rollers
    a_s = 0.25 * math.pi * (design.screw_diameter**2 - design.screw_bore_diameter**2)
    a_r = 0.25 * math.pi * design.roller_diameter**2
    a_n = 0.25 * math.pi * (design.nut_outer_diameter**2 - design.nut_diameter**2)
    return {
        "screw": n_r * p / (design.screw_material.youngs_modulus * a_s),
        "roller": p / (design.roller_material.youngs_modulus * a_r),
        "nut": n_r * p / (design.nut_material.youngs_modulus * a_n),
    }


def shaft_stiffness(design: PRSMDesign) -> float:
    """K_shaft = E_s·π(d_s² − d_b²)/4 / L_free [N/m] of the unengaged screw.

    References
    ----------
    Paper 04, K_shaft = E_S π r_S²/L_free (r_S the screw pitch radius).
    """
    area = 0.25 * math.pi * (design.screw_diameter**2 - design.screw_bore_diameter**2)
    return design.screw_material.youngs_modulus * area / design.screw_free_length


def thread_pair_coefficients(design: PRSMDesign, side: str) -> tuple[float, float]:
    """(c_H, c_T) of one thread pair's axial law u = c_H·F_a^(2/3) + c_T·F_a.

    c_H [m/N^(2/3)] is the axial Hertz coefficient, c_T [m/N] the teeth in series (screw or
    nut tooth + roller tooth).
    """
    _check_side(side)
    geo = thread_contact_geometry(design)[0 if side == "screw" else 1]
    teeth = tooth_compliances(design)
    return geo.axial_compliance_coefficient, teeth[side].total + teeth["roller"].total


def thread_pair_deflection(design: PRSMDesign, axial_load, side: str):
    """Axial approach u [m] of one thread pair (contact + teeth) under ``axial_load`` [N].

    References
    ----------
    Paper 04, δ_H and the tooth terms of the compatibility equation; paper 01, 1/K_pair.
    """
    c_h, c_t = thread_pair_coefficients(design, side)
    q = np.maximum(np.asarray(axial_load, dtype=float), 0.0)
    return c_h * np.cbrt(q) ** 2 + c_t * q


# ============================================================================ input checks
def _check_side(side) -> None:
    require(side in SIDES, "side", side, "must be 'screw' or 'nut'")


def _check_combination(combination) -> None:
    require(
        combination in COMBINATIONS,
        "combination",
        combination,
        f"must be one of {', '.join(COMBINATIONS)}",
    )


def _as_array(name: str, value, *, nonnegative: bool = True) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number or an array of numbers") from None
    require(bool(np.all(np.isfinite(arr))), name, value, "must be finite")
    if nonnegative:
        require(bool(np.all(arr >= 0.0)), name, value, "must be ≥ 0")
    return arr


# ============================================================================ one roller
def _invert_law(alpha, beta, delta):
    """W ≥ 0 with α·W^(2/3) + β·W = δ (α > 0, β ≥ 0); 0 for δ ≤ 0. Vectorised."""
    delta = np.asarray(delta, dtype=float)
    alpha = np.broadcast_to(np.asarray(alpha, dtype=float), delta.shape)
    beta = np.broadcast_to(np.asarray(beta, dtype=float), delta.shape)
    pos = delta > 0.0
    d = np.where(pos, delta, 1.0)
    # y = W^(1/3) solves β y³ + α y² = δ. Both √(δ/α) and ∛(δ/β) are upper bounds and the
    # cubic is convex for y > 0, so Newton from their minimum descends monotonically.
    y = np.sqrt(d / alpha)
    with np.errstate(divide="ignore"):
        y = np.where(beta > 0.0, np.minimum(y, np.cbrt(d / np.where(beta > 0, beta, 1.0))), y)
    for _ in range(60):
        f = beta * y**3 + alpha * y**2 - d
        step = f / (3.0 * beta * y**2 + 2.0 * alpha * y)
        y = y - step
        if np.all(np.abs(step) <= 4e-16 * y):
            break
    return np.where(pos, y**3, 0.0)


@dataclass(frozen=True, eq=False)
class _RollerState:
    load: np.ndarray  # (B,) roller axial load W
    screw: np.ndarray  # (B, n) axial thread loads, screw side
    nut: np.ndarray  # (B, n)
    deflection: np.ndarray  # (B, 2) axial approach at thread 1, [screw, nut]
    compliance: np.ndarray  # (B, 2) tangent dδ_side/dW
    split: np.ndarray  # (B, 2, 3) contact / teeth / bodies per side


class _RollerModel:
    """One roller's screw-side and nut-side engagement (module docstring)."""

    def __init__(self, design: PRSMDesign, combination: str, body_scale: float):
        self.n = n = design.engaged_threads
        self.combination = combination
        c_h, c_t = zip(*(thread_pair_coefficients(design, s) for s in SIDES))
        self.c_h = np.array(c_h)
        self.c_t = np.array(c_t)
        body = {k: v * body_scale for k, v in body_compliances(design).items()}
        self.body_side = np.array([body["screw"] + body["roller"], body["nut"] + body["roller"]])
        if combination == "uniform" or body_scale == 0.0:
            self.matrix = None
        else:
            # δ_S = a_S − (c_s + c_r)·M·Q_S + c_r·M·Q_N,  δ_N = a_N − (c_n + c_r)·M·Q_N + c_r·M·Q_S
            # with M_jk = min(j, k) (0-based): the bar segment between threads m and m+1
            # carries the loads of all threads beyond m (screw compressed, nut stretched).
            idx = np.arange(n)
            m = np.minimum.outer(idx, idx).astype(float)
            a = np.zeros((2 * n, 2 * n))
            a[:n, :n] = -(body["screw"] + body["roller"]) * m
            a[:n, n:] = body["roller"] * m
            a[n:, :n] = body["roller"] * m
            a[n:, n:] = -(body["nut"] + body["roller"]) * m
            self.matrix = a
        # Per-side closed-form law u = α W^(2/3) + β W for the non-distributed readings.
        if combination == "paper01_series":
            self.alpha = n * self.c_h
            self.beta = n * (self.c_t + self.body_side)
        else:
            self.alpha = self.c_h * n ** (-2.0 / 3.0)
            self.beta = self.c_t / n

    # ------------------------------------------------------------------ public entry
    def solve(self, control: str, value) -> _RollerState:
        """control: "load" (W), "roller" (δ_S + δ_N), "screw" (δ_S) or "nut" (δ_N)."""
        value = np.atleast_1d(np.asarray(value, dtype=float))
        n = self.n
        bsz = value.size
        load = np.zeros(bsz)
        screw = np.zeros((bsz, n))
        nut = np.zeros((bsz, n))
        defl = np.zeros((bsz, 2))
        comp = np.full((bsz, 2), np.inf)
        split = np.zeros((bsz, 2, 3))
        active = value > 0.0
        if np.any(active):
            v = value[active]
            if self.matrix is None or self.combination == "paper01_series":
                res = self._closed_form(control, v)
            else:
                res = self._newton(control, v)
            load[active], screw[active], nut[active] = res[0], res[1], res[2]
            defl[active], comp[active], split[active] = res[3], res[4], res[5]
        return _RollerState(load, screw, nut, defl, comp, split)

    # ------------------------------------------------------------------ closed forms
    def _closed_form(self, control, v):
        alpha, beta = self.alpha, self.beta
        if control == "load":
            w = v
        elif control == "roller":
            w = _invert_law(alpha.sum(), beta.sum(), v)
        else:
            k = SIDES.index(control)
            w = _invert_law(alpha[k], beta[k], v)
        w13 = np.cbrt(w)
        defl = alpha[None, :] * (w13**2)[:, None] + beta[None, :] * w[:, None]
        comp = (2.0 / 3.0) * alpha[None, :] / w13[:, None] + beta[None, :]
        n = self.n
        split = np.zeros((w.size, 2, 3))
        if self.combination == "paper01_series":
            per_thread = np.repeat(w[:, None], n, axis=1)
            split[:, :, 0] = n * self.c_h[None, :] * (w13**2)[:, None]
            split[:, :, 1] = n * self.c_t[None, :] * w[:, None]
            split[:, :, 2] = n * self.body_side[None, :] * w[:, None]
        else:
            per_thread = np.repeat((w / n)[:, None], n, axis=1)
            split[:, :, 0] = alpha[None, :] * (w13**2)[:, None]
            split[:, :, 1] = beta[None, :] * w[:, None]
        return w, per_thread, per_thread.copy(), defl, comp, split

    # ------------------------------------------------------------------ Newton
    def _g(self, delta):
        """Thread load Q(δ) and dQ/dδ for the 2n thread pairs (inverse of c_H Q^(2/3) + c_T Q)."""
        n = self.n
        ch = np.repeat(self.c_h, n)[None, :]
        ct = np.repeat(self.c_t, n)[None, :]
        q = _invert_law(ch, ct, delta)
        with np.errstate(divide="ignore"):
            dq = np.where(
                q > 0.0, 1.0 / ((2.0 / 3.0) * ch / np.cbrt(np.where(q > 0, q, 1.0)) + ct), 0.0
            )
        return q, dq

    def _residual(self, x, control, value, jacobian=True):
        n = self.n
        q = x[:, : 2 * n]
        a = x[:, 2 * n :]
        delta = np.repeat(a, n, axis=1) + q @ self.matrix.T
        g, dg = self._g(delta)
        r = np.empty_like(x)
        r[:, : 2 * n] = q - g
        r[:, 2 * n] = q[:, :n].sum(axis=1) - q[:, n:].sum(axis=1)
        last = self._control_row(control)
        r[:, 2 * n + 1] = x @ last - value
        if not jacobian:
            return r, None
        bsz, m = x.shape
        jac = np.zeros((bsz, m, m))
        jac[:, : 2 * n, : 2 * n] = np.eye(2 * n)[None] - dg[:, :, None] * self.matrix[None]
        jac[:, :n, 2 * n] = -dg[:, :n]
        jac[:, n : 2 * n, 2 * n + 1] = -dg[:, n:]
        jac[:, 2 * n, :n] = 1.0
        jac[:, 2 * n, n : 2 * n] = -1.0
        jac[:, 2 * n + 1, :] = last[None, :]
        return r, jac

    def _control_row(self, control):
        n = self.n
        row = np.zeros(2 * n + 2)
        if control == "load":
            row[:n] = 1.0
        elif control == "roller":
            row[2 * n :] = 1.0
        else:
            row[2 * n + SIDES.index(control)] = 1.0
        return row

    def _newton(self, control, value):
        n = self.n
        m = 2 * n + 2
        bsz = value.size
        # Start from the rigid-body (uniform) solution of the same control.
        w0, q0, _, d0, _, _ = self._closed_form(control, value)
        x = np.zeros((bsz, m))
        x[:, :n] = q0
        x[:, n : 2 * n] = q0
        x[:, 2 * n :] = d0
        # Scale loads by the mean thread load and approaches by the total approach so the
        # Jacobian is O(1) (loads in N and approaches in m differ by ~1e8).
        col = np.empty((bsz, m))
        col[:, : 2 * n] = (w0 / n)[:, None]
        col[:, 2 * n :] = d0.sum(axis=1)[:, None]
        row = 1.0 / col.copy()
        row[:, 2 * n] = n / w0
        if control == "load":
            row[:, 2 * n + 1] = n / w0
        else:
            row[:, 2 * n + 1] = 1.0 / d0.sum(axis=1)
        r, jac = self._residual(x, control, value)
        for _ in range(_NEWTON_MAXITER):
            rs = r * row
            err = np.max(np.abs(rs), axis=1)
            if np.all(err < _NEWTON_TOL):
                break
            js = row[:, :, None] * jac * col[:, None, :]
            dx = -np.linalg.solve(js, rs[:, :, None])[:, :, 0] * col
            dx[err < _NEWTON_TOL] = 0.0
            merit0 = np.sum(rs**2, axis=1)
            t = np.ones(bsz)
            accepted = err < _NEWTON_TOL
            x_new = x.copy()
            r_new = r.copy()
            jac_new = jac.copy()
            for _ in range(40):
                todo = ~accepted
                if not np.any(todo):
                    break
                xt = x[todo] + t[todo, None] * dx[todo]
                rt, jt = self._residual(xt, control, value[todo])
                merit = np.sum((rt * row[todo]) ** 2, axis=1)
                # Approaches at thread 1 stay positive at every solution with W > 0.
                ok = (merit < (1.0 - 1e-4 * t[todo]) * merit0[todo]) & np.all(
                    xt[:, 2 * n :] > 0, axis=1
                )
                idx = np.flatnonzero(todo)[ok]
                x_new[idx], r_new[idx], jac_new[idx] = xt[ok], rt[ok], jt[ok]
                accepted[idx] = True
                t[np.flatnonzero(todo)[~ok]] *= 0.5
            if not np.all(accepted):  # pragma: no cover - a failure here is a bug, not input
                raise RuntimeError("thread load distribution: line search failed")
            x, r, jac = x_new, r_new, jac_new
        else:  # pragma: no cover
            raise RuntimeError("thread load distribution: Newton did not converge")
        # Tangent: R(x, v) = 0 → J·dx/dv = e_last.
        rhs = np.zeros((bsz, m, 1))
        rhs[:, -1, 0] = 1.0
        dxdv = np.linalg.solve(jac, rhs)[:, :, 0]
        dw = dxdv[:, :n].sum(axis=1)
        comp = dxdv[:, 2 * n :] / dw[:, None]
        q_s, q_n = x[:, :n], x[:, n : 2 * n]
        w = q_s.sum(axis=1)
        defl = x[:, 2 * n :]
        # Deformation split: u_1 = Σ_j (Q_j/W)·[contact_j + teeth_j + (u_1 − u_j)], the load-
        # weighted (Clapeyron) split; the last term is the body stretch between thread 1 and j.
        split = np.zeros((bsz, 2, 3))
        for k, q in enumerate((q_s, q_n)):
            weight = q / w[:, None]
            split[:, k, 0] = np.sum(weight * self.c_h[k] * np.cbrt(q) ** 2, axis=1)
            split[:, k, 1] = np.sum(weight * self.c_t[k] * q, axis=1)
            split[:, k, 2] = defl[:, k] - split[:, k, 0] - split[:, k, 1]
        return w, q_s, q_n, defl, comp, split


@functools.lru_cache(maxsize=64)
def _roller_model(design: PRSMDesign, combination: str, body_scale: float = 1.0) -> _RollerModel:
    return _RollerModel(design, combination, body_scale)


# ============================================================================ distribution
@dataclass(frozen=True, eq=False)
class LoadDistribution:
    """Per-thread axial loads of one roller.

    Attributes
    ----------
    roller_load : ndarray [N]
        Axial load W of the roller (shape of the input).
    screw, nut : ndarray [N]
        Axial load of each engaged thread pair, thread 1 (load entry) first; shape
        (..., engaged_threads).
    screw_deflection, nut_deflection : ndarray [m]
        Axial approach of the screw-side / nut-side engagement, measured at thread 1.
    screw_stiffness, nut_stiffness, roller_stiffness : ndarray [N/m]
        Tangent stiffness dW/dδ of each side and of the roller (sides in series).
    combination : str
    """

    roller_load: np.ndarray
    screw: np.ndarray
    nut: np.ndarray
    screw_deflection: np.ndarray
    nut_deflection: np.ndarray
    screw_stiffness: np.ndarray
    nut_stiffness: np.ndarray
    roller_stiffness: np.ndarray
    combination: str


def _stiffness_from_compliance(comp):
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(comp), 1.0 / comp, 0.0)


def thread_load_distribution(
    design: PRSMDesign,
    roller_load,
    *,
    combination: str = "distributed",
    body_scale: float = 1.0,
) -> LoadDistribution:
    """Loads of the engaged threads of one roller, screw side and nut side.

    Solves the deformation compatibility of paper 04 for the n = ``engaged_threads`` thread
    pairs of each side: for thread j and j + 1 (0-based m = j),

        u_S(Q^S_j) − u_S(Q^S_{j+1}) = (c_s + c_r)·Σ_{k>j} Q^S_k − c_r·Σ_{k>j} Q^N_k
        u_N(Q^N_j) − u_N(Q^N_{j+1}) = (c_n + c_r)·Σ_{k>j} Q^N_k − c_r·Σ_{k>j} Q^S_k

    with u(Q) = c_H Q^(2/3) + c_T Q the thread-pair law (:func:`thread_pair_deflection`) and
    c_s, c_r, c_n the body compliances per pitch (:func:`body_compliances`), together with
    ΣQ^S = ΣQ^N = W. Newton's method with a line search, from the uniform solution.

    Parameters
    ----------
    design : PRSMDesign
    roller_load : float or array_like [N]
        Axial load W of one roller, ≥ 0.
    combination : {"distributed", "uniform", "paper01_series"}
        See the module docstring.
    body_scale : float [-]
        Multiplies the body compliances (1 = physical, 0 = rigid bodies → uniform sharing).

    Returns
    -------
    LoadDistribution

    References
    ----------
    Paper 04, compatibility equation of the i-th engaged thread (its printed form adds
    stiffnesses where compliances add and writes Q_i for the cumulative load; the form above
    is the standard bolt–nut compatibility it paraphrases); paper 01 §2.2 (series reading).
    """
    _check_combination(combination)
    w = _as_array("roller_load", roller_load)
    require(
        isinstance(body_scale, (int, float)) and math.isfinite(body_scale) and body_scale >= 0,
        "body_scale",
        body_scale,
        "must be a finite number ≥ 0",
    )
    state = _roller_model(design, combination, float(body_scale)).solve("load", w.ravel())
    shape = w.shape
    n = design.engaged_threads
    k = _stiffness_from_compliance(state.compliance)
    kr = _stiffness_from_compliance(state.compliance.sum(axis=1))
    return LoadDistribution(
        roller_load=w,
        screw=state.screw.reshape(shape + (n,)),
        nut=state.nut.reshape(shape + (n,)),
        screw_deflection=state.deflection[:, 0].reshape(shape),
        nut_deflection=state.deflection[:, 1].reshape(shape),
        screw_stiffness=k[:, 0].reshape(shape),
        nut_stiffness=k[:, 1].reshape(shape),
        roller_stiffness=kr.reshape(shape),
        combination=combination,
    )


# ============================================================================ gaps
def radial_to_axial_gap(design: PRSMDesign, radial_offset):
    """Axial gap [m] of a roller whose radial room grows by ``radial_offset`` [m].

    Parameters
    ----------
    design : PRSMDesign
    radial_offset : float or array_like [m]
        Change of the radial distance between the screw and nut pitch surfaces available to
        the roller, minus the change of the roller's pitch diameter (positive = looser:
        screw–nut eccentricity away from the roller, an undersized roller, wear).

    Returns
    -------
    ndarray [m]
        Axial gap (negative = pre-approach) of the roller's load path.

    Notes
    -----
    Derivation: at a flank whose unit normal has radial component cos β and axial component
    sin β·cos λ, moving the surfaces apart radially by Δr opens the normal gap by Δr·cos β;
    closing it axially takes Δr·cos β/(sin β cos λ). The roller floats axially between its
    two engagements, so only the *sum* of the screw-side and nut-side radial changes counts,
    however the roller sits radially: a roller offset radially inside an unchanged room
    (its own eccentricity or runout) opens one side by as much as it closes the other and
    takes no gap at first order. λ is the mean of the screw and nut lead angles (they differ
    by O(λ²) in the result).

    References
    ----------
    Paper 05, the contact normal components (cos β radial, sin β cos λ axial); paper 04
    (clearance and eccentricity reduce the stiffness).
    """
    dr = _as_array("radial_offset", radial_offset, nonnegative=False)
    beta = design.contact_angle
    inv_cos = 0.5 * (
        1.0 / math.cos(design.screw_lead_angle) + 1.0 / math.cos(design.nut_lead_angle)
    )
    return dr * inv_cos / math.tan(beta)


def eccentricity_to_gaps(design: PRSMDesign, eccentricity: float, phase: float = 0.0) -> np.ndarray:
    """Axial gaps [m] of the n_R rollers for a screw–nut radial eccentricity.

    Parameters
    ----------
    design : PRSMDesign
    eccentricity : float [m]
        Radial offset e of the screw axis from the nut axis over the engagement (or runout
        of a pitch circle), ≥ 0.
    phase : float [rad]
        Direction of the offset; roller i sits at φ_i = 2π·i/n_R.

    Returns
    -------
    ndarray (n_R,) [m]
        Gaps measured from the first roller to touch (the smallest is 0).

    Notes
    -----
    The screw moves toward roller i by e·cos(φ_i − phase), reducing its radial room by that
    much: gap_i = −:func:`radial_to_axial_gap` (e·cos(φ_i − phase)), shifted so min = 0.
    """
    require(
        isinstance(eccentricity, (int, float))
        and math.isfinite(eccentricity)
        and eccentricity >= 0,
        "eccentricity",
        eccentricity,
        "must be a finite number ≥ 0 [m]",
    )
    phi = 2.0 * math.pi * np.arange(design.n_rollers) / design.n_rollers
    gaps = radial_to_axial_gap(design, -eccentricity * np.cos(phi - phase))
    return gaps - gaps.min()


# ============================================================================ mechanism
@dataclass(frozen=True, eq=False)
class AxialStiffness:
    """Axial load–deformation state of the whole mechanism.

    Arrays carry a leading load axis when ``load`` was an array; scalars otherwise.

    Attributes
    ----------
    load : [N]
    deformation : [m]
        Axial displacement of the nut relative to the screw's bearing: engagement approach
        (from the first roller to touch) + shaft.
    secant_stiffness : [N/m]
        F/δ (0 at F = 0, its limit).
    tangent_stiffness : [N/m]
        dF/dδ (0 at F = 0, where the Hertz compliance is infinite).
    roller_loads : (…, n_R) [N]
    roller_deflections : (…, n_R) [m]
        Axial approach of each roller's engagement (screw side + nut side); 0 if unloaded.
    thread_loads_screw, thread_loads_nut : (…, n_R, n) [N]
        Axial load per engaged thread, thread 1 first.
    deformation_split : dict of [m]
        ``contact``, ``teeth``, ``bodies`` (load-weighted over rollers and threads),
        ``gaps`` (load-weighted roller gap) and ``shaft``; they sum to ``deformation``.
    roller_gaps : (n_R,) [m]
        Axial gaps used, shifted so the smallest is 0.
    combination : str
    """

    load: np.ndarray
    deformation: np.ndarray
    secant_stiffness: np.ndarray
    tangent_stiffness: np.ndarray
    roller_loads: np.ndarray
    roller_deflections: np.ndarray
    thread_loads_screw: np.ndarray
    thread_loads_nut: np.ndarray
    deformation_split: dict
    roller_gaps: np.ndarray
    combination: str


def _mechanism_roller_states(model: _RollerModel, loads: np.ndarray, gaps: np.ndarray):
    """Common approach Δ (L,) and per-(load, roller) states for rollers with axial gaps."""
    n_roll = gaps.size
    n_load = loads.size
    uniq, inverse, counts = np.unique(gaps, return_inverse=True, return_counts=True)
    if uniq.size == 1:
        st = model.solve("load", loads / n_roll)
        delta = st.deflection.sum(axis=1)
        return delta, [st] * n_roll, inverse

    # Σ_i W_i(Δ − g_i) = F is monotone in Δ. Bracket: all rollers at gap 0 would need
    # Δ = δ(F/n_R) (a lower bound, gaps only unload), the gap-0 roller alone carrying F
    # needs δ(F) (an upper bound). Safeguarded Newton with the exact tangent Σ k_i.
    pos = loads > 0
    lo = np.zeros(n_load)
    hi = np.zeros(n_load)
    lo[pos] = model.solve("load", loads[pos] / n_roll).deflection.sum(axis=1)
    hi[pos] = model.solve("load", loads[pos]).deflection.sum(axis=1)
    delta = lo.copy()
    for _ in range(200):
        trial = delta[:, None] - uniq[None, :]
        st = model.solve("roller", trial.ravel())
        w = st.load.reshape(n_load, uniq.size)
        k = _stiffness_from_compliance(st.compliance.sum(axis=1)).reshape(n_load, uniq.size)
        f = w @ counts - loads
        fp = k @ counts
        done = (np.abs(f) <= 1e-12 * np.maximum(loads, 1e-300)) | ~pos
        if np.all(done):
            break
        lo = np.where(f < 0, delta, lo)
        hi = np.where(f > 0, delta, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = delta - f / fp
        bad = ~np.isfinite(newton) | (newton <= lo) | (newton >= hi)
        delta = np.where(done, delta, np.where(bad, 0.5 * (lo + hi), newton))
    else:  # pragma: no cover
        raise RuntimeError("axial stiffness: common approach did not converge")
    trial = delta[:, None] - uniq[None, :]
    st = model.solve("roller", trial.ravel())
    states = []
    for u in range(uniq.size):
        sel = np.arange(n_load) * uniq.size + u
        states.append(
            _RollerState(
                st.load[sel],
                st.screw[sel],
                st.nut[sel],
                st.deflection[sel],
                st.compliance[sel],
                st.split[sel],
            )
        )
    return delta, states, inverse


def axial_stiffness(
    design: PRSMDesign,
    load,
    *,
    roller_gaps=None,
    eccentricity: float | None = None,
    combination: str = "distributed",
) -> AxialStiffness:
    """Axial stiffness of the PRSM: rollers in parallel, sides in series, plus the shaft.

    Parameters
    ----------
    design : PRSMDesign
    load : float or array_like [N]
        Total axial load F on the nut, ≥ 0.
    roller_gaps : array_like (n_R,) [m] or None
        Axial gap of each roller's load path, ≥ 0 (e.g. from :func:`radial_to_axial_gap`).
        A roller carries load only once the common approach exceeds its gap. Gaps are
        measured from the first roller to touch (a common offset changes nothing).
    eccentricity : float [m] or None
        Screw–nut radial eccentricity; adds :func:`eccentricity_to_gaps` to the gaps.
    combination : {"distributed", "uniform", "paper01_series"}
        How the engaged threads of one roller combine (module docstring).

    Returns
    -------
    AxialStiffness

    Notes
    -----
    1/K = 1/K_engaged + 1/K_shaft with K_engaged = Σ_i k_i over the loaded rollers (tangent)
    and K_shaft = E A/L_free. Without gaps each roller carries F/n_R.

    References
    ----------
    Paper 04, 1/K_total = 1/K_engaged + 1/K_shaft and the clearance/eccentricity discussion;
    paper 01 §2.2, K_sca = (Σ 1/K_pair)^(-1)·n_r for ``"paper01_series"``.
    """
    _check_combination(combination)
    f = _as_array("load", load)
    scalar = f.ndim == 0
    loads = np.atleast_1d(f).ravel()
    n_roll = design.n_rollers
    if roller_gaps is None:
        gaps = np.zeros(n_roll)
    else:
        gaps = _as_array("roller_gaps", roller_gaps)
        require(
            gaps.shape == (n_roll,),
            "roller_gaps",
            f"array of shape {gaps.shape}",
            f"must have one gap per roller, shape ({n_roll},)",
        )
    if eccentricity is not None:
        gaps = gaps + eccentricity_to_gaps(design, eccentricity)
    gaps = gaps - gaps.min()

    model = _roller_model(design, combination)
    delta, states, inverse = _mechanism_roller_states(model, loads, gaps)
    n_load = loads.size
    w = np.stack([states[inverse[i]].load for i in range(n_roll)], axis=1)
    defl = np.stack([states[inverse[i]].deflection.sum(axis=1) for i in range(n_roll)], axis=1)
    comp = np.stack([states[inverse[i]].compliance.sum(axis=1) for i in range(n_roll)], axis=1)
    split = np.stack([states[inverse[i]].split.sum(axis=1) for i in range(n_roll)], axis=1)
    q_s = np.stack([states[inverse[i]].screw for i in range(n_roll)], axis=1)
    q_n = np.stack([states[inverse[i]].nut for i in range(n_roll)], axis=1)

    k_shaft = shaft_stiffness(design)
    k_eng = _stiffness_from_compliance(comp).sum(axis=1)
    shaft = loads / k_shaft
    deformation = delta + shaft
    pos = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        secant = np.where(pos, loads / np.where(pos, deformation, 1.0), 0.0)
        tangent = np.where(
            k_eng > 0, 1.0 / (1.0 / np.where(k_eng > 0, k_eng, 1.0) + 1.0 / k_shaft), 0.0
        )
        weight = np.where(pos[:, None], w / np.where(pos, loads, 1.0)[:, None], 0.0)
    parts = {
        "contact": np.sum(weight * split[:, :, 0], axis=1),
        "teeth": np.sum(weight * split[:, :, 1], axis=1),
        "bodies": np.sum(weight * split[:, :, 2], axis=1),
        "gaps": weight @ gaps,
        "shaft": shaft,
    }

    def out(arr):
        return arr[0] if scalar else arr.reshape((n_load,) + arr.shape[1:])

    return AxialStiffness(
        load=out(loads),
        deformation=out(deformation),
        secant_stiffness=out(secant),
        tangent_stiffness=out(tangent),
        roller_loads=out(w),
        roller_deflections=out(np.where(w > 0, defl, 0.0)),
        thread_loads_screw=out(q_s),
        thread_loads_nut=out(q_n),
        deformation_split={k: out(v) for k, v in parts.items()},
        roller_gaps=gaps,
        combination=combination,
    )


# ============================================================================ simulator API
def roller_side_force(
    design: PRSMDesign, axial_deflection, side: str, *, combination: str = "distributed"
):
    """Axial force [N] of one roller's engagement on ``side`` at an axial deflection [m].

    Parameters
    ----------
    design : PRSMDesign
    axial_deflection : float or array_like [m]
        Axial approach of the side's engagement, measured at the loaded end (thread 1);
        ≤ 0 means separated (force 0).
    side : {"screw", "nut"}
    combination : {"distributed", "uniform", "paper01_series"}

    Returns
    -------
    ndarray [N]
        Same shape as ``axial_deflection``.

    Notes
    -----
    Consistent with :func:`thread_load_distribution`: the force W for which the side's
    approach equals the deflection, both sides of the roller loaded by W (displacement-
    controlled solve of the same compatibility system). The two sides in series reproduce
    the roller law of :func:`axial_stiffness`.

    References
    ----------
    Paper 01, F_sai = K_sca·f(δ, b) (here nonlinear); paper 04, load distribution.
    """
    _check_side(side)
    _check_combination(combination)
    d = _as_array("axial_deflection", axial_deflection, nonnegative=False)
    st = _roller_model(design, combination).solve(side, np.maximum(d.ravel(), 0.0))
    return st.load.reshape(d.shape) if d.ndim else st.load[0]


def roller_side_stiffness(
    design: PRSMDesign, roller_axial_load, side: str, *, combination: str = "distributed"
):
    """Tangent axial stiffness dW/dδ_side [N/m] of one roller's engagement on ``side``.

    Parameters
    ----------
    design : PRSMDesign
    roller_axial_load : float or array_like [N]
        Axial load W of the roller, ≥ 0 (0 gives 0: the Hertz law is infinitely soft there).
    side : {"screw", "nut"}
    combination : {"distributed", "uniform", "paper01_series"}

    Returns
    -------
    ndarray [N/m]

    References
    ----------
    Paper 01 §2.2, K_sca and K_Nca; paper 04, k_H = dQ/dδ_H.
    """
    _check_side(side)
    _check_combination(combination)
    w = _as_array("roller_axial_load", roller_axial_load)
    st = _roller_model(design, combination).solve("load", w.ravel())
    k = _stiffness_from_compliance(st.compliance[:, SIDES.index(side)])
    return k.reshape(w.shape) if w.ndim else k[0]


class PowerLawFit(NamedTuple):
    """F = coefficient·δ^exponent fitted over a load range.

    Attributes
    ----------
    coefficient : float [N/m^exponent]
    exponent : float [-]
    max_relative_error : float [-]
        max |c·δ^n − F|/F over the fitted points.
    """

    coefficient: float
    exponent: float
    max_relative_error: float


def roller_side_power_law(
    design: PRSMDesign,
    side: str,
    load_range: tuple[float, float],
    *,
    combination: str = "distributed",
    points: int = 41,
) -> PowerLawFit:
    """Fit F = c·δ^n to one roller's engagement on ``side`` over ``load_range``.

    Parameters
    ----------
    design : PRSMDesign
    side : {"screw", "nut"}
    load_range : (float, float) [N]
        Roller axial loads (lo, hi), 0 < lo < hi.
    combination : {"distributed", "uniform", "paper01_series"}
    points : int
        Log-spaced loads used for the least-squares fit in log–log space (≥ 3).

    Returns
    -------
    PowerLawFit
        (coefficient, exponent, max_relative_error). A pure Hertz law gives n = 1.5 exactly;
        the teeth and bodies (linear) pull n below 1.5 at high load.

    References
    ----------
    Paper 05 (contact ∝ F^(2/3)); paper 04 (nonlinear δ_H); Johnson (1985) §4.2.
    """
    _check_side(side)
    _check_combination(combination)
    ok = (
        isinstance(load_range, (tuple, list))
        and len(load_range) == 2
        and all(isinstance(v, (int, float)) and math.isfinite(v) for v in load_range)
        and 0 < load_range[0] < load_range[1]
    )
    require(ok, "load_range", load_range, "must be (lo, hi) [N] with 0 < lo < hi")
    require(isinstance(points, int) and points >= 3, "points", points, "must be an integer ≥ 3")
    w = np.geomspace(load_range[0], load_range[1], points)
    st = _roller_model(design, combination).solve("load", w)
    delta = st.deflection[:, SIDES.index(side)]
    slope, intercept = np.polyfit(np.log(delta), np.log(w), 1)
    coef = math.exp(intercept)
    err = float(np.max(np.abs(coef * delta**slope - w) / w))
    return PowerLawFit(coef, float(slope), err)
