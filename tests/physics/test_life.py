"""Unit and fleet lives (prsm_health.physics.life): determinism, the clearance and RUL bookkeeping, the
wear integral against an independent quadrature, lubricant ageing, the health state handed to
the dynamics, ISO 281 spall statistics, and [life] validation."""

import math

import numpy as np
import pytest
from scipy import stats

from prsm_health.actuator.design import preset
from prsm_health.core.errors import ParameterError
from prsm_health.physics.life import fleet_lives, unit_life
from prsm_health.physics.life_spec import FleetScatter, LifeSpec
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.lubrication import asperity_share, stribeck_curve
from prsm_health.physics.wear import (
    WEIBULL_SLOPE,
    PartGeometry,
    WearParameters,
    clearance_growth_rate,
    contact_states,
)

DESIGN = preset("paper01")
GEOMETRY = PartGeometry.of(DESIGN)
SPEC = LifeSpec(units=8)
#: The duty's loads are shares of the design's ratings; the independent recomputations below
#: work in newtons.
RATINGS = load_ratings(DESIGN)


@pytest.fixture(scope="module")
def fleet():
    return fleet_lives(DESIGN, SPEC, 11)


@pytest.fixture(scope="module")
def exact_fleet():
    # No usage wandering and no wear-coefficient scatter: each unit wears at its duty cycle's
    # rate exactly, which the test can recompute from the unit's drawn load scale and temperature
    spec = LifeSpec(units=4, scatter=FleetScatter(usage=0.0, wear_coefficient=0.0))
    return spec, fleet_lives(DESIGN, spec, 5)


# Low reference pressure: L10 of the flanks ≈ 15 h against a wear life of ≈ 2000 h, so every unit
# spalls long before it wears out. One load scale: every unit has the same fatigue damage rates.
SPALL_SPEC = LifeSpec(
    units=300,
    wear=WearParameters(fatigue_pressure=1.5e9),
    scatter=FleetScatter(load_scale=(1.0, 1.0)),
)


@pytest.fixture(scope="module")
def spall_fleet():
    return fleet_lives(DESIGN, SPALL_SPEC, 7)


def _same(a, b):
    assert a.failure_age == b.failure_age and a.failure_mode == b.failure_mode
    assert a.spall_age == b.spall_age or (math.isinf(a.spall_age) and math.isinf(b.spall_age))
    assert np.array_equal(a.worn_screw, b.worn_screw) and np.array_equal(a.worn_nut, b.worn_nut)
    assert (a.seed, a.initial_clearance, a.lubricant_life) == (
        b.seed,
        b.initial_clearance,
        b.lubricant_life,
    )


def test_fleet_is_deterministic_in_its_seed(fleet):
    again = fleet_lives(DESIGN, SPEC, 11)
    for a, b in zip(fleet, again):
        _same(a, b)
    # one unit alone is the fleet's unit
    _same(unit_life(DESIGN, SPEC, 3, 11), fleet[3])
    other = fleet_lives(DESIGN, SPEC, 12)
    assert all(a.failure_age != b.failure_age for a, b in zip(fleet, other))
    assert all(a.seed != b.seed for a, b in zip(fleet, other))
    # units of one fleet differ from one another
    assert len({u.failure_age for u in fleet}) == len(fleet)


def test_clearance_and_rul_bookkeeping(fleet):
    for unit in fleet:
        assert unit.failure_mode == "wear" and math.isinf(unit.spall_age)
        ages = np.linspace(0.0, unit.failure_age, 500)
        screw, nut = unit.clearances(ages)
        assert np.all(np.diff(screw) >= 0) and np.all(np.diff(nut) >= 0)
        assert screw[0] == nut[0] == unit.initial_clearance
        # the crossing is interpolated linearly between two grid ages, as clearance() is: equal
        # up to rounding of ~30 µm (1e-12 m is ~1e4 ulps of margin)
        assert abs(float(unit.clearance(unit.failure_age)) - unit.failure_clearance) < 1e-12
        assert np.all(unit.clearance(ages[:-1]) < unit.failure_clearance)
        assert np.array_equal(unit.rul(ages), unit.failure_age - ages)
        snaps = unit.snapshot_ages(7)
        assert len(snaps) == 7 and snaps[0] == 0.0
        assert np.all(np.diff(snaps) > 0) and snaps[-1] < unit.failure_age


