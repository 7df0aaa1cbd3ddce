"""Wear and rolling-contact fatigue of the thread contacts (prsm_health.physics.wear): Archard wear of
a Hertz contact against an independent integration, its limits, and the ISO 281 life laws."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from prsm_health.actuator.design import preset
from prsm_health.core.errors import ParameterError
from prsm_health.physics.wear import (
    PartGeometry,
    WearParameters,
    clearance_growth_rate,
    contact_states,
    l10_cycles,
)

DESIGN = preset("paper01")
GEOMETRY = PartGeometry.of(DESIGN)
LOAD, SPEED, STROKE = 2000.0, 100.0, 0.05  # N, rad/s, m
K, F_C = 1e-17, 0.6  # m²/N, asperity share


def rate(contact, side, *, coefficient=K, share=F_C, stroke=STROKE):
    return clearance_growth_rate(
        GEOMETRY, contact, side, stroke=stroke, asperity_share=share, coefficient=coefficient
    )


def independent_rate(contact, side, *, coefficient=K, share=F_C, stroke=STROKE):
    """ḃ from first principles: Archard depth per pass of the track centre line, integrated
    numerically over the Hertz pressure, times the passes per second counted from the design."""
    p0, b = contact.max_pressure, contact.semi_minor
    pressure_integral, _ = quad(lambda x: p0 * math.sqrt(max(1.0 - (x / b) ** 2, 0.0)), -b, b)
    u = contact.entrainment_speed  # rolling speed over both surfaces (no gross slip along u)
    depth_per_pass = coefficient * share * contact.sliding_speed / u * pressure_integral
    n_r = DESIGN.n_rollers
    roller = u / (2 * math.pi * DESIGN.roller_diameter / 2)  # one contact per flank track
    if side == "screw":
        nut_length = DESIGN.engaged_threads * DESIGN.pitch
        under_nut = nut_length / (nut_length + stroke)  # share of a stroke under the rollers
        part = n_r * u / (2 * math.pi * DESIGN.screw_diameter / 2) * under_nut
    else:
        part = n_r * u / (2 * math.pi * DESIGN.nut_diameter / 2)
    normal_depth_rate = depth_per_pass * (part + roller)  # screw/nut track + roller track
    axial_play_rate = normal_depth_rate / math.sin(DESIGN.contact_angle)
    return 0.5 * axial_play_rate  # b is half the play


@pytest.fixture(scope="module")
def contacts():
    return contact_states(DESIGN, GEOMETRY, LOAD, SPEED)


@pytest.mark.parametrize("side", ["screw", "nut"])
@pytest.mark.parametrize("stroke", [0.0, STROKE])
def test_clearance_growth_rate_against_an_independent_integration(contacts, side, stroke):
    # quad integrates √(1 − x²/b²) to ~1e-10 relative (the end-point square-root singularity);
    # the rest is exact arithmetic, so 1e-6 leaves room only for rounding. The integral also
    # checks that the contact's p₀ is the Hertz 3Q/(2πab) the module's ¾·Q/a assumes.
    c = contacts[side]
    assert c.sliding_speed > 0 and c.entrainment_speed > 0
    expected = independent_rate(c, side, stroke=stroke)
    assert rate(c, side, stroke=stroke) == pytest.approx(expected, rel=1e-6)


def test_rolling_kinematics_of_the_contacts(contacts):
    # Pure rolling at both engagements (carrier speed r_s/(r_s + r_n) of the screw's for
    # r_n = r_s + 2 r_r): the contact moves at the same speed over screw and nut. Screw side
    # slides axially at the lead speed p_s·ω plus spin; the nut side only spins (paper 02). On
    # the track's centre line a point at x slides at |x|·ω_sp, ω_sp = (u/r_r)·sin β (Johnson
    # 1985 §8.4); weighted by the Hertz pressure along it that is 4b/(3π)·ω_sp.
    r_s, r_r, r_n = (
        d / 2 for d in (DESIGN.screw_diameter, DESIGN.roller_diameter, DESIGN.nut_diameter)
    )
    carrier = SPEED * r_s / (r_s + r_n)
    u = r_s * (SPEED - carrier)
    assert u == pytest.approx(r_n * carrier, rel=1e-12)
    sin_b = math.sin(DESIGN.contact_angle)
    lead_speed = DESIGN.screw_starts * DESIGN.pitch / (2 * math.pi) * SPEED
    for side, gross in (("screw", lead_speed), ("nut", 0.0)):
        c = contacts[side]
        assert c.entrainment_speed == pytest.approx(u, rel=1e-9)
        b = c.semi_minor
        # ∫p|x|dx/∫p dx over the centre line, in s = x/b (quad's absolute tolerance would
        # swamp an integral of order b² ≈ 1e-8 m²)
        weighted = 2 * b * quad(lambda s: s * math.sqrt(max(1 - s * s, 0.0)), 0, 1)[0]
        spin = weighted / (math.pi / 2) * u / r_r * sin_b
        assert c.sliding_speed == pytest.approx(gross + spin, rel=1e-9)


def test_no_wear_at_standstill():
    still = contact_states(DESIGN, GEOMETRY, LOAD, 0.0)
    for side, c in still.items():
        assert c.sliding_speed == 0.0
        assert rate(c, side) == 0.0


def test_rate_is_linear_in_the_wear_coefficient_and_the_asperity_share(contacts):
    for side, c in contacts.items():
        base = rate(c, side)
        assert base > 0
        assert rate(c, side, coefficient=3 * K) == pytest.approx(3 * base, rel=1e-12)
        assert rate(c, side, share=F_C / 4) == pytest.approx(base / 4, rel=1e-12)
        assert rate(c, side, share=0.0) == 0.0


def test_the_nut_side_wears_much_less_than_the_screw_side(contacts):
    # Paper 02: no gross sliding at the roller–nut contact, spin only, so its sliding speed is
    # the spin's (≈ 5 % of the screw side's lead-speed sliding for paper 01). The rate ratio is
    # that sliding ratio times Q/a and the track pass counts, each within tens of per cent of
    # the screw side's: well below 0.2.
    s, n = contacts["screw"], contacts["nut"]
    sliding = n.sliding_speed / s.sliding_speed
    assert sliding < 0.1
    others = independent_rate(n, "nut") / n.sliding_speed
    others /= independent_rate(s, "screw") / s.sliding_speed
    ratio = rate(n, "nut") / rate(s, "screw")
    assert ratio == pytest.approx(sliding * others, rel=1e-6)
    assert ratio < 0.2


def test_l10_falls_with_the_ninth_power_of_the_pressure():
    params = WearParameters()
    p = np.array([1.0e9, 1.7e9, 2.5e9])
    assert np.allclose(l10_cycles(params, 2 * p) / l10_cycles(params, p), 2.0**-9, rtol=1e-12)
    # at the reference pressure the life is the reference life, by definition
    assert float(l10_cycles(params, params.fatigue_pressure)) == pytest.approx(
        params.fatigue_cycles, rel=1e-12
    )


def test_doubling_the_load_divides_l10_by_eight():
    # ISO 281, point contact: L10 ∝ P⁻³, since the Hertz p₀ ∝ Q^⅓ and L10 ∝ p₀⁻⁹.
    params = WearParameters()
    single = contact_states(DESIGN, GEOMETRY, LOAD, SPEED)
    double = contact_states(DESIGN, GEOMETRY, 2 * LOAD, SPEED)
    for side in ("screw", "nut"):
        ratio = l10_cycles(params, double[side].max_pressure) / l10_cycles(
            params, single[side].max_pressure
        )
        assert float(ratio) == pytest.approx(2.0**-3, rel=1e-9)


@pytest.mark.parametrize(
    "field, value",
    [
        ("wear_coefficient", 1e-10),
        ("wear_coefficient", -1e-17),
        ("depleted_wear_ratio", 0.5),
        ("fatigue_pressure", 1e8),
        ("fatigue_cycles", 0.0),
        ("spall_initial_length", 1e-2),
        ("spall_depth", 0.0),
        ("spall_doubling", 100.0),
    ],
)
def test_bad_wear_parameters_name_the_field(field, value):
    with pytest.raises(ParameterError) as err:
        WearParameters(**{field: value})
    assert err.value.field == f"wear.{field}"


def test_unknown_wear_key_names_the_table():
    with pytest.raises(ParameterError) as err:
        WearParameters.from_dict({"wear_rate": 1.0})
    assert err.value.field == "life.wear.wear_rate"
