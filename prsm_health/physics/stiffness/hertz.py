"""Hertzian point contact of two curved elastic bodies (elliptical contact area).

The thread contacts of a PRSM (screw–roller, roller–nut) are point contacts between a
roller's circular thread profile and the screw's or nut's flank helicoid. Given the principal
curvatures of both surfaces at the contact point, this module solves Hertz's problem exactly
(complete elliptic integrals, no curve-fit approximations) and returns the normal approach δ,
the contact semi-axes and the contact stiffness dP/dδ = 3P/(2δ).

Sign convention: a curvature is positive where the surface is convex (centre of curvature
inside the body), negative where concave (the nut's internal flank, paper 05 ρ_N21 < 0).

References
----------
- Paper 04 (docs/references.md): curvature sum and difference
  Θ ± χ, equivalent radius R_E = ½(Θχ)^(-1/2), δ_H = (9Q²/(16E*²R_E))^(1/3)·F_2.
- Paper 05 (docs/references.md): contact deformation built from
  Σρ and the tabulated coefficient 2K(e)/(π m_a).
- K. L. Johnson, *Contact Mechanics*, CUP 1985, §4.2 eqs. (4.4), (3.64)–(3.69): exact solution
  used here; the paper formulas are special forms of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from prsm_health.core.errors import require, require_positive


def effective_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Contact modulus E* with 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2.

    Parameters
    ----------
    e1, e2 : float [Pa]
    nu1, nu2 : float [-]

    Returns
    -------
    float [Pa]
    """
    return 1.0 / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def relative_curvatures(
    body1: tuple[float, float], body2: tuple[float, float], angle: float = 0.0
) -> tuple[float, float]:
    """Coefficients A ≤ B of the gap h = A·x² + B·y² between two curved bodies.

    Parameters
    ----------
    body1, body2 : (float, float) [1/m]
        Principal curvatures (κ', κ'') of each surface at the contact point.
    angle : float [rad]
        Angle between the planes of κ'_1 and κ'_2 (paper 04's γ_i).

    Returns
    -------
    (A, B) : (float, float) [1/m]
        A + B = ½ Σκ (paper 04's Θ + χ), B − A per paper 04's Θ − χ.

    References
    ----------
    Paper 04, equations for Θ_i ± χ_i; Johnson (1985) eq. (4.4).
    """
    k1a, k1b = body1
    k2a, k2b = body2
    total = 0.5 * (k1a + k1b + k2a + k2b)
    d1 = k1a - k1b
    d2 = k2a - k2b
    diff = 0.5 * math.sqrt(max(0.0, d1 * d1 + d2 * d2 + 2.0 * d1 * d2 * math.cos(2.0 * angle)))
    a_coef = 0.5 * (total - diff)
    b_coef = 0.5 * (total + diff)
    require(
        a_coef > 0.0,
        "contact curvature",
        a_coef,
        "the bodies must close on each other (A > 0); a concave surface must be flatter "
        "than the convex one it touches",
    )
    return a_coef, b_coef


def _k_minus_e_over_m(m: float) -> float:
    # (K − E)/m loses all digits to cancellation as m → 0; its series is π/4·(1 + 3m/8 + …).
    if m < 1e-6:
        return 0.25 * math.pi * (1.0 + 0.375 * m)
    return (ellipk(m) - ellipe(m)) / m


def _axis_ratio_equation(m: float, ratio: float) -> float:
    # Johnson (3.69): B/A = [(a/b)²E(e) − K(e)] / [K(e) − E(e)], with (a/b)² = 1/(1 − e²), m = e².
    k, e = ellipk(m), ellipe(m)
    return (e / (1.0 - m) - k) / (k - e) - ratio if m > 1e-6 else 1.0 + 1.5 * m - ratio