def _mean_wear_rate(spec, unit, degradation):
    """(ḃ_screw + ḃ_nut)/2 [m/h] of the unit's duty cycle at lubricant degradation d, from the
    wear laws (prsm_health.physics.wear, tested on their own) and the Stribeck film."""
    duty, total = spec.duty.resolved(RATINGS), np.zeros_like(degradation)
    for load, share in zip(duty.loads, duty.shares):
        load *= unit.load_scale
        seconds_per_hour = share * duty.motion_fraction * 3600.0
        for side, contact in contact_states(DESIGN, GEOMETRY, load, duty.speed).items():
            film = stribeck_curve(
                DESIGN,
                spec.lubricant,
                [contact.entrainment_speed],
                axial_load=load,
                temperature=unit.temperature,
                degradation=degradation,
            )
            total += (
                0.5
                * seconds_per_hour
                * clearance_growth_rate(
                    GEOMETRY,
                    contact,
                    side,
                    stroke=duty.stroke,
                    asperity_share=asperity_share(film.film_ratio),
                    coefficient=spec.wear.coefficient(degradation),
                )
            )
    return total


def test_failure_age_without_usage_scatter_is_the_closed_form(exact_fleet):
    # Independent: the wear b(t) − b₀ = T·∫₀^{t/T} ḃ(d) dd on a 20001-point degradation grid
    # (trapezoid, relative error ~1e-9), then linear once the lubricant is spent. The module
    # interpolates ḃ linearly on a 101-point grid; ḃ ∝ k ∝ 10^d, whose chord overestimates the
    # integral by at most h²(ln 10)²/8 = 6.6e-5 relatively (h = 0.01), and since ḃ grows with
    # age, wear W(F) ≤ F·ḃ(F), so the failure age moves by at most as much. The age grid's
    # midpoint sums and linear crossing are second order in its step (Δt/F = 2e-3): ~1e-6.
    # Hence 1e-4.
    spec, lives = exact_fleet
    d = np.linspace(0.0, 1.0, 20001)
    for unit in lives:
        rate = _mean_wear_rate(spec, unit, d)
        worn = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(d))])
        worn *= unit.lubricant_life
        needed = spec.failure_clearance - unit.initial_clearance - unit.assembly_play
        if needed <= worn[-1]:
            expected = float(np.interp(needed, worn, d)) * unit.lubricant_life
        else:
            expected = unit.lubricant_life + (needed - worn[-1]) / rate[-1]
        assert unit.failure_age == pytest.approx(expected, rel=1e-4)
        # and the whole history, not only its end: wear at half life
        half = 0.5 * unit.failure_age
        t = np.linspace(0.0, half, 20001)
        r = np.interp(np.minimum(t / unit.lubricant_life, 1.0), d, rate)
        worn_half = float(np.sum(0.5 * (r[1:] + r[:-1]) * np.diff(t)))
        assert float(unit.thread_clearance(half)) - unit.initial_clearance == pytest.approx(
            worn_half, rel=1e-4
        )


def test_wear_accelerates_as_the_additives_deplete(exact_fleet):
    # ḃ ∝ k_0·(k_dry/k_0)^d·f_c(Λ(d)), and the film only thins as the lubricant degrades, so
    # the wear rate over the last tenth of life exceeds that over the first by at least the
    # coefficient's growth between them, (k_dry/k_0)^(0.8·d(F)).
    spec, lives = exact_fleet
    for unit in lives:
        f = unit.failure_age
        first = float(unit.clearance(0.1 * f) - unit.clearance(0.0)) / (0.1 * f)
        last = float(unit.clearance(f) - unit.clearance(0.9 * f)) / (0.1 * f)
        d_end = min(f / unit.lubricant_life, 1.0)
        assert last / first > spec.wear.depleted_wear_ratio ** (0.8 * d_end) > 1.2
    # without depletion the acceleration is only the film's: much less
    flat = LifeSpec(
        units=4,
        scatter=FleetScatter(usage=0.0, wear_coefficient=0.0),
        wear=WearParameters(depleted_wear_ratio=1.0),
    )
    for unit, base in zip(fleet_lives(DESIGN, flat, 5), lives):
        f = unit.failure_age
        first = float(unit.clearance(0.1 * f) - unit.clearance(0.0))
        last = float(unit.clearance(f) - unit.clearance(0.9 * f))
        g = base.failure_age
        base_ratio = float(base.clearance(g) - base.clearance(0.9 * g)) / float(
            base.clearance(0.1 * g) - base.clearance(0.0)
        )
        assert 1.0 <= last / first < base_ratio


