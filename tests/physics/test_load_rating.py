"""Basic load ratings C_a, C_0a of a PRSM against independent recomputation and ISO scaling."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from prsm_health.actuator.design import PRESETS, preset
from prsm_health.apps.cli import main
from prsm_health.core.errors import ParameterError
from prsm_health.physics.load_rating import STATIC_CONTACT_PRESSURE, load_ratings
from prsm_health.physics.stiffness.thread_geometry import thread_contacts
from prsm_health.physics.stiffness.thread_load import thread_load_distribution


def _hertz_pressure(a_coef, b_coef, e_star, q):
    """p0 of a Hertz point contact from Johnson (1985) eqs. (3.64)-(3.69), written anew."""
    ratio = b_coef / a_coef

    def eq(m):
        k, e = ellipk(m), ellipe(m)
        return (e / (1 - m) - k) / (k - e) - ratio

    m = brentq(eq, 1e-10, 1 - 1e-14, xtol=1e-15) if ratio > 1 + 1e-9 else 0.0
    k, e = ellipk(m), ellipe(m)
    a = (3 * q * (k - e) / (2 * math.pi * e_star * m * a_coef)) ** (1 / 3)
    b = a * math.sqrt(1 - m)
    return 3 * q / (2 * math.pi * a * b)


def test_static_rating_reaches_iso76_pressure_at_most_loaded_contact():
    design = preset("paper01")
    ratings = load_ratings(design)
    beta = design.contact_angle
    for side, contact, lam in zip(
        ("screw", "nut"),
        thread_contacts(design),
        (design.screw_lead_angle, design.nut_lead_angle),
    ):
        f = ratings.per_side[side].static
        dist = thread_load_distribution(design, f / design.n_rollers)
        q = float(np.max(getattr(dist, side))) / (math.sin(beta) * math.cos(lam))
        p0 = _hertz_pressure(contact.a_coef, contact.b_coef, contact.contact_modulus, q)
        # brentq solves to 1e-13 in log W and both Hertz solutions are exact: 1e-8 is
        # rounding of the elliptic integrals, far below any modelling question.
        assert p0 == pytest.approx(STATIC_CONTACT_PRESSURE, rel=1e-8)
    assert ratings.static == min(s.static for s in ratings.per_side.values())


def test_static_rating_uniform_value_is_closed_form():
    design = preset("paper04")
    side = load_ratings(design).per_side["screw"]
    contact = thread_contacts(design)[0]
    p1 = _hertz_pressure(contact.a_coef, contact.b_coef, contact.contact_modulus, 1.0)
    q_lim = (STATIC_CONTACT_PRESSURE / p1) ** 3  # p0 ∝ Q^(1/3)
    axial = math.sin(design.contact_angle) * math.cos(design.screw_lead_angle)
    expected = design.n_rollers * design.engaged_threads * axial * q_lim
    assert side.static_uniform == pytest.approx(expected, rel=1e-8)  # exact closed form
    # Uneven thread sharing lowers the rating by the loaded-end thread's share exactly.
    assert side.static == pytest.approx(
        side.static_uniform / (design.engaged_threads * side.peak_share), rel=1e-8
    )
    assert side.static < side.static_uniform


def test_dynamic_rating_roller_count_exponent_two_thirds():
    # ISO 281 eq. (9): C ∝ Z^(2/3). Changing only n_rollers leaves the contact geometry and
    # the carrier ratio unchanged, so the per-side ratings scale exactly by (Z2/Z1)^(2/3).
    base = preset("paper05")  # 10 rollers
    fewer = base.with_(n_rollers=8)
    r0, r1 = load_ratings(base), load_ratings(fewer)
    for side in ("screw", "nut"):
        ratio = r1.per_side[side].dynamic / r0.per_side[side].dynamic
        assert ratio == pytest.approx((8 / 10) ** (2 / 3), rel=1e-9)
    assert r1.dynamic / r0.dynamic == pytest.approx((8 / 10) ** (2 / 3), rel=1e-9)


def test_dynamic_rating_rows_exponent_and_size_scaling():
    base = preset("paper04")
    r0 = load_ratings(base)
    # Rows: C ∝ i^0.7 (ISO 281 multi-row rule with equal rows); the Hertz geometry does not
    # depend on the engaged thread count.
    more = load_ratings(base.with_(engaged_threads=20))
    assert more.dynamic / r0.dynamic == pytest.approx(2**0.7, rel=1e-9)
    # Size: a geometrically similar design s times larger has p0(1 N) ∝ s^(-2/3), the same
    # cycles per revolution, so C ∝ s² (the law without LP's volume term, module docstring).
    s = 2.0
    lengths = {
        k: getattr(base, k) * s
        for k in (
            "screw_diameter",
            "roller_diameter",
            "nut_diameter",
            "pitch",
            "nut_outer_diameter",
            "screw_free_length",
        )
    }
    try:
        big = base.with_(
            **lengths,
            gear=replace(
                base.gear, module=base.gear.module * s, face_width=base.gear.face_width * s
            ),
        )
    except ParameterError as err:  # pragma: no cover - a preset that cannot scale
        pytest.skip(str(err))
    assert load_ratings(big).dynamic / r0.dynamic == pytest.approx(s**2, rel=1e-9)
    assert load_ratings(big).static / r0.static == pytest.approx(s**2, rel=1e-6)


def test_ratings_monotonic_and_consistent():
    for name in PRESETS:
        r = load_ratings(preset(name))
        assert 0 < r.dynamic <= min(s.dynamic for s in r.per_side.values())
        assert r.static > 0
        for side in r.per_side.values():
            assert side.static <= side.static_uniform * (1 + 1e-12)
            assert 1 / preset(name).engaged_threads <= side.peak_share * (1 + 1e-9) <= 1
            # At C the contact pressure lies below the static limit for every preset.
            assert side.pressure_at_dynamic < STATIC_CONTACT_PRESSURE
    # A higher static pressure limit gives a higher static rating, as p_lim³.
    d = preset("paper02")
    lo, hi = load_ratings(d), load_ratings(d, static_pressure=4.0e9)
    assert hi.static < lo.static
    assert hi.per_side["nut"].static_uniform / lo.per_side["nut"].static_uniform == (
        pytest.approx((4.0 / 4.2) ** 3, rel=1e-9)
    )


@pytest.mark.parametrize(
    "kwargs",
    [
        {"design": "paper01"},
        {"design": None},
        {"design": preset("paper01"), "static_pressure": 1e12},
        {"design": preset("paper01"), "fatigue": {"fatigue_pressure": 4e9}},
    ],
)
def test_bad_input_raises_parameter_error(kwargs):
    design = kwargs.pop("design")
    with pytest.raises(ParameterError):
        load_ratings(design, **kwargs)


def test_cli_prints_ratings(capsys):
    assert main(["design", "show", "paper01"]) == 0
    out = capsys.readouterr().out
    ratings = load_ratings(preset("paper01"))
    assert f"{ratings.dynamic / 1e3:.6g} kN" in out
    assert f"{ratings.static / 1e3:.6g} kN" in out
    assert main(["kinematics", "--design", "paper01", "--speed", "10", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["load_ratings"]["dynamic"] == pytest.approx(ratings.dynamic)
    assert data["load_ratings"]["static"] == pytest.approx(ratings.static)
