"""Thread contact geometry, load distribution and PRSM axial stiffness (stiffness/: thread_geometry, thread_compliance, thread_load, clearance,
axial).

Checks are against closed forms (paper 05's curvatures, Yamamoto's tooth terms), independent
numerical methods (height-function fit, quadrature, finite differences), analytical limits
(Hertz exponents, rigid bodies, equal gaps) and physical bounds. No paper-04 table value is
asserted: the paper contradicts itself (docs/validation.md).
"""

import importlib
import math

import numpy as np
import pytest
from scipy.integrate import quad

from prsm_health.actuator.design import preset
from prsm_health.core.errors import ConvergenceError, ParameterError
from prsm_health.physics.stiffness._thread_inputs import SIDES
from prsm_health.physics.stiffness.axial import axial_stiffness
from prsm_health.physics.stiffness.clearance import eccentricity_to_gaps, radial_to_axial_gap
from prsm_health.physics.stiffness.thread_compliance import (
    body_compliances,
    shaft_stiffness,
    tooth_compliances,
    tooth_geometry,
)
from prsm_health.physics.stiffness.thread_geometry import (
    helical_surface_curvature,
    normal_load,
    thread_contact_geometry,
    thread_contacts,
    thread_surface_curvatures,
)
from prsm_health.physics.stiffness.thread_load import (
    roller_side_force,
    roller_side_power_law,
    roller_side_stiffness,
    thread_load_distribution,
    thread_pair_deflection,
)
from prsm_health.validation import NOT_REPRODUCED, REPRODUCED
from prsm_health.validation import paper04 as v04

P04 = preset("paper04")  # λ_s = 1.74°, λ_r = 1.04°: the small-lead case
P01 = preset("paper01")  # λ_s = 9.27°, λ_r = 5.59°


# ============================================================================ geometry
def _roller_lower_flank(design, lead):
    big_r = design.roller_thread_radius
    rho = big_r * math.cos(design.contact_angle)
    z0 = math.sqrt(big_r**2 - rho**2)
    h = lead / (2 * math.pi)

    def surface(t, r):
        return np.array([r * np.cos(t), r * np.sin(t), h * t - (np.sqrt(big_r**2 - r**2) - z0)])

    return surface, rho, rho / z0, big_r**2 / z0**3


def test_fundamental_forms_against_closed_form_and_finite_differences():
    surface, rho, fp, fpp = _roller_lower_flank(P01, P01.roller_lead)
    s = helical_surface_curvature(rho, P01.roller_lead, fp, fpp, theta=math.pi, material="above")
    h = P01.roller_lead / (2 * math.pi)
    w = math.sqrt(rho**2 * (1 + fp**2) + h**2)
    # Closed forms for r = (ρ cos θ, ρ sin θ, hθ + f): E = ρ² + h², F = h f', G = 1 + f'²;
    # with the inward normal (material above → −(r_θ × r_ρ)/W) at θ = π: L = ρ²f'/W,
    # M = −h/W, N = ρf''/W, W = √(ρ²(1 + f'²) + h²).
    assert s.first_form == pytest.approx((rho**2 + h**2, h * fp, 1 + fp**2), rel=1e-13)
    assert s.second_form == pytest.approx((rho**2 * fp / w, -h / w, rho * fpp / w), rel=1e-12)
    # Central differences of the parametrisation (steps 1e-4 rad and 1e-4·ρ): truncation
    # O(step²) ≈ 1e-8 and rounding ≈ 1e-16/1e-8 ≈ 1e-8 relative, so 1e-5 is generous.
    dt, dr = 1e-4, 1e-4 * rho
    t0 = math.pi
    r_t = (surface(t0 + dt, rho) - surface(t0 - dt, rho)) / (2 * dt)
    r_r = (surface(t0, rho + dr) - surface(t0, rho - dr)) / (2 * dr)
    r_tt = (surface(t0 + dt, rho) - 2 * surface(t0, rho) + surface(t0 - dt, rho)) / dt**2
    r_rr = (surface(t0, rho + dr) - 2 * surface(t0, rho) + surface(t0, rho - dr)) / dr**2
    r_tr = (
        surface(t0 + dt, rho + dr)
        - surface(t0 + dt, rho - dr)
        - surface(t0 - dt, rho + dr)
        + surface(t0 - dt, rho - dr)
    ) / (4 * dt * dr)
    inward = -s.normal
    fd_first = (r_t @ r_t, r_t @ r_r, r_r @ r_r)
    fd_second = (r_tt @ inward, r_tr @ inward, r_rr @ inward)
    assert np.allclose(fd_first, s.first_form, rtol=1e-5, atol=1e-5 * abs(s.first_form[1]) + 1e-15)
    assert np.allclose(fd_second, s.second_form, rtol=1e-5, atol=1e-5 * abs(s.second_form[0]))


