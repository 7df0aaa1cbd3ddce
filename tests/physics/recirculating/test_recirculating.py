"""Recirculating PRSM (paper 03): design rules, kinematics with resets, reset contact force.

Reference values: paper 03 (docs/references.md) and docs/validation.md ("Paper 03 —
recirculating PRSM"). The ``paper03`` preset is the
reconstructed geometry (orbit radius 19.75 mm, d_s = 32, d_r = 7.5, d_n = 47 mm, 12 rollers,
1 mm single-start pitch, α = 90°); Table 1 is not printed.
"""

import importlib
import math
from types import SimpleNamespace

import numpy as np
import pytest

from prsm_health.actuator.design import preset, printed_eq14_limit, recirculating_roller_limit
from prsm_health.core.errors import ConvergenceError, ParameterError
from prsm_health.physics import recirculating as rc

W_S = 40 * math.pi  # §4.2: "a constant speed 40π rad/s"
RUN = 0.1  # §4.2: simulation time 0.1 s


@pytest.fixture(scope="module")
def design():
    return preset("paper03")


@pytest.fixture(scope="module")
def geometry(design):
    return rc.RecirculatingGeometry.for_design(design)


# ------------------------------------------------------------------ paper 03 numbers
def test_paper03_speeds(design):
    # 40π rad/s is the paper's input; Fig. 25 reads 125.66 (5 significant figures).
    assert W_S == pytest.approx(125.66, abs=0.005)
    # Eq. (29): one lead (1 mm) per screw turn → 20.00 mm/s, geometry-independent, exact.
    assert rc.nut_speed(design, W_S) == pytest.approx(20.00e-3, rel=1e-12)
    # Eqs. (25) + (27) force ω_r = −(d_s/2d_r)·ω_s for any concentric geometry (exact identity).
    assert rc.roller_speed(design, W_S) == pytest.approx(
        -design.screw_diameter / (2 * design.roller_diameter) * W_S, rel=1e-12
    )
    # Reconstructed geometry, printed to 2 decimals in the notes: ±0.005 rad/s.
    assert rc.carrier_speed(design, W_S) == pytest.approx(50.90, abs=0.005)
    assert rc.roller_speed(design, W_S) == pytest.approx(-268.08, abs=0.005)


def test_paper03_displacements_over_the_run(design):
    m = rc.motion(design, W_S, [0.0, RUN])
    # Eq. (28): the screw turns 4π in 0.1 s, the nut travels 2 leads = 2.000 mm (exact).
    assert m.screw_angle[-1] == pytest.approx(4 * math.pi, rel=1e-12)
    assert m.nut[-1] == pytest.approx(2.000e-3, rel=1e-12)
    # §4.2 "orbital angle 1.62π" is the carrier angle of eq. (30) after 4π of screw:
    # 4π·d_s/(2d_c) = 4π·32/79 = 1.62025π; the notes give 1.6203π (4 decimals → ±5e-5).
    assert m.carrier_angle[-1] / math.pi == pytest.approx(1.6203, abs=5e-5)
    assert m.carrier_angle[-1] == pytest.approx(4 * math.pi * 32 / 79, rel=1e-12)
    # Eqs. (31)–(33) for roller 7 (the paper's reference roller), reset once by 0.1 s:
    # L_r1 = 0.810 mm, L_r2 = 2.000 − 0.810 = 1.190 mm, L_r3 = L_r2 + 1 mm = 2.190 mm.
    assert m.roller_drift[-1] == pytest.approx(1e-3 * 1.6203 / 2, abs=5e-8)
    assert m.roller_threaded[-1] == pytest.approx(1.190e-3, abs=5e-7)
    assert m.roller[6, -1] == pytest.approx(2.190e-3, abs=5e-7)
    assert m.resets[6, -1] == 1.0


def test_paper03_rollers_reset_in_the_run(design):
    # §4.3: rollers 11 and 12 "have not entered into the nut threadless area" within 0.1 s,
    # rollers 1–10 have; roller 7 resets after half a carrier turn (paper "0.06–0.07 s").
    ev = rc.reset_events(design, W_S, RUN)
    assert sorted(ev.rollers.tolist()) == list(range(1, 11))
    t7 = ev.times[ev.rollers == 7][0]
    assert t7 == pytest.approx(math.pi / rc.carrier_speed(design, W_S), rel=1e-12)
    assert 0.06 <= t7 and t7 + ev.crossing_time <= 0.07