def test_health_at_age(fleet, spall_fleet):
    for unit in fleet[:3] + spall_fleet[:3]:
        for age in (0.0, 0.37 * unit.failure_age, 0.99 * unit.failure_age):
            h = unit.health_at(age)
            screw, nut = unit.clearances(age)
            assert (h.clearance_screw, h.clearance_nut) == (float(screw), float(nut))
            assert h.clearance_gear == unit.initial_clearance
            mean = 0.5 * (screw + nut)
            worn_share = (mean - unit.initial_clearance) / mean
            assert h.wear_spread == pytest.approx(unit.wear_spread * worn_share, rel=1e-12)
            assert h.lubricant_degradation == pytest.approx(
                min(age / unit.lubricant_life, 1.0), rel=1e-12
            )
            assert bool(h.faults) == (age >= unit.spall_age)
    assert fleet[0].health_at(0.0).wear_spread == 0.0
    # the spall appears at its initiation age, at its initial length
    unit = spall_fleet[0]
    assert not unit.health_at(unit.spall_age * (1 - 1e-9)).faults
    (spall,) = unit.health_at(unit.spall_age).faults
    assert spall.length == pytest.approx(SPALL_SPEC.wear.spall_initial_length, rel=1e-12)
    assert spall.depth == SPALL_SPEC.wear.spall_depth


def _system_l10_hours():
    """ISO 281 system life of the flanks [h] from the per-surface damage rates, counted here:
    cycles per second at the most-cycled point (screw: n_R contacts on 2πr_s for the share of a
    stroke under the rollers; roller: one on 2πr_r; nut: n_R on 2πr_n), L10 = N_ref·(p_ref/p₀)⁹
    (the roller's flanks at the higher of its two contact pressures), combined as Σ D_i^e."""
    duty, wear = SPALL_SPEC.duty.resolved(RATINGS), SPALL_SPEC.wear
    r_s, r_r, r_n = (
        d / 2 for d in (DESIGN.screw_diameter, DESIGN.roller_diameter, DESIGN.nut_diameter)
    )
    nut_length = DESIGN.engaged_threads * DESIGN.pitch
    under = nut_length / (nut_length + duty.stroke)
    damage = np.zeros(3)  # screw, roller, nut: L10 lives per operating hour
    for load, share in zip(duty.loads, duty.shares):
        c = contact_states(DESIGN, GEOMETRY, load, duty.speed)
        u = c["screw"].entrainment_speed
        per_second = np.array(
            [
                DESIGN.n_rollers * u / (2 * math.pi * r_s) * under,
                u / (2 * math.pi * r_r),
                DESIGN.n_rollers * u / (2 * math.pi * r_n),
            ]
        )
        p_s, p_n = c["screw"].max_pressure, c["nut"].max_pressure
        pressure = np.array([p_s, max(p_s, p_n), p_n])
        l10 = wear.fatigue_cycles * (wear.fatigue_pressure / pressure) ** 9
        damage += share * duty.motion_fraction * 3600.0 * per_second / l10
    return float(np.sum(damage**WEIBULL_SLOPE) ** (-1 / WEIBULL_SLOPE))


def test_spall_initiation_follows_the_iso281_weibull(spall_fleet):
    l10 = _system_l10_hours()
    ages = np.array([u.spall_age for u in spall_fleet])
    assert np.all(np.isfinite(ages))
    # 10 % of the units spall before the system L10: binomial sd √(0.1·0.9/300) = 0.017; 4 sd
    share = np.mean(ages < l10)
    assert abs(share - 0.1) < 4 * math.sqrt(0.09 / len(ages))
    # the whole distribution: two-parameter Weibull, slope e = 10/9, scale L10/(−ln 0.9)^(1/e)
    # (S(L10) = 0.9), both fixed in advance, so the KS test's p-value is exact (false alarm 1e-3)
    scale = l10 / (-math.log(0.9)) ** (1 / WEIBULL_SLOPE)
    ks = stats.kstest(ages, stats.weibull_min(WEIBULL_SLOPE, scale=scale).cdf)
    assert ks.pvalue > 1e-3, ks
    # a scale off by half is rejected: the test can fail
    wrong = stats.kstest(ages, stats.weibull_min(WEIBULL_SLOPE, scale=1.5 * scale).cdf)
    assert wrong.pvalue < 1e-3