@pytest.mark.parametrize("design", [P04, P01], ids=["paper04", "paper01"])
def test_principal_curvatures_against_height_function_fit(design):
    # Independent method: sample the surface near the point, express it as a height w(x, y)
    # over the tangent plane and fit a cubic; the Hessian of the quadratic part has the
    # principal curvatures as eigenvalues. Patch ±0.4 % of ρ: the neglected quartic terms
    # change the fitted Hessian by ~(patch/ρ)² ≈ 1e-5 relative; 1e-3 leaves margin.
    surface, rho, _, _ = _roller_lower_flank(design, design.roller_lead)
    s = thread_surface_curvatures(design)["roller_screw_side"]
    p0 = surface(math.pi, rho)
    n_in = -s.normal
    e1 = s.directions[0]
    e2 = np.cross(n_in, e1)
    pts = np.array(
        [
            surface(math.pi + a, rho + b) - p0
            for a in np.linspace(-4e-3, 4e-3, 15)
            for b in np.linspace(-4e-3 * rho, 4e-3 * rho, 15)
        ]
    )
    x, y, w = pts @ e1, pts @ e2, pts @ n_in
    basis = np.c_[x * x, x * y, y * y, x, y, x**3, x * x * y, x * y * y, y**3]
    c = np.linalg.lstsq(basis, w, rcond=None)[0]
    fitted = np.sort(np.linalg.eigvalsh([[2 * c[0], c[1]], [c[1], 2 * c[2]]]))[::-1]
    assert fitted == pytest.approx(s.principal, rel=1e-3)


def test_gaussian_and_mean_curvature_paper04_formulas():
    for s in thread_surface_curvatures(P01).values():
        k1, k2 = s.principal
        # Paper 04: κ1,2 = H ± √(H² − K) (its H has the opposite normal, hence the sign).
        assert k1 == pytest.approx(s.mean + math.sqrt(s.mean**2 - s.gaussian), rel=1e-9, abs=1e-9)
        assert k2 == pytest.approx(s.mean - math.sqrt(s.mean**2 - s.gaussian), rel=1e-9, abs=1e-6)
        assert k1 * k2 == pytest.approx(s.gaussian, rel=1e-9, abs=1e-9)
        assert abs(s.directions[0] @ s.directions[1]) < 1e-12  # principal directions ⟂


def test_curvatures_match_paper05_closed_forms_small_lead():
    d = P04
    beta = d.contact_angle
    surf = thread_surface_curvatures(d)
    lam_s, lam_n = d.screw_lead_angle, d.nut_lead_angle
    roller = 2 * math.cos(beta) / d.roller_diameter
    screw = 2 * math.cos(beta) / (d.screw_diameter * math.cos(lam_s))
    nut = -2 * math.cos(beta) / (d.nut_diameter * math.cos(lam_n))
    # Screw and nut flanks: the lead changes the curvatures at O(tan²λ) ≈ 1e-3 here, as
    # does paper 05's 1/cos λ: 1 % tolerance (10× margin). The second curvature is O(tan²λ)·κ1.
    assert surf["screw"].principal[0] == pytest.approx(screw, rel=1e-2)
    assert abs(surf["screw"].principal[1]) < 1e-2 * screw
    assert surf["nut"].principal[1] == pytest.approx(nut, rel=1e-2)
    assert abs(surf["nut"].principal[0]) < 1e-2 * abs(nut)
    # Roller: paper 05's ρ11 = ρ12 (an umbilic without lead). The helix twists the surface and
    # splits the two curvatures at first order in tan λ_r (±2.6 % at 1.04°), while their mean
    # changes only at O(tan²λ): mean to 0.1 %, each curvature within a few % (4 %).
    for key in ("roller_screw_side", "roller_nut_side"):
        k1, k2 = surf[key].principal
        assert 0.5 * (k1 + k2) == pytest.approx(roller, rel=1e-3)
        assert k1 == pytest.approx(roller, rel=0.04) and k2 == pytest.approx(roller, rel=0.04)