def test_eq14_limit_and_eq13(design):
    # Printed eq. (14): π·d_c·tan(45°)/p = π·39.5 = 124.09; N = 12 satisfies it.
    assert printed_eq14_limit(design) == pytest.approx(124.1, abs=0.05)
    # Eqs. (11)–(13) give half of it: β = 2π/limit14 exactly, β < φ/2 ⇔ N < limit14/2.
    beta = rc.orbital_angle(design)
    assert beta == pytest.approx(2 * math.pi / printed_eq14_limit(design), rel=1e-12)
    assert recirculating_roller_limit(design) == pytest.approx(math.pi / beta, rel=1e-12)
    assert rc.eq13_roller_limit(design) == pytest.approx(math.pi * 39.5 / 2, rel=1e-12)
    assert design.n_rollers < rc.eq13_roller_limit(design)


# ------------------------------------------------------------------ design equations
def test_threadless_area_closed_forms(design):
    ta = rc.threadless_area(design)
    a = design.addendum  # 0.25 mm
    # Eq. (5) with α/2 = 90° − β_contact equals the design's default profile radius r_r/cos β.
    assert ta.roller_arc_radius == pytest.approx(design.roller_thread_radius, rel=1e-12)
    # Eq. (7): both crests above their pitch circles, 2·addendum = 0.5 mm.
    assert ta.radial_lift == pytest.approx(2 * a, rel=1e-12)
    # Eq. (6): 19.75 + 0.5 mm; eq. (8) is the lifted roller's crest, R_r3 + d_r3/2 = 24.25 mm.
    assert ta.lift_radius == pytest.approx(20.25e-3, rel=1e-12)
    assert ta.radius == pytest.approx(ta.lift_radius + design.roller_major_diameter / 2)
    assert ta.radius == pytest.approx(24.25e-3, rel=1e-12)
    # The threadless recess must clear the nut thread root, else the roller would hit it.
    assert ta.radius > design.nut_root_diameter / 2
    # Eq. (9): 1 mm / tan 45° = 1 mm. Eq. (11) in degrees: 1·360/(π·39.5·1) = 2.9011°.
    assert ta.arc_de == pytest.approx(1e-3, rel=1e-12)
    assert ta.orbital_angle_deg == pytest.approx(360 / (math.pi * 39.5), rel=1e-12)
    assert ta.orbital_angle_over_pi == pytest.approx(2 / (39.5 * math.pi), rel=1e-12)
    assert ta.angle == pytest.approx(2 * ta.orbital_angle)
    assert ta.roller_spacing == pytest.approx(math.radians(30))
    assert ta.reset_stroke == design.pitch


def test_axial_offsets_follow_eqs_35_to_37(design, geometry):
    li = rc.roller_axial_offsets(design, geometry)
    m, s1, p = geometry.axial_offset, geometry.roller_half_length_1, design.pitch
    assert li[0] == pytest.approx(m + s1 + p)  # eq. (35)
    assert li[1] == pytest.approx(m + s1 + 11 / 12 * p)  # eq. (36)
    assert li[11] == pytest.approx(m + s1 + 1 / 12 * p)  # eq. (37), roller 12
    assert np.allclose(np.diff(li), -p / 12)


def test_default_geometry_meets_its_equations(design, geometry):
    g = geometry
    assert design.screw_major_diameter + design.roller_root_diameter < g.carrier_outer_diameter
    assert g.carrier_outer_diameter < design.nut_minor_diameter  # eq. (15)
    assert g.groove_end_radius == pytest.approx(design.roller_major_diameter / 2)  # eq. (18)
    assert g.groove_length == pytest.approx(2 * 4e-3 + 2 * 1e-3 + 2 * 5e-3)  # eq. (17), 20 mm
    assert g.platform_inner_diameter == g.carrier_outer_diameter  # eq. (20)
    assert g.platform_arc_angle == g.carrier_arc_angle  # eq. (22)
    assert rc.cam_ring_spacing(design, g) == pytest.approx(5e-3 + 5e-3 + 1e-3 / 12 + 1e-3)
    # Derived defaults follow an override.
    g2 = rc.RecirculatingGeometry.for_design(design, roller_half_length_1=6e-3)
    assert g2.groove_length == pytest.approx(g.groove_length + 1e-3)


