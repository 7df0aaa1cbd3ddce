"""Lubrication regime of the screw–roller thread contacts: a Stribeck curve from the physics.

The Coulomb coefficient of a lubricated rolling–sliding contact depends on how much of the load
the lubricant film carries and how much the surface asperities do:

1. **Viscosity** of the oil at the operating temperature from its grade (ν at 40 °C and 100 °C)
   by the Walther equation of ASTM D341: log₁₀ log₁₀(ν + 0.7) = A − B·log₁₀ T (ν in mm²/s,
   T in K); density ρ(T) = ρ₁₅·(1 − 6.5e-4·(T − 288.15 K)).
2. **Film thickness** of the elliptical thread contact by Hamrock & Dowson (1977, minimum film,
   eq. 3): h_min = 3.63·R_x·U^0.68·G^0.49·W^−0.073·(1 − e^(−0.68k)), with U = η₀u_e/(E′R_x),
   G = αE′, W = Q/(E′R_x²), E′ = 2E*, k = 1.0339·(R_y/R_x)^0.636 and R_x the effective radius
   along the entrainment (rolling, circumferential) direction. The thread geometry comes from
   :func:`prsm_health.physics.stiffness.thread_geometry.thread_contacts`.
3. **Specific film thickness** Λ = h_min/σ, σ = √(σ₁² + σ₂²) the composite RMS roughness.
4. **Load sharing** (Johnson, Greenwood & Poon 1972): the asperities carry the share
   f_c(Λ) = F_{5/2}(Λ)/F_{5/2}(0) of the load, with F_{5/2} the Greenwood–Tripp (1970) integral
   of a Gaussian asperity-height distribution, F_{5/2}(Λ) = (2π)^−½∫_Λ^∞ (s − Λ)^{5/2} e^{−s²/2} ds;
   the coefficient is μ = f_c·μ_b + (1 − f_c)·μ_f, boundary friction of the additive film μ_b
   and traction of the full film μ_f.

That is the Stribeck shape: μ_b at very low entrainment speed (boundary), falling through the
mixed regime (Λ ≈ 0.5–2) to μ_f once the film separates the surfaces. Hotter oil is thinner and
shifts the curve to higher speeds. The viscous drag that grows with speed beyond the minimum
is the dynamics model's own viscous term (paper 01's μ_sc), not repeated here.

Lubricant health (:class:`~prsm_health.actuator.states.HealthState`):

* ``lubricant_degradation`` d ∈ [0, 1] — additive depletion and base-oil breakdown: the
  boundary coefficient rises towards that of unprotected steel, μ_b + d·(μ_dry − μ_b) with
  μ_dry = 0.3 (oxide-covered steel on steel, Bowden & Tabor 1950 range 0.3–0.6: engineering
  choice at its low end), and the viscosity falls by 30 %·d (shear breakdown of the thickener
  and viscosity improvers; engineering estimate).
* ``lubricant_starvation`` s ∈ [0, 1] — oil no longer replenishes the inlet: the film is
  (1 − s) of the fully flooded one, after Chevalier, Lubrecht, Cann, Colin & Dalmaz (1998),
  whose starved film thickness is set by the oil layer reaching the inlet.

References
----------
- B.J. Hamrock, D. Dowson, "Isothermal elastohydrodynamic lubrication of point contacts,
  Part III — fully flooded results", J. Lubr. Technol. 99 (1977) 264–276.
- J.A. Greenwood, J.H. Tripp, "The contact of two nominally flat rough surfaces", Proc. IMechE
  185 (1970) 625–633.
- K.L. Johnson, J.A. Greenwood, S.Y. Poon, "A simple theory of asperity contact in
  elastohydrodynamic lubrication", Wear 19 (1972) 91–108.
- F. Chevalier, A.A. Lubrecht, P.M.E. Cann, F. Colin, G. Dalmaz, "Film thickness in starved EHL
  point contacts", J. Tribol. 120 (1998) 126–133.
- ASTM D341 (viscosity–temperature charts, Walther equation); ISO 3448 (viscosity grades).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require, require_range

#: Friction coefficient of unprotected (oxide-covered) steel on steel, the limit of boundary
#: friction as the additive film is depleted (Bowden & Tabor 1950: 0.3–0.6; low end taken).
DRY_FRICTION = 0.3


@dataclass(frozen=True)
class Lubricant:
    """A lubricant (or a grease's base oil) as the contacts see it.

    Parameters
    ----------
    name : str
    viscosity_40, viscosity_100 : float [m²/s]
        Kinematic viscosity at 40 °C and 100 °C (ISO 3448 grades give ν40; ν100 from the
        product's data sheet or a viscosity index ≈ 95–100 for mineral oils).
    density : float [kg/m³]
        At 15 °C.
    pressure_viscosity : float [1/Pa]
        Barus coefficient α (mineral oils 1.5–2.5e-8).
    boundary_friction : float [-]
        μ_b of the additive (AW/EP) boundary film, steel on steel (0.08–0.15).
    film_friction : float [-]
        μ_f, traction of the full EHL film at the thread's slide-to-roll ratios (mineral oils
        0.02–0.06; Johnson & Tevaarwerk 1977).
    roughness : float [m]
        RMS roughness of each flank (ground threads Ra 0.2–0.4 µm, Rq ≈ 1.25·Ra); the composite
        σ is √2 times it.
    """

    name: str
    viscosity_40: float
    viscosity_100: float
    density: float = 875.0
    pressure_viscosity: float = 2.0e-8
    boundary_friction: float = 0.12
    film_friction: float = 0.04
    roughness: float = 0.3e-6

    def __post_init__(self):
        require_range("lubricant.viscosity_40", self.viscosity_40, 1e-6, 1e-2, unit="m²/s")
        require_range(
            "lubricant.viscosity_100", self.viscosity_100, 1e-7, self.viscosity_40, unit="m²/s"
        )
        require_range("lubricant.density", self.density, 500.0, 2000.0, unit="kg/m³")
        require_range(
            "lubricant.pressure_viscosity", self.pressure_viscosity, 0.0, 1e-7, unit="1/Pa"
        )
        require_range("lubricant.boundary_friction", self.boundary_friction, 0.0, 1.0)
        require_range("lubricant.film_friction", self.film_friction, 0.0, self.boundary_friction)
        require_range("lubricant.roughness", self.roughness, 1e-9, 5e-6, unit="m")

    def kinematic_viscosity(self, temperature) -> np.ndarray:
        """ν [m²/s] at ``temperature`` [K] (Walther / ASTM D341 through the two grade points)."""
        t = np.asarray(temperature, dtype=float)
        (t1, n1), (t2, n2) = (313.15, self.viscosity_40), (373.15, self.viscosity_100)
        w1 = math.log10(math.log10(n1 * 1e6 + 0.7))
        w2 = math.log10(math.log10(n2 * 1e6 + 0.7))
        slope = (w1 - w2) / (math.log10(t2) - math.log10(t1))
        w = w1 - slope * (np.log10(t) - math.log10(t1))
        return (10.0 ** (10.0**w) - 0.7) * 1e-6

    def dynamic_viscosity(self, temperature) -> np.ndarray:
        """η₀ [Pa·s] at ``temperature`` [K] and ambient pressure."""
        t = np.asarray(temperature, dtype=float)
        density = self.density * (1.0 - 6.5e-4 * (t - 288.15))
        return self.kinematic_viscosity(t) * density


#: Built-in lubricants. Mineral oils at their ISO 3448 grade with ν100 of a viscosity index
#: ≈ 95–100 (typical of industrial gear and hydraulic oils' data sheets: engineering values,
#: not one product); the grease is a lithium-complex NLGI 2 whose base oil is ISO VG 100.
LUBRICANTS = {
    "iso-vg-68": Lubricant("iso-vg-68", 68e-6, 8.7e-6, 875.0, 2.1e-8),
    "iso-vg-220": Lubricant("iso-vg-220", 220e-6, 19.0e-6, 890.0, 2.3e-8),
    "grease-vg-100": Lubricant("grease-vg-100", 100e-6, 11.0e-6, 880.0, 2.2e-8),
}
DEFAULT_LUBRICANT = "grease-vg-100"


def lubricant(name: str | Lubricant) -> Lubricant:
    """A built-in lubricant by name (or the lubricant itself)."""
    if isinstance(name, Lubricant):
        return name
    require(
        name in LUBRICANTS,
        "options.lubricant",
        name,
        f"must be one of {', '.join(LUBRICANTS)}",
    )
    return LUBRICANTS[name]


def _greenwood_tripp(lam: float) -> float:
    return quad(lambda s: (s - lam) ** 2.5 * math.exp(-0.5 * s * s), lam, lam + 12.0)[0] / (
        math.sqrt(2 * math.pi)
    )


_GT_GRID = np.linspace(0.0, 4.0, 81)
_GT_VALUES = np.array([_greenwood_tripp(x) for x in _GT_GRID]) / _greenwood_tripp(0.0)


def asperity_share(film_ratio) -> np.ndarray:
    """f_c(Λ) = F_{5/2}(Λ)/F_{5/2}(0), the share of the load the asperities carry [-]
    (0 beyond Λ = 4, where it is below 1e-5)."""
    lam = np.asarray(film_ratio, dtype=float)
    return np.interp(lam, _GT_GRID, _GT_VALUES, left=1.0, right=0.0)


@dataclass(frozen=True)
class StribeckCurve:
    """Film and friction of the screw–roller contact over entrainment speed.

    Attributes
    ----------
    speed : ndarray [m/s]
        Entrainment speed u_e = (u₁ + u₂)/2 of the surfaces relative to the contact.
    film_thickness : ndarray [m]
        Minimum film thickness h_min.
    film_ratio : ndarray [-]
        Λ = h_min/σ.
    coefficient : ndarray [-]
        Coulomb coefficient μ.
    """

    speed: np.ndarray
    film_thickness: np.ndarray
    film_ratio: np.ndarray
    coefficient: np.ndarray


def stribeck_curve(
    design: PRSMDesign,
    lube: str | Lubricant,
    speeds,
    *,
    axial_load: float,
    temperature: float = 313.15,
    degradation: float = 0.0,
    starvation: float = 0.0,
) -> StribeckCurve:
    """The screw–roller contact's Coulomb coefficient at entrainment ``speeds`` [m/s].

    Parameters
    ----------
    design : PRSMDesign
    lube : str or Lubricant
        A :data:`LUBRICANTS` name or a lubricant.
    speeds : array_like [m/s]
    axial_load : float [N]
        Axial load of the actuator; shared by all rollers and engaged threads (the film
        depends on it only as W^−0.073).
    temperature : float [K]
        Oil temperature in the contact inlet.
    degradation, starvation : float [-]
        Lubricant health, 0 … 1 (module docstring); ``degradation`` may be an array that
        broadcasts with ``speeds`` (one curve per degradation).
    """
    from .stiffness.thread_geometry import normal_load, thread_contacts

    oil = lubricant(lube)
    require_range("profile.temperature", temperature, 223.15, 473.15, unit="K")
    degradation = np.asarray(degradation, dtype=float)  # may be an array: broadcast with speeds
    for bound in (degradation.min(initial=0.0), degradation.max(initial=0.0)):
        require_range("health.lubricant_degradation", float(bound), 0.0, 1.0)
    require_range("health.lubricant_starvation", starvation, 0.0, 1.0)
    contact = thread_contacts(design)[0]
    e_prime = 2.0 * contact.contact_modulus
    r_x = 0.5 / contact.b_coef  # rolling direction: the larger (circumferential) curvature
    r_y = 0.5 / contact.a_coef
    ellipticity = 1.0339 * (r_y / r_x) ** 0.636
    per_contact = max(abs(axial_load), 20.0) / (design.n_rollers * design.engaged_threads)
    q = float(normal_load(design, per_contact, "screw"))
    eta = float(oil.dynamic_viscosity(temperature)) * (1.0 - 0.3 * degradation)
    u = np.maximum(np.asarray(speeds, dtype=float), 0.0)
    big_u = eta * u / (e_prime * r_x)
    h = (
        3.63
        * r_x
        * big_u**0.68
        * (oil.pressure_viscosity * e_prime) ** 0.49
        * (q / (e_prime * r_x**2)) ** -0.073
        * (1.0 - math.exp(-0.68 * ellipticity))
        * (1.0 - starvation)
    )
    film_ratio = h / (math.sqrt(2.0) * oil.roughness)
    share = asperity_share(film_ratio)
    boundary = oil.boundary_friction + degradation * (DRY_FRICTION - oil.boundary_friction)
    mu = share * boundary + (1.0 - share) * oil.film_friction
    return StribeckCurve(u, h, film_ratio, mu)