def test_zero_lead_reproduces_paper05_exactly_and_split_is_linear_in_lead():
    beta = math.radians(45)
    r = 3.5e-3
    big_r = r / math.cos(beta)
    root = math.sqrt(big_r**2 - r**2)
    splits = []
    for lead in (0.0, 1e-4, 2e-4):
        s = helical_surface_curvature(
            r, lead, r / root, big_r**2 / root**3, theta=math.pi, material="above"
        )
        splits.append(s.principal[0] - s.principal[1])
        if lead == 0.0:
            # Surfaces of revolution: paper 05's forms are exact.
            assert s.principal == pytest.approx((math.cos(beta) / r,) * 2, rel=1e-12)
    screw = helical_surface_curvature(10e-3, 0.0, -1.0, 0.0, material="below")
    assert screw.principal == pytest.approx((math.cos(beta) / 10e-3, 0.0), rel=1e-12, abs=1e-12)
    # Doubling a small lead doubles the split (first order), to the O(λ²) remainder (1 %).
    assert splits[2] / splits[1] == pytest.approx(2.0, rel=1e-2)


def test_contact_normals_and_angle():
    for d in (P04, P01):
        s, n = thread_contact_geometry(d)
        # Roller and nut share the lead angle: the nominal point is a true contact point.
        assert n.normal_misalignment < 1e-12
        # Screw side: same-hand helices tilt the normals apart by ≈ sinβ(tanλ_s + tanλ_r)
        # (small-angle estimate, 3 % covers its second-order error at λ_s = 9°).
        expected = math.sin(d.contact_angle) * (
            math.tan(d.screw_lead_angle) + math.tan(d.roller_lead_angle)
        )
        assert s.normal_misalignment == pytest.approx(expected, rel=0.03)
        for g in (s, n):
            assert 0.0 <= g.principal_angle <= math.pi / 2
            assert g.axial_factor == pytest.approx(
                math.sin(d.contact_angle)
                * math.cos(d.screw_lead_angle if g.side == "screw" else d.nut_lead_angle)
            )


# ============================================================================ contact laws
def test_hertz_exponent_and_axial_projection():
    for contact in thread_contacts(P04):
        # Per contact δ ∝ Q^(2/3) exactly.
        q = np.array([10.0, 20.0, 1000.0])
        d = contact.deflection(q)
        assert np.log(d[1] / d[0]) / np.log(2.0) == pytest.approx(2 / 3, rel=1e-12)
    geo_s, _ = thread_contact_geometry(P04)
    fa = 150.0
    q = normal_load(P04, fa, "screw")
    assert q == pytest.approx(
        fa / (math.sin(P04.contact_angle) * math.cos(P04.screw_lead_angle)), rel=1e-15
    )
    # Virtual work: axial load × axial approach = normal load × normal approach.
    u = geo_s.axial_compliance_coefficient * fa ** (2 / 3)
    assert fa * u == pytest.approx(q * geo_s.hertz.deflection(q), rel=1e-12)


# ============================================================================ teeth
@pytest.mark.parametrize("beta_deg", [30.0, 45.0, 60.0])
def test_yamamoto_bending_and_shear_against_quadrature(beta_deg):
    d = P04.with_(contact_angle=math.radians(beta_deg))
    g = tooth_geometry(d)
    a, b, c, phi = g["a"], g["b"], g["c"], g["flank_angle"]
    nu, e = d.screw_material.poisson_ratio, d.screw_material.youngs_modulus
    t = tooth_compliances(d)["screw"]
    scale = e * t.load_length
    tan_p = math.tan(phi)

    def width(x):
        return a - 2 * x * tan_p

    # Plane-strain cantilever: M(x) = W(c − x) − W tanφ·b/2, unit-load deflection at x = c.
    bend = (
        12
        * (1 - nu**2)
        * quad(lambda x: ((c - x) ** 2 - 0.5 * b * tan_p * (c - x)) / width(x) ** 3, 0, c)[0]
    )
    shear = 1.2 * 2 * (1 + nu) * quad(lambda x: 1 / width(x), 0, c)[0]
    # quad is accurate to ~1e-14 on these smooth integrands.
    assert t.bending * scale == pytest.approx(bend, rel=1e-9)
    assert t.shear * scale == pytest.approx(shear, rel=1e-9)
    assert t.total > 0
    assert abs(b + 2 * c * tan_p - a) < 1e-15 and a <= d.pitch * (1 + 1e-12)