@pytest.mark.parametrize(
    "field, value",
    [
        ("carrier_outer_diameter", 39e-3),  # eq. (15): below d_s3 + d_r1 = 39.375 mm
        ("carrier_outer_diameter", 46.6e-3),  # eq. (15): above d_n1 = 46.5 mm
        ("carrier_inner_diameter", 32.4e-3),  # eq. (16): not above d_s3 = 32.5 mm
        ("groove_length", 19e-3),  # eq. (17): shorter than 20 mm
        ("groove_end_radius", 3.9e-3),  # eq. (18): narrower than the roller crest radius
        ("cam_inner_diameter", 32e-3),  # eq. (19)
        ("platform_inner_diameter", 42e-3),  # eq. (20): smaller than D_B
        ("platform_outer_radius", 23.3e-3),  # eq. (21): beyond d_n1/2 = 23.25 mm
        ("platform_arc_angle", 0.3),  # eq. (22)
    ],
)
def test_geometry_violations_name_the_field(design, geometry, field, value):
    with pytest.raises(ParameterError) as err:
        rc.check_recirculating(design, geometry.with_(**{field: value}))
    assert err.value.field == f"geometry.{field}"
    # The same through the builder: the override is checked too.
    with pytest.raises(ParameterError, match=field):
        rc.RecirculatingGeometry.for_design(design, **{field: value})


def test_eq13_violation_names_n_rollers(design):
    # A 10 mm pitch passes the printed eq. (14) (12 < 12.41) but not eq. (13) (12 ≥ 6.2): the
    # design refuses it at construction, naming the field.
    with pytest.raises(ParameterError) as err:
        design.with_(pitch=10e-3, thread_addendum=0.25e-3)
    assert err.value.field == "design.n_rollers"
    assert "eqs. 11–14" in str(err.value)


def test_eq14_violation_is_refused_by_the_design(design):
    with pytest.raises(ParameterError) as err:
        design.with_(pitch=10e-3, thread_addendum=0.25e-3, n_rollers=13)
    assert err.value.field == "design.n_rollers"


def test_bad_inputs_name_the_field(design, geometry):
    with pytest.raises(ParameterError, match="geometry") as err:
        rc.RecirculatingGeometry.for_design(design, carrier_diameter=40e-3)
    assert err.value.value == "carrier_diameter"
    with pytest.raises(ParameterError, match="geometry"):
        geometry.with_(nonsense=1.0)
    with pytest.raises(ParameterError, match="geometry.cam_step_thickness"):
        geometry.with_(cam_step_thickness=-1e-3)
    with pytest.raises(ParameterError, match="design.variant"):
        rc.threadless_area(preset("paper01"))
    with pytest.raises(ParameterError, match="^duration"):
        rc.reset_events(design, W_S, -0.1)
    with pytest.raises(ParameterError, match="screw_speed"):
        rc.reset_events(design, math.nan, 0.1)
    with pytest.raises(ParameterError, match="^time"):
        rc.motion(design, W_S, [-0.1, 0.0])
    with pytest.raises(ParameterError, match="sample_rate"):
        rc.reset_force_series(design, geometry, W_S, 0.1, -1000.0)
    with pytest.raises(ParameterError, match="resisting_force"):
        rc.reset_pulse(design, W_S, resisting_force=-1.0)
    with pytest.raises(ParameterError, match="screw_speed"):
        rc.reset_pulse(design, 0.0)


# ------------------------------------------------------------------ reset events
@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("revolutions", [1, 3])
def test_n_events_per_carrier_revolution(design, sign, revolutions):
    w_c = abs(rc.carrier_speed(design, W_S))
    period = 2 * math.pi / w_c
    # A small start offset keeps every event away from the interval ends (floating point).
    ev = rc.reset_events(design, sign * W_S, revolutions * period, roller1_angle=-0.2)
    assert len(ev) == revolutions * design.n_rollers
    for roller in range(1, design.n_rollers + 1):
        assert np.count_nonzero(ev.rollers == roller) == revolutions
    # Equal spacing 2π/(N·ω_c), and the rate agrees with kinematics' N·f_c.
    assert np.allclose(np.diff(ev.times), period / design.n_rollers, rtol=1e-9)
    assert ev.rate == pytest.approx(design.n_rollers / period)
    assert ev.crossing_time == pytest.approx(rc.orbital_angle(design) / w_c)


def test_events_follow_the_roller_angles(design):
    # Forward: roller i enters (i − 1)φ of carrier travel after roller 1 (which starts at the
    # entrance). Reverse: the entrance is the other edge, 2β away, so roller N is first.
    w_c = rc.carrier_speed(design, W_S)
    phi, beta = rc.roller_spacing(design), rc.orbital_angle(design)
    fwd = rc.reset_events(design, W_S, 2 * math.pi / w_c)
    assert np.allclose(fwd.times, np.arange(12) * phi / w_c)
    rev = rc.reset_events(design, -W_S, 2 * math.pi / w_c)
    assert rev.rollers[0] == 12
    assert rev.times[0] == pytest.approx((phi - 2 * beta) / w_c, rel=1e-12)
    assert rc.reset_events(design, 0.0, 1.0).times.size == 0