def test_spalled_units_fail_by_the_spall(spall_fleet):
    spec = SPALL_SPEC
    for unit in spall_fleet:
        assert unit.failure_mode == "spall" and unit.spall is not None
        assert unit.spall_age < unit.failure_age
        assert float(unit.spall_length(unit.failure_age)) == pytest.approx(
            spec.failure_spall_length, rel=1e-9
        )
        # long before wear would have failed it: under a quarter of the wear it fails by
        worn = float(unit.clearance(unit.failure_age)) - unit.initial_clearance
        assert worn < 0.25 * (spec.failure_clearance - unit.initial_clearance)
    # spalls land on every surface (the roller's, at the higher pressure and most cycles, most)
    locations = [u.spall.location for u in spall_fleet]
    assert set(locations) == {"screw", "roller", "nut"}


@pytest.mark.parametrize(
    "table, field",
    [
        ({"colour": "red"}, "life.colour"),
        ({"duty": {"loads": [100.0, 200.0], "shares": [0.5, 0.6]}}, "life.duty.shares"),
        ({"duty": {"loads": [100.0, 200.0], "shares": [1.0]}}, "life.duty.shares"),
        ({"duty": {"rpm": 3}}, "life.duty.rpm"),
        ({"failure_clearance": 5e-6}, "life.failure_clearance"),  # below initial up to 8 µm
        ({"units": 0}, "life.units"),
        ({"snapshots": 2.5}, "life.snapshots"),
        ({"scatter": {"usage": -0.1}}, "life.scatter.usage"),
        ({"scatter": {"initial_clearance": [8e-6, 3e-6]}}, "life.scatter.initial_clearance"),
        ({"wear": {"fatigue_pressure": 1e11}}, "wear.fatigue_pressure"),
        ({"wear": {"pitting": 1}}, "life.wear.pitting"),
        ({"duty": 3}, "life.duty"),
        ({"duty": {"loads": ["20 % C_x"], "shares": [1.0]}}, "life.duty.loads"),
        ({"duty": {"loads": ["4 lbf"], "shares": [1.0]}}, "life.duty.loads"),
        ({"duty": {"loads": "20 % C_a", "shares": [1.0]}}, "life.duty.loads"),
    ],
)
def test_bad_life_tables_name_the_field(table, field):
    with pytest.raises(ParameterError) as err:
        LifeSpec.from_dict(table)
    assert err.value.field == field


def test_life_table_must_be_a_table():
    with pytest.raises(ParameterError) as err:
        LifeSpec.from_dict(["units", 3])
    assert err.value.field == "life"


def test_a_unit_that_outlives_max_age_is_refused():
    spec = LifeSpec.from_dict({"units": 1, "max_age": 100.0})  # wear life ≈ 2000 h
    with pytest.raises(ParameterError) as err:
        unit_life(DESIGN, spec, 0, 1)
    assert err.value.field == "life.max_age"


# ---------------------------------------------------------------------- loads as rating shares
def test_duty_loads_take_every_written_form_and_resolve_against_the_ratings():
    duty = LifeSpec.from_dict(
        {"duty": {"loads": [1500, "2.5 kN", "20 % C_a", "0.1 C_0a"], "shares": [0.25] * 4}}
    ).duty
    assert not duty.is_resolved and duty.loads[:2] == (1500.0, 2500.0)
    resolved = duty.resolved({"C_a": 10e3, "C_0a": 20e3})
    assert resolved.is_resolved and resolved.loads == (1500.0, 2500.0, 2000.0, 2000.0)
    # the LoadRatings of a design do as well as the dict
    by_design = duty.resolved(RATINGS).loads
    assert by_design[2] == pytest.approx(0.2 * RATINGS.dynamic, rel=1e-12)
    assert duty.as_dict()["loads"] == [1500.0, 2500.0, "20 % C_a", "10 % C_0a"]