def test_yamamoto_terms_equal_paper05_gammas_for_45deg_v_thread():
    # Full V at 45° (a = p, b = p/2, c = p/4): paper 05's γ1…γ5 with F'·sinβ replaced by the
    # line load W (cylinder.py documents that reading): E·ℓ·δ_k/W equals the brackets below.
    d = P04
    nu = d.screw_material.poisson_ratio
    t = tooth_compliances(d)["screw"]
    scale = d.screw_material.youngs_modulus * t.load_length
    assert t.bending * scale == pytest.approx(
        (1 - nu**2) * 3 * (4 * math.log(2) - 3) / 8, rel=1e-12
    )
    assert t.shear * scale == pytest.approx((1 + nu) * 6 * math.log(2) / 5, rel=1e-12)
    assert t.root_bending * scale == pytest.approx(0.0, abs=1e-12)
    assert t.root_shear * scale == pytest.approx((1 - nu**2) * 3 * math.log(3) / math.pi, rel=1e-12)
    assert t.radial * scale == pytest.approx((1 - nu) * d.screw_diameter / (2 * d.pitch), rel=1e-12)
    assert t.load_length == pytest.approx(math.pi * d.screw_diameter / d.n_rollers)


# ============================================================================ distribution
def test_load_distribution_equilibrium_and_first_thread():
    loads = np.array([5.0, 1000 / 7, 2e4])
    ld = thread_load_distribution(P01, loads)
    for side in (ld.screw, ld.nut):
        assert np.allclose(side.sum(axis=1), loads, rtol=1e-9, atol=0)
        assert np.all(np.argmax(side, axis=1) == 0)
        assert np.all(np.diff(side, axis=1) < 0)  # decreasing away from the loaded end


def test_load_distribution_satisfies_compatibility():
    ld = thread_load_distribution(P01, 3000.0, body_scale=20.0)  # strongly non-uniform
    bodies = {k: 20.0 * v for k, v in body_compliances(P01).items()}
    q_s, q_n = ld.screw, ld.nut
    u_s = thread_pair_deflection(P01, q_s, "screw")
    u_n = thread_pair_deflection(P01, q_n, "nut")
    beyond_s = q_s.sum() - np.cumsum(q_s)[:-1]  # Σ_{k>j} Q_k
    beyond_n = q_n.sum() - np.cumsum(q_n)[:-1]
    rhs_s = (bodies["screw"] + bodies["roller"]) * beyond_s - bodies["roller"] * beyond_n
    rhs_n = (bodies["nut"] + bodies["roller"]) * beyond_n - bodies["roller"] * beyond_s
    # Newton stops at 1e-13 of the scaled residual: 1e-9 of the approach is ample.
    assert np.allclose(u_s[:-1] - u_s[1:], rhs_s, rtol=0, atol=1e-9 * u_s[0])
    assert np.allclose(u_n[:-1] - u_n[1:], rhs_n, rtol=0, atol=1e-9 * u_n[0])
    assert ld.screw_deflection == pytest.approx(u_s[0], rel=1e-9)
    assert ld.nut_deflection == pytest.approx(u_n[0], rel=1e-9)
    assert q_s[0] / q_s[-1] > 3


def test_rigid_bodies_give_uniform_sharing():
    w = 1000.0
    n = P01.engaged_threads
    rigid = thread_load_distribution(P01, w, body_scale=0.0)
    assert np.all(rigid.screw == w / n) and np.all(rigid.nut == w / n)
    uniform = thread_load_distribution(P01, w, combination="uniform")
    assert np.array_equal(uniform.screw, rigid.screw)
    # Limit: the spread of the distributed solution vanishes linearly with the body compliance.
    spreads = [np.ptp(thread_load_distribution(P01, w, body_scale=s).screw) for s in (1e-2, 1e-3)]
    assert spreads[1] < spreads[0] and spreads[1] / (w / n) < 1e-3
    assert spreads[0] / spreads[1] == pytest.approx(10.0, rel=1e-2)