def test_roller_relative_to_nut_is_periodic(design):
    # Drift −lead per carrier turn (eq. 31) and one +lead reset: the roller returns to the
    # same place in the nut every revolution (exactly, by construction of both terms).
    w_c = rc.carrier_speed(design, W_S)
    period = 2 * math.pi / w_c
    t = np.array([0.013, 0.013 + period, 0.013 + 2 * period])
    for sign in (1.0, -1.0):
        m = rc.motion(design, sign * W_S, t)
        rel = m.roller_relative_to_nut
        assert np.allclose(rel[:, 1:], rel[:, :1], rtol=0, atol=1e-15)
        assert np.allclose(np.diff(m.resets, axis=1), 1.0)
        # Relative to the screw every roller advances with the nut: one lead per screw turn.
        assert np.allclose(np.diff(m.roller, axis=1), np.diff(m.nut), rtol=1e-12)
        assert np.sign(m.nut[-1]) == sign


# ------------------------------------------------------------------ impact function (eq. 38)
def test_impact_force_properties():
    c = rc.PAPER03_CONTACT
    # ADAMS units converted: 1e5 N/mm^1.5 → 1e5·1000^1.5 N/m^1.5; 50 N·s/mm; 0.1 mm.
    assert c.stiffness == pytest.approx(1e5 * 1e3**1.5)
    assert c.max_damping == pytest.approx(5e4) and c.depth == pytest.approx(1e-4)
    # No penetration → no force, whatever the rate.
    assert rc.impact_force(0.0, 5.0) == 0.0
    assert rc.impact_force(-1e-5, 5.0) == 0.0
    # Exponent 1.5 at zero rate: F(2x)/F(x) = 2^1.5 (exact up to rounding).
    x = np.array([1e-6, 2e-6, 4e-5, 8e-5])
    f = rc.impact_force(x, np.zeros(4))
    assert f[1] / f[0] == pytest.approx(2**1.5, rel=1e-12)
    assert f[3] / f[2] == pytest.approx(2**1.5, rel=1e-12)
    assert f[0] == pytest.approx(c.stiffness * 1e-9, rel=1e-12)
    # Damping fully on at and beyond the penetration depth d.
    for depth in (c.depth, 2 * c.depth):
        diff = rc.impact_force(depth, 0.3) - rc.impact_force(depth, 0.0)
        assert diff == pytest.approx(c.max_damping * 0.3, rel=1e-12)
    # Half-way the cubic STEP is ½.
    half = rc.impact_force(c.depth / 2, 0.3) - rc.impact_force(c.depth / 2, 0.0)
    assert half == pytest.approx(0.5 * c.max_damping * 0.3, rel=1e-12)
    # Never pulls: a fast separation clamps to 0.
    assert rc.impact_force(1e-6, -10.0) == 0.0


def test_impact_force_is_continuous():
    c = rc.PAPER03_CONTACT
    # At first contact (x → 0⁺, any rate) and at x = d the change over 1e-12 m is bounded by
    # the slope K·e·x^(e−1) + C·|v|·6u(1−u)/d: ≤ 4.8e7 N/m at x = d (STEP is flat there),
    # i.e. < 1e-4 N; 1e-3 N would still catch any jump.
    eps = 1e-12
    for v in (0.0, 1.0, -1.0):
        assert rc.impact_force(eps, v) < 1e-3
        left, right = rc.impact_force(c.depth - eps, v), rc.impact_force(c.depth + eps, v)
        assert abs(right - left) < 1e-3
    # Dense sweep, steps of 1.05e-9 m at v = 0.5 m/s: the slope is at most
    # 1.5·K·√(2e-4) + 1.5·C·v/d = 6.7e7 + 3.75e8 N/m, so no step may change F by more than
    # 0.47 N; the smallest force jump worth calling a discontinuity here is far above 1 N.
    x = np.linspace(-1e-5, 2e-4, 200_001)
    f = rc.impact_force(x, np.full_like(x, 0.5))
    assert np.max(np.abs(np.diff(f))) < 0.5