def test_a_duty_load_above_the_static_rating_is_refused():
    spec = LifeSpec.from_dict({"units": 1, "duty": {"loads": ["120 % C_0a"], "shares": [1.0]}})
    with pytest.raises(ParameterError, match="C_0a") as err:
        unit_life(DESIGN, spec, 0, 1)
    assert err.value.field == "life.duty.loads"


def test_a_fleet_in_newtons_equals_the_fleet_in_shares():
    # The default duty written in newtons of paper01's rating gives the same lives, bit for bit
    # up to the rounding of the shares' products.
    shares = LifeSpec(units=2)
    newtons = LifeSpec(units=2, duty=shares.duty.resolved(RATINGS))
    a, b = fleet_lives(DESIGN, shares, 4), fleet_lives(DESIGN, newtons, 4)
    assert [u.failure_age for u in a] == pytest.approx([u.failure_age for u in b], rel=1e-12)


def test_the_life_duty_is_the_duty_the_fleet_records():
    # datasets/fleet.toml records each snapshot under a reversing load (mean and swing drawn
    # uniformly, trapezoidal wave: half the time at |F + A|, half at |F − A|); its [life.duty] is
    # meant to be that |load| distribution in three levels. Compare what wear and fatigue see:
    # the mean load (Archard wear ∝ load) and the cubic mean (ISO 281 life ∝ load⁻³), from 200k
    # draws (sampling error < 0.3 %); 5 % allows for the three-level rounding.
    from pathlib import Path

    from prsm_health.datasets import load_recipe

    recipe = load_recipe(Path(__file__).resolve().parents[2] / "datasets" / "fleet.toml")
    duty = recipe.life_spec.duty.resolved(recipe.ratings)
    assert duty == LifeSpec().duty.resolved(recipe.ratings)  # the library's default duty too
    rng = np.random.default_rng(0)
    mean = rng.uniform(*recipe.resolved_sweep["load"], 200_000)
    swing = rng.uniform(*recipe.resolved_sweep["load_amplitude"], 200_000)
    recorded = np.abs(np.concatenate([mean + swing, mean - swing]))
    loads, shares = np.array(duty.loads), np.array(duty.shares)
    assert shares @ loads == pytest.approx(recorded.mean(), rel=0.05)
    assert (shares @ loads**3) ** (1 / 3) == pytest.approx(
        np.mean(recorded**3) ** (1 / 3), rel=0.05
    )


def test_a_duty_change_wears_faster_from_its_age_on():
    from dataclasses import replace

    from prsm_health.physics.life import _changed_spall_age

    spec = LifeSpec(units=2)
    doubled = replace(spec, duty=replace(spec.duty, change_age=500.0, change_load=2.0))
    for unit in range(2):
        base, changed = unit_life(DESIGN, spec, unit, 5), unit_life(DESIGN, doubled, unit, 5)
        # the same unit and usage draws: identical until the change, faster after it
        assert float(changed.clearance(400.0)) == float(base.clearance(400.0))
        assert float(changed.clearance(900.0)) > float(base.clearance(900.0))
        assert changed.failure_age < base.failure_age
        assert changed.labels(600.0)["duty_load"] == pytest.approx(2 * base.load_scale)
        assert changed.labels(400.0)["duty_load"] == pytest.approx(base.load_scale)
    # the piecewise fatigue hazard reduces to ISO 281's closed form when nothing changes
    rates = {"screw": 2e-4, "roller": 1e-4, "nut": 5e-5}
    closed = (math.log(0.3) / math.log(0.9)) ** (1 / WEIBULL_SLOPE) / sum(
        v**WEIBULL_SLOPE for v in rates.values()
    ) ** (1 / WEIBULL_SLOPE)
    assert _changed_spall_age(rates, rates, 100.0, 0.3) == pytest.approx(closed, rel=1e-9)
    with pytest.raises(ParameterError, match="life.duty.change_load"):
        LifeSpec.from_dict({"duty": {"change_age": 10.0, "change_load": 50.0}})