def test_paper01_series_reading():
    w = 1000 / 7
    n = P01.engaged_threads
    series = thread_load_distribution(P01, w, combination="paper01_series")
    assert np.all(series.screw == w)  # series springs all carry the roller load
    bodies = body_compliances(P01)
    expected = n * (
        thread_pair_deflection(P01, w, "screw") + (bodies["screw"] + bodies["roller"]) * w
    )
    assert series.screw_deflection == pytest.approx(expected, rel=1e-12)
    dist = thread_load_distribution(P01, w)
    # Contact part alone is n^(5/3) = 46× softer in series; the whole side well over n×.
    assert series.screw_stiffness < dist.screw_stiffness / n


# ============================================================================ mechanism
def test_paper04_order_of_magnitude():
    k = axial_stiffness(P04, 10e3).secant_stiffness
    # Notes: 150–800 N/µm at 10 kN for such sizes (model gives ≈ 237 N/µm).
    assert 150e6 < k < 800e6


def test_stiffness_sublinear_in_load_and_tangent():
    loads = np.array([1e3, 1e4, 2e4, 5e4, 7e4])
    r = axial_stiffness(P04, loads)
    ks = r.secant_stiffness
    assert np.all(np.diff(ks) > 0)
    # Hertz (δ ∝ F^(2/3)) + linear springs: secant grows at most as F^(1/3).
    assert np.all(ks[1:] / ks[:-1] <= (loads[1:] / loads[:-1]) ** (1 / 3))
    assert np.all(r.tangent_stiffness > ks)  # δ(F) is concave
    # Tangent against central differences (step 1e-5·F: error ~1e-10, rounding ~1e-10).
    h = 1e-5 * loads
    fd = (
        2
        * h
        / (
            axial_stiffness(P04, loads + h).deformation
            - axial_stiffness(P04, loads - h).deformation
        )
    )
    assert np.allclose(r.tangent_stiffness, fd, rtol=1e-6)
    parts = r.deformation_split
    assert np.allclose(sum(parts.values()), r.deformation, rtol=1e-12)
    assert np.all(parts["gaps"] == 0)
    zero = axial_stiffness(P04, 0.0)
    assert zero.deformation == 0 and zero.secant_stiffness == 0 and zero.tangent_stiffness == 0


def test_scalar_and_array_loads_agree():
    r = axial_stiffness(P04, [1e4, 2e4])
    s = axial_stiffness(P04, 2e4)
    # the same equations; numpy's vectorised and scalar paths may round the last bit apart
    # (seen 1 ulp on this machine), so agreement to 1e-12, not bitwise
    assert s.secant_stiffness == pytest.approx(r.secant_stiffness[1], rel=1e-12)
    assert s.thread_loads_screw.shape == (P04.n_rollers, P04.engaged_threads)
    assert r.thread_loads_nut.shape == (2, P04.n_rollers, P04.engaged_threads)


def test_stiffness_rises_with_roller_count_sublinearly():
    load = 2e4
    counts = (5, 7, 9, 11)
    k = [axial_stiffness(P04.with_(n_rollers=n), load).secant_stiffness for n in counts]
    assert np.all(np.diff(k) > 0)
    # Bound: contact stiffens as n_R^(2/3); shaft, nut dilation and screw/nut teeth do not
    # change with n_R (only the tiny roller-tooth term falls faster, as 1/n_R).
    assert k[-1] / k[0] <= (counts[-1] / counts[0]) ** (2 / 3)
    # The contact part alone scales exactly as n_R^(-2/3) when the threads share uniformly.
    c = [
        axial_stiffness(P04.with_(n_rollers=n), load, combination="uniform").deformation_split[
            "contact"
        ]
        for n in (5, 11)
    ]
    assert c[0] / c[1] == pytest.approx((11 / 5) ** (2 / 3), rel=1e-12)


def test_stiffness_rises_with_contact_angle():
    k = [
        axial_stiffness(P04.with_(contact_angle=math.radians(b)), 1e4).secant_stiffness
        for b in (30, 45, 60)
    ]
    assert k[0] < k[1] < k[2]