# ------------------------------------------------------------------ reset pulse and series
def test_undamped_pulse_matches_hertz_impact(design):
    # Independent analytical limit: with C = 0 the axial 1-DOF problem m·z̈ = −k·z^1.5,
    # k = K·cos^2.5(α/2), is Hertz's impact: z_max = (5m·v0²/4k)^(2/5), peak axial force
    # k·z_max^1.5, elastic rebound (axial impulse 2m·v0). LSODA at rtol 1e-8: 1e-4 is ample.
    elastic = rc.ImpactContact(rc.PAPER03_CONTACT.stiffness, 1.5, 0.0, 1e-4)
    p = rc.reset_pulse(design, W_S, contact=elastic)
    m, v0, cg = design.masses.roller_mass, p.approach_speed, math.cos(p.chamfer_angle)
    k = elastic.stiffness * cg**2.5
    z_max = (5 * m * v0**2 / (4 * k)) ** 0.4
    assert p.penetration.max() / cg == pytest.approx(z_max, rel=1e-4)
    assert p.peak_force * cg == pytest.approx(k * z_max**1.5, rel=1e-4)
    assert p.axial_impulse == pytest.approx(2 * m * v0, rel=1e-4)
    # Approach speed = chamfer speed ω_c·r_c·tan(α/2) + the eq. (31) drift lead·ω_c/2π.
    w_c = rc.carrier_speed(design, W_S)
    assert v0 == pytest.approx(w_c * 39.5e-3 / 2 + 1e-3 * w_c / (2 * math.pi), rel=1e-12)


def test_damped_pulse_dissipates(design):
    p = rc.reset_pulse(design, W_S)
    m, v0 = design.masses.roller_mass, p.approach_speed
    # With damping the rebound is partial: m·v0 < axial impulse < 2m·v0 (restitution 0…1).
    assert m * v0 < p.axial_impulse < 2 * m * v0
    assert 0 < p.peak_force < 1e4
    assert p.crossing_time == pytest.approx(rc.orbital_angle(design) / 50.9017, rel=1e-5)


@pytest.mark.parametrize("sample_rate", [2_000.0, 51_200.0])
def test_force_series_has_one_pulse_per_reset(design, geometry, sample_rate):
    w_c = rc.carrier_speed(design, W_S)
    duration = 2 * 2 * math.pi / w_c  # two carrier turns
    # Roller 1 starts 0.02 rad before the entrance: the first pulse starts at 0.39 ms, the
    # last one 10 ms before the end, so every pulse lies wholly inside the run.
    start = -rc.orbital_angle(design) - 0.02
    s = rc.reset_force_series(design, geometry, W_S, duration, sample_rate, roller1_angle=start)
    assert len(s.events) == 2 * design.n_rollers
    assert s.time.size == math.floor(duration * sample_rate + 1e-9)
    dt = 1 / sample_rate
    # Momentum is conserved by the sampling: Σ F·Δt = events × pulse impulse.
    assert s.normal_force.sum() * dt == pytest.approx(len(s.events) * s.pulse.impulse[-1])
    # Force appears only near events; the axial force on the nut opposes the nut's travel.
    assert np.all(s.normal_force >= 0)
    assert np.allclose(s.axial_force, -s.normal_force * math.cos(math.pi / 4))
    near = np.zeros(s.time.size, bool)
    for t in s.events.times:
        near |= (s.time > t - dt) & (s.time < t + s.events.crossing_time + dt)
    assert not np.any(s.normal_force[~near])
    # Reversed: same count and impulse, axial force changes sign.
    r = rc.reset_force_series(design, None, -W_S, duration, sample_rate, roller1_angle=start)
    assert len(r.events) == len(s.events)
    assert r.normal_force.sum() == pytest.approx(s.normal_force.sum())
    assert np.all(r.axial_force >= 0)


def test_zero_speed_gives_zero_signal(design):
    s = rc.reset_force_series(design, None, 0.0, 0.01, 10_000.0)
    assert not np.any(s.normal_force) and s.pulse is None and s.peak_force == 0.0


# ------------------------------------------------------------------ package layout
def test_package_reexports_every_public_name():
    for sub in ("geometry", "travel", "impact"):
        module = importlib.import_module(f"prsm_health.physics.recirculating.{sub}")
        for name in dir(module):
            obj = getattr(module, name)
            if not name.startswith("_") and getattr(obj, "__module__", None) == module.__name__:
                assert getattr(rc, name) is obj, name
                assert name in rc.__all__, name
    assert (
        callable(rc.motion) and rc.motion.__module__ == "prsm_health.physics.recirculating.travel"
    )


def test_reset_pulse_failure_is_a_convergence_error(design, monkeypatch):
    impact = importlib.import_module("prsm_health.physics.recirculating.impact")
    monkeypatch.setattr(
        impact, "solve_ivp", lambda *a, **k: SimpleNamespace(success=False, message="stiff")
    )
    with pytest.raises(ConvergenceError, match=r"reset pulse.*screw_speed = 125\.664.*stiff"):
        rc.reset_pulse(design, W_S)
