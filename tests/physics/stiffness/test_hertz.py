"""Exact Hertz point contact against closed forms and an independent approximation."""

import math

import numpy as np
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.physics.stiffness.hertz import HertzContact, effective_modulus, relative_curvatures

E_STAR = effective_modulus(2.1e11, 0.3, 2.1e11, 0.3)


def test_sphere_on_flat_closed_form():
    radius, load = 5e-3, 250.0
    c = HertzContact.from_curvatures((1 / radius, 1 / radius), (0.0, 0.0), E_STAR)
    assert c.eccentricity_sq == 0.0
    # Johnson (4.23): δ = (9P²/(16 R E*²))^(1/3), a = (3PR/(4E*))^(1/3), p0 = 3P/(2πa²).
    assert c.deflection(load) == pytest.approx(
        (9 * load**2 / (16 * radius * E_STAR**2)) ** (1 / 3), rel=1e-12
    )
    a, b = c.semi_axes(load)
    assert a == pytest.approx((3 * load * radius / (4 * E_STAR)) ** (1 / 3), rel=1e-12)
    assert b == pytest.approx(a, rel=1e-12)
    assert c.max_pressure(load) == pytest.approx(3 * load / (2 * math.pi * a * a), rel=1e-12)


def test_crossed_cylinders_equal_sphere():
    # Two equal cylinders crossed at 90° touch like a sphere of the same radius on a flat.
    radius = 4e-3
    crossed = HertzContact.from_curvatures(
        (1 / radius, 0.0), (1 / radius, 0.0), E_STAR, math.pi / 2
    )
    sphere = HertzContact.from_curvatures((1 / radius, 1 / radius), (0.0, 0.0), E_STAR)
    assert crossed.eccentricity_sq == pytest.approx(0.0, abs=1e-12)
    assert crossed.deflection(100.0) == pytest.approx(sphere.deflection(100.0), rel=1e-9)


@pytest.mark.parametrize("ratio", [1.5, 3.0, 8.0])
def test_elliptical_contact_matches_hamrock_brewe(ratio):
    # Hamrock & Brewe (1983) curve fits are accurate to ~3 % for 1 ≤ R_y/R_x ≤ 100 (their
    # stated accuracy), so the exact solution must agree to within that.
    r_x = 3e-3
    r_y = ratio * r_x
    load = 500.0
    c = HertzContact.from_curvatures((1 / r_x, 1 / r_y), (0.0, 0.0), E_STAR)
    e_prime = 2 * E_STAR
    r_eff = 1 / (1 / r_x + 1 / r_y)
    k = 1.0339 * ratio**0.636
    e_bar = 1.0003 + 0.5968 / ratio
    f_bar = 1.5277 + 0.6023 * math.log(ratio)
    a_hb = (6 * k**2 * e_bar * load * r_eff / (math.pi * e_prime)) ** (1 / 3)
    b_hb = (6 * e_bar * load * r_eff / (math.pi * k * e_prime)) ** (1 / 3)
    delta_hb = f_bar * ((9 / (2 * e_bar * r_eff)) * (load / (math.pi * k * e_prime)) ** 2) ** (
        1 / 3
    )
    a, b = c.semi_axes(load)
    assert a == pytest.approx(a_hb, rel=0.03)
    assert b == pytest.approx(b_hb, rel=0.03)
    assert c.deflection(load) == pytest.approx(delta_hb, rel=0.03)


def test_load_deflection_exponent_and_stiffness():
    c = HertzContact.from_curvatures((300.0, 300.0), (100.0, 0.0), E_STAR)
    loads = np.array([10.0, 100.0, 1000.0])
    d = c.deflection(loads)
    # δ ∝ P^(2/3) exactly.
    assert np.allclose(np.log(d[1:] / d[:-1]) / np.log(10.0), 2 / 3, rtol=1e-12)
    # Tangent stiffness against a central finite difference (step 1e-4 relative: error ~1e-8).
    h = 1e-4 * loads
    fd = 2 * h / (c.deflection(loads + h) - c.deflection(loads - h))
    assert np.allclose(c.stiffness(loads), fd, rtol=1e-6)
    # load() inverts deflection() and is zero when separated.
    assert np.allclose(c.load(d), loads, rtol=1e-12)
    assert c.load(-1e-6) == 0.0


def test_concave_surface_flatter_than_convex():
    # Paper 05's nut flank is concave (ρ_N21 < 0); it must be flatter than the roller.
    a, b = relative_curvatures((1 / 6e-3, 1 / 6e-3), (-1 / 30e-3, 0.0))
    assert 0 < a <= b
    with pytest.raises(ParameterError):
        relative_curvatures((1 / 6e-3, 1 / 6e-3), (-1 / 3e-3, -1 / 3e-3))