def test_zero_and_equal_gaps_reproduce_the_ideal_case_exactly():
    loads = np.array([0.0, 500.0, 5e3])
    ideal = axial_stiffness(P01, loads)
    for gaps in (np.zeros(7), np.full(7, 5e-6)):
        r = axial_stiffness(P01, loads, roller_gaps=gaps)
        for name in (
            "deformation",
            "secant_stiffness",
            "tangent_stiffness",
            "roller_loads",
            "thread_loads_screw",
        ):
            assert np.array_equal(getattr(r, name), getattr(ideal, name))
    assert np.array_equal(
        axial_stiffness(P01, loads, eccentricity=0.0).deformation, ideal.deformation
    )


def test_uneven_gaps_and_eccentricity_reduce_stiffness():
    loads = np.array([300.0, 3e3])
    ideal = axial_stiffness(P01, loads)
    gaps = np.array([0, 2, 4, 6, 8, 10, 12]) * 1e-6
    r = axial_stiffness(P01, loads, roller_gaps=gaps)
    assert np.all(r.secant_stiffness < ideal.secant_stiffness)
    assert np.all(r.tangent_stiffness < ideal.tangent_stiffness)
    assert np.allclose(r.roller_loads.sum(axis=1), loads, rtol=1e-10)
    # Loaded rollers share one approach: δ_i + g_i = Δ.
    for row_w, row_d in zip(r.roller_loads, r.roller_deflections):
        on = row_w > 0
        assert np.ptp(row_d[on] + gaps[on]) < 1e-9 * row_d.max()
        assert np.all(row_d[~on] == 0) and np.all(gaps[~on] >= gaps[on].max())
    assert np.allclose(sum(r.deformation_split.values()), r.deformation, rtol=1e-12)
    e = axial_stiffness(P01, loads, eccentricity=10e-6)
    assert np.all(e.secant_stiffness < ideal.secant_stiffness)


def test_far_roller_carries_nothing_and_others_share_equally():
    load = 2000.0
    gaps = np.zeros(7)
    gaps[3] = 1e-3  # far beyond any approach at 2 kN
    r = axial_stiffness(P01, load, roller_gaps=gaps)
    assert r.roller_loads[3] == 0.0
    others = np.delete(r.roller_loads, 3)
    assert np.allclose(others, load / 6, rtol=1e-10)
    # Δ equals one roller's approach at F/6 (independent load-controlled solve) + shaft.
    one = thread_load_distribution(P01, load / 6)
    expected = one.screw_deflection + one.nut_deflection + load / shaft_stiffness(P01)
    assert r.deformation == pytest.approx(expected, rel=1e-10)


def test_radial_to_axial_gap_and_eccentricity():
    d = P01
    lam = 0.5 * (1 / math.cos(d.screw_lead_angle) + 1 / math.cos(d.nut_lead_angle))
    assert radial_to_axial_gap(d, 1e-5) == pytest.approx(
        1e-5 * lam / math.tan(d.contact_angle), rel=1e-14
    )
    gaps = eccentricity_to_gaps(d, 10e-6)
    assert gaps.min() == 0.0 and gaps[0] == 0.0  # roller 0 faces the offset
    # Rollers at 2πi/7: room changes from −e (i = 0) to +e·cos(π/7) (i = 3, 4).
    assert np.ptp(gaps) == pytest.approx(
        radial_to_axial_gap(d, 10e-6) * (1 + math.cos(math.pi / 7)), rel=1e-12
    )
    assert np.allclose(gaps[1:], gaps[1:][::-1])  # symmetric about the offset direction


# ============================================================================ simulator API
@pytest.mark.parametrize("side", SIDES)
def test_roller_side_force_inverts_the_distribution(side):
    w = np.array([1.0, 50.0, 2000.0])
    ld = thread_load_distribution(P01, w)
    defl = getattr(ld, f"{side}_deflection")
    assert np.allclose(roller_side_force(P01, defl, side), w, rtol=1e-10)
    assert np.all(roller_side_force(P01, np.array([-1e-6, 0.0]), side) == 0.0)
    # Tangent stiffness against central differences of the force law (step 1e-6·δ).
    h = 1e-6 * defl
    fd = (roller_side_force(P01, defl + h, side) - roller_side_force(P01, defl - h, side)) / (2 * h)
    assert np.allclose(roller_side_stiffness(P01, w, side), fd, rtol=1e-6)
    assert roller_side_stiffness(P01, 0.0, side) == 0.0


