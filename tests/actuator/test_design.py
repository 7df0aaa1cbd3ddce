"""Design presets and validation at construction (papers 01–05; paper 03 eqs. 1–3, 14)."""

import dataclasses
import math

import pytest

from prsm_health.actuator.design import PRESETS, ParameterError, preset, recirculating_roller_limit


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_construct_and_are_concentric(name):
    d = preset(name)
    # Concentric condition, paper 03 eq. (1), exact for every shipped preset.
    assert d.nut_diameter == pytest.approx(d.screw_diameter + 2 * d.roller_diameter, rel=1e-12)
    assert d.screw_lead == pytest.approx(d.nut_lead)


def test_paper01_table_values():
    d = preset("paper01")
    assert d.screw_diameter == pytest.approx(19.5e-3)
    assert d.roller_diameter == pytest.approx(6.5e-3)
    assert d.n_rollers == 7 and d.screw_starts == 5 and d.pitch == pytest.approx(2e-3)
    assert d.gear.ring_teeth == 65 and d.gear.roller_teeth == 13
    assert d.gear.ring_pitch_diameter == pytest.approx(d.nut_diameter)
    assert d.masses.nut_mass == 20.0 and d.masses.roller_inertia == pytest.approx(0.077e-6)
    # Profile angle 90° → half-angle 45° from the axis → contact angle 45° from the radial plane.
    assert math.degrees(d.contact_angle) == pytest.approx(45.0)


def test_paper04_lead_angle_reading():
    # Base parameter "screw lead angle 1.74°" on d_s = 21 mm.
    assert math.degrees(preset("paper04").screw_lead_angle) == pytest.approx(1.74, abs=1e-3)


def test_designs_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        preset().n_rollers = 3


@pytest.mark.parametrize(
    "change, field",
    [
        ({"screw_diameter": -0.01}, "design.screw_diameter"),
        ({"pitch": 0.0}, "design.pitch"),
        ({"nut_diameter": 0.04}, "design.nut_diameter"),
        ({"nut_starts": 4}, "design.nut_starts"),
        ({"n_rollers": 1}, "design.n_rollers"),
        ({"n_rollers": 30}, "design.n_rollers"),
        ({"contact_angle": math.radians(89)}, "design.contact_angle"),
        ({"engaged_threads": 0}, "design.engaged_threads"),
        ({"nut_outer_diameter": 0.03}, "design.nut_outer_diameter"),
        ({"roller_starts": 0}, "design.roller_starts"),
    ],
)
def test_invalid_design_names_field(change, field):
    with pytest.raises(ParameterError) as info:
        preset("paper01").with_(**change)
    message = str(info.value)
    assert message.startswith(field)
    assert "must" in message  # the allowed range is stated


def test_concentric_tolerance_is_half_percent():
    d = preset("paper01")
    ok = d.screw_diameter + 2 * d.roller_diameter
    d.with_(nut_diameter=ok * 1.004)  # inside 0.5 %
    with pytest.raises(ParameterError, match="concentric"):
        d.with_(nut_diameter=ok * 1.006)


def test_negative_mass_refused():
    d = preset("paper01")
    with pytest.raises(ParameterError, match="masses.nut_mass"):
        d.with_(masses=dataclasses.replace(d.masses, nut_mass=-1.0))


def test_gear_ratio_must_match_thread_ratio():
    d = preset("paper01")
    with pytest.raises(ParameterError, match="ring_teeth / gear.roller_teeth"):
        d.with_(gear=dataclasses.replace(d.gear, roller_teeth=12))


def test_ring_gear_must_fit_the_nut():
    # The roller gear sits on the roller orbit d_c = d_s + d_r: the internal pair's centre
    # distance m·(z_ring − z_roller)/2 must be d_c/2 (paper01: 0.5 mm × (65 − 13) = 26 mm).
    d = preset("paper01")
    gap = d.gear.ring_teeth - d.gear.roller_teeth
    fits = d.orbit_diameter / gap
    d.with_(gear=dataclasses.replace(d.gear, module=fits * 1.004))  # within 0.5 %
    for module in (fits * 1.006, 2 * fits):
        with pytest.raises(
            ParameterError, match=r"gear\.module .*ring_teeth = 65.*roller_teeth = 13"
        ):
            d.with_(gear=dataclasses.replace(d.gear, module=module))


def test_recirculating_roller_limit():
    d = preset("paper03")
    # Paper 03 eqs. (11)–(13) with α = 90°, d_c = 39.5 mm, one 1 mm lead: N < π·39.5/2 = 62.0
    # (the printed eq. 14 omits the factor 2; docs/validation.md).
    assert recirculating_roller_limit(d) == pytest.approx(math.pi * 39.5 / 2, rel=1e-12)
    # A coarse 5 mm pitch lowers the limit to 12.4: 12 rollers fit, 13 do not — while the
    # rollers still fit geometrically on the orbit (thin crests keep the overlap check away).
    coarse = d.with_(pitch=5e-3, thread_addendum=0.25e-3)
    assert coarse.n_rollers == 12
    with pytest.raises(ParameterError, match="eqs. 11–14"):
        coarse.with_(n_rollers=13)


def test_recirculating_rollers_are_grooved_and_gearless():
    d = preset("paper03")
    with pytest.raises(ParameterError, match="roller_starts"):
        d.with_(roller_starts=1)
    with pytest.raises(ParameterError, match="gear"):
        d.with_(gear=preset("paper01").gear)


def test_unknown_preset():
    with pytest.raises(ParameterError, match="design = 'nope'"):
        preset("nope")
