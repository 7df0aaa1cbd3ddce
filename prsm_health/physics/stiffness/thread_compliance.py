"""Linear compliances of the thread teeth (Yamamoto) and of the cores between threads.

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
    the deformation is reported in :attr:`~.axial.AxialStiffness.deformation_split`.
    :func:`yamamoto_terms` is the one implementation of the formulas; paper 05's electric
    cylinder (:func:`.cylinder.yamamoto_thread_terms`) evaluates it for its sharp V tooth.
Bodies
    Screw, roller and nut cores are bars between adjacent threads (pitch p): compliance
    p/(E·A) with A on the pitch diameter (screw, roller; paper 04 uses π r_S² for the shaft)
    and the annulus between nut pitch and outer diameter (paper 05). Screw and nut are shared
    by the n_R rollers: one roller sees the sector A/n_R.

References
----------
- Paper 04 (docs/references.md) — body stiffnesses k_BS, k_BN, k_BR, tooth compliance k_RT,
  k_NT, K_shaft = E_S π r_S²/L_free.
- Paper 05 (docs/references.md) — Yamamoto terms γ1…γ5, Δl5 (nut annulus).
- A. Yamamoto, *The Theory and Computation of Threads Connection*, Yokendo, Tokyo, 1980:
  thread-tooth deflections δ1…δ5 per unit line load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from prsm_health.actuator.design import PRSMDesign


@dataclass(frozen=True)
class ToothCompliance:
    """Axial compliance of one thread tooth per axial contact load [m/N] (Yamamoto).

    Attributes
    ----------
    bending, shear, root_bending, root_shear, radial : float [m/N]
        Yamamoto's δ1…δ5 (tooth bending, tooth shear, root inclination by the moment, root
        inclination by shear, radial contraction/expansion of the core).
    load_length : float [m]
        Thread length over which one contact's load is spread (module docstring of
        :mod:`.thread_compliance`).
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


def yamamoto_terms(
    p: float,
    a: float,
    b: float,
    c: float,
    phi: float,
    nu: float,
    radial_factor: float,
    diameter: float,
) -> tuple[float, float, float, float, float]:
    """Yamamoto's five thread-tooth deflections, dimensionless: δ_k·E/W, k = 1…5.

    Parameters
    ----------
    p : float [m]
        Axial spacing of the loaded thread rings (the pitch).
    a, b, c : float [m]
        Tooth root width, tooth width at the load point, height of the load point above the
        root (:func:`tooth_geometry`).
    phi : float [rad]
        Flank angle from the radial plane.
    nu : float [-]
        Poisson's ratio.
    radial_factor : float [-]
        Lamé factor of the radial term (see :func:`tooth_compliances`).
    diameter : float [m]
        Diameter on which the load acts.

    Returns
    -------
    (bending, shear, root_bending, root_shear, radial) : tuple of float [-]
        Divide by E for the deflection per unit line load W [m/(N/m)].

    References
    ----------
    Yamamoto (1980), δ1…δ5; paper 05, γ1…γ5 (the same terms for a 45° sharp V thread).
    """
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
        terms = yamamoto_terms(p, a, b, c, phi, mat.poisson_ratio, radial_factor, diameter)
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