@dataclass(frozen=True)
class HertzContact:
    """Hertzian point contact of fixed geometry: δ = c·P^(2/3).

    Parameters
    ----------
    a_coef, b_coef : float [1/m]
        Gap coefficients A ≤ B from :func:`relative_curvatures`.
    contact_modulus : float [Pa]
        E* from :func:`effective_modulus`.

    Attributes
    ----------
    eccentricity_sq : float [-]
        e² = 1 − (b/a)² of the contact ellipse (0 for a circle).
    compliance_coefficient : float [m/N^(2/3)]
        c in δ = c·P^(2/3).

    References
    ----------
    Johnson (1985) eqs. (3.64)–(3.69); paper 04 δ_H; paper 05 k_S, k_N.
    """

    a_coef: float
    b_coef: float
    contact_modulus: float

    def __post_init__(self):
        require_positive("contact a_coef", self.a_coef)
        require_positive("contact b_coef", self.b_coef)
        require_positive("contact_modulus", self.contact_modulus)
        require(
            self.b_coef >= self.a_coef * (1 - 1e-12),
            "contact b_coef",
            self.b_coef,
            "must be ≥ a_coef",
        )

    @classmethod
    def from_curvatures(
        cls,
        body1: tuple[float, float],
        body2: tuple[float, float],
        contact_modulus: float,
        angle: float = 0.0,
    ) -> HertzContact:
        """Contact of two surfaces given their principal curvatures [1/m]."""
        a_coef, b_coef = relative_curvatures(body1, body2, angle)
        return cls(a_coef, b_coef, contact_modulus)

    @property
    def eccentricity_sq(self) -> float:
        ratio = self.b_coef / self.a_coef
        if ratio - 1.0 < 1e-12:
            return 0.0
        return brentq(
            _axis_ratio_equation, 1e-12, 1.0 - 1e-15, args=(ratio,), xtol=1e-15, rtol=1e-14
        )

    def _major_axis_coefficient(self) -> float:
        # a³ = 3P(K − E)/(2π E* e² A)  →  a = α·P^(1/3)
        m = self.eccentricity_sq
        return (
            3.0 * _k_minus_e_over_m(m) / (2.0 * math.pi * self.contact_modulus * self.a_coef)
        ) ** (1 / 3)

    @property
    def compliance_coefficient(self) -> float:
        # δ = 3P·K(e)/(2π a E*)
        m = self.eccentricity_sq
        return (
            3.0
            * ellipk(m)
            / (2.0 * math.pi * self.contact_modulus * self._major_axis_coefficient())
        )

    @property
    def equivalent_radius(self) -> float:
        """R_E = ½(AB)^(-1/2) [m] (paper 04)."""
        return 0.5 / math.sqrt(self.a_coef * self.b_coef)

    def deflection(self, load):
        """Normal approach δ [m] under normal load ``load`` [N] (array or scalar, ≥ 0)."""
        load = np.asarray(load, dtype=float)
        return self.compliance_coefficient * np.cbrt(np.maximum(load, 0.0)) ** 2

    def load(self, deflection):
        """Normal load [N] at approach ``deflection`` [m]; zero when separated (δ ≤ 0)."""
        deflection = np.asarray(deflection, dtype=float)
        return (np.maximum(deflection, 0.0) / self.compliance_coefficient) ** 1.5

    def stiffness(self, load):
        """Tangent normal stiffness dP/dδ = 3P/(2δ) = 1.5·P^(1/3)/c [N/m]."""
        load = np.asarray(load, dtype=float)
        return 1.5 * np.cbrt(np.maximum(load, 0.0)) / self.compliance_coefficient

    def semi_axes(self, load) -> tuple[np.ndarray, np.ndarray]:
        """Contact-ellipse semi-axes (a, b) [m], a ≥ b."""
        a = self._major_axis_coefficient() * np.cbrt(np.maximum(np.asarray(load, float), 0.0))
        return a, a * math.sqrt(1.0 - self.eccentricity_sq)

    def max_pressure(self, load):
        """Peak contact pressure p0 = 3P/(2πab) [Pa]."""
        a, b = self.semi_axes(load)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(a > 0, 3.0 * np.asarray(load, float) / (2.0 * math.pi * a * b), 0.0)