def test_sides_in_series_reproduce_the_mechanism_roller_law():
    f = 1000.0
    w = f / P01.n_rollers
    r = axial_stiffness(P01, f)
    ld = thread_load_distribution(P01, w)
    assert r.roller_deflections[0] == pytest.approx(
        ld.screw_deflection + ld.nut_deflection, rel=1e-12
    )
    k_roller = 1 / (
        1 / roller_side_stiffness(P01, w, "screw") + 1 / roller_side_stiffness(P01, w, "nut")
    )
    k_total = 1 / (1 / (P01.n_rollers * k_roller) + 1 / shaft_stiffness(P01))
    assert r.tangent_stiffness == pytest.approx(k_total, rel=1e-9)


def test_power_law_fit():
    lo, hi = 100 / 7, 1000 / 7
    for side in SIDES:
        fit = roller_side_power_law(P01, side, (lo, hi))
        c, n, err = fit
        # Hertz alone: 1.5; linear teeth/bodies in series lower it (F = cδ^n with n < 1.5).
        assert 1.3 < n < 1.5
        assert err < 0.01
        w = np.geomspace(lo, hi, 7)
        defl = getattr(thread_load_distribution(P01, w), f"{side}_deflection")
        assert np.all(np.abs(c * defl**n / w - 1) <= err * (1 + 1e-9) + 1e-12)


def test_paper01_per_roller_side_stiffness_regression():
    # Regression values of this model (not paper numbers; nothing is tuned). The dynamics
    # notes estimate ≈ 7.9e7 N/m per roller per side for the paper's 590 Hz nut mode.
    expected = {
        (100 / 7, "screw"): 4.060e7,
        (100 / 7, "nut"): 4.522e7,
        (1000 / 7, "screw"): 8.370e7,
        (1000 / 7, "nut"): 9.374e7,
    }
    for (w, side), k in expected.items():
        assert roller_side_stiffness(P01, w, side) == pytest.approx(k, rel=1e-3)


# ============================================================================ errors
@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: axial_stiffness(P01, -1.0), "load"),
        (lambda: axial_stiffness(P01, [1.0, float("nan")]), "load"),
        (lambda: axial_stiffness(P01, 1.0, roller_gaps=[-1e-6] * 7), "roller_gaps"),
        (lambda: axial_stiffness(P01, 1.0, roller_gaps=[0.0] * 6), "roller_gaps"),
        (lambda: axial_stiffness(P01, 1.0, eccentricity=-1e-6), "eccentricity"),
        (lambda: axial_stiffness(P01, 1.0, combination="series"), "combination"),
        (lambda: roller_side_force(P01, 1e-6, "roller"), "side"),
        (lambda: roller_side_stiffness(P01, -5.0, "nut"), "roller_axial_load"),
        (lambda: roller_side_power_law(P01, "nut", (10.0, 1.0)), "load_range"),
        (lambda: thread_load_distribution(P01, 1.0, body_scale=-1.0), "body_scale"),
        (lambda: radial_to_axial_gap(P01, "x"), "radial_offset"),
    ],
)
def test_errors_name_the_field(call, field):
    with pytest.raises(ParameterError) as info:
        call()
    assert info.value.field == field


def test_newton_failure_is_a_convergence_error(monkeypatch):
    thread_load = importlib.import_module("prsm_health.physics.stiffness.thread_load")
    monkeypatch.setattr(thread_load, "_NEWTON_MAXITER", 0)
    with pytest.raises(
        ConvergenceError,
        match=r"thread load distribution: Newton .* roller load W = \[5, 2000\] N .*'paper01'",
    ):
        thread_load_distribution(P01, [5.0, 2000.0])


def test_common_approach_failure_is_a_convergence_error(monkeypatch):
    axial = importlib.import_module("prsm_health.physics.stiffness.axial")
    monkeypatch.setattr(axial, "_APPROACH_MAXITER", 0)
    with pytest.raises(ConvergenceError, match=r"common approach .* F = 1000 N with roller gaps"):
        axial_stiffness(P04, 1000.0, eccentricity=5e-6)


# ============================================================================ validation
def test_paper04_rows():
    rows = v04.rows()
    assert not [r for r in rows if r.verdict == NOT_REPRODUCED]
    reproduced = [r for r in rows if r.verdict == REPRODUCED]
    # Only the recomputed error column and the lead angle are reproducible.
    assert len(reproduced) == 8
    assert all("relative error" in r.quantity or "lead angle" in r.quantity for r in reproduced)
