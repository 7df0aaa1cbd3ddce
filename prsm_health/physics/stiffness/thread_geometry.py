"""Thread flank curvature by differential geometry and the Hertz contact of one thread pair.

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

References
----------
- Paper 04 (docs/references.md) — roller surface r_R(θ, u), fundamental forms, K, H, κ1,2,
  curvature sum/difference Θ ± χ with the angle γ_i, contact deformation δ_H.
- Paper 05 (docs/references.md) — principal curvatures ρ_S.., ρ_N.., Q = F/(i sin β cos λ).
- M. P. do Carmo, *Differential Geometry of Curves and Surfaces*, 1976, §3-3: shape operator,
  K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL)/(2(EG − F²)).
- K. L. Johnson, *Contact Mechanics*, CUP 1985, §4.2 (via :mod:`.hertz`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require

from ._thread_inputs import _check_side
from .hertz import HertzContact, effective_modulus


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
