"""Lubrication as physics (issue 12, item 4): the Stribeck curve of the thread contacts, its
health states, paper 02's invariants with it, and the dynamics model reading it."""

import math

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, SimulationOptions, preset, simulate
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.core.errors import ParameterError
from prsm_health.physics.friction import (
    FrictionParameters,
    simulate_friction,
    steady_friction_torque,
)
from prsm_health.physics.lubrication import LUBRICANTS, asperity_share, stribeck_curve

DESIGN = preset("paper01")
SPEEDS = np.geomspace(1e-4, 10.0, 200)  # m/s


def curve(**kw):
    return stribeck_curve(DESIGN, "grease-vg-100", SPEEDS, axial_load=300.0, **kw)


def test_viscosity_passes_through_the_grade_and_falls_with_temperature():
    oil = LUBRICANTS["iso-vg-68"]
    assert oil.kinematic_viscosity(313.15) == pytest.approx(68e-6, rel=1e-9)
    assert oil.kinematic_viscosity(373.15) == pytest.approx(8.7e-6, rel=1e-9)
    nu = oil.kinematic_viscosity(np.linspace(273.15, 393.15, 13))
    assert np.all(np.diff(nu) < 0)


def test_film_grows_with_the_hamrock_dowson_exponent():
    c = curve()
    k = np.searchsorted(SPEEDS, [0.1, 1.0])
    exponent = math.log(c.film_thickness[k[1]] / c.film_thickness[k[0]]) / math.log(
        SPEEDS[k[1]] / SPEEDS[k[0]]
    )
    assert exponent == pytest.approx(0.68, abs=1e-9)


def test_greenwood_tripp_load_share():
    # f_c = F_5/2(Λ)/F_5/2(0). F_5/2(0) = 2^(3/4)·Γ(7/4)/√(2π) in closed form; F_5/2(Λ) against
    # the fit 4.4086e-5·(4 − Λ)^6.804 common in the mixed-lubrication literature, itself within
    # 12 % of the integral for Λ ≤ 2 (hence the tolerance); negligible past Λ = 3.
    f0 = 2**0.75 * math.gamma(1.75) / math.sqrt(2 * math.pi)
    for lam in (0.5, 1.0, 1.5, 2.0):
        fit = 4.4086e-5 * (4.0 - lam) ** 6.804
        assert f0 * asperity_share(lam) == pytest.approx(fit, rel=0.12)
    assert asperity_share(0.0) == pytest.approx(1.0)
    assert asperity_share(3.0) < 1e-3


def test_stribeck_shape():
    c = curve()
    oil = LUBRICANTS["grease-vg-100"]
    # boundary at creeping speed, monotone through the mixed regime, film friction once Λ > 3
    assert c.coefficient[0] == pytest.approx(oil.boundary_friction, abs=1e-3)
    assert np.all(np.diff(c.coefficient) <= 1e-12)
    assert np.all(c.coefficient[c.film_ratio > 3] < oil.film_friction * 1.01)
    mixed = (c.film_ratio > 0.3) & (c.film_ratio < 2)
    assert mixed.sum() > 10 and np.ptp(c.coefficient[mixed]) > 0.03


def test_hot_oil_degradation_and_starvation_raise_friction_in_the_mixed_regime():
    k = np.searchsorted(SPEEDS, 0.6)  # the paper-01 contacts at 100 rad/s
    base = curve().coefficient[k]
    assert curve(temperature=353.15).coefficient[k] > base + 0.01
    assert curve(degradation=0.5).coefficient[k] > base + 0.01
    assert curve(starvation=0.5).coefficient[k] > base + 0.01


PARAMS = FrictionParameters.from_design(DESIGN)


@pytest.mark.parametrize("degradation", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("speed", [1.0, 50.0])
def test_paper02_invariants_hold_with_the_lubrication_regime(degradation, speed):
    stribeck = stribeck_curve(
        DESIGN, "grease-vg-100", np.linspace(0, 2, 400), axial_load=1000, degradation=degradation
    )
    r = simulate_friction(PARAMS, 1000.0, speed, 0.02, stribeck=stribeck)
    assert r.peak_friction_torque >= r.steady_friction_torque
    assert r.min_efficiency <= r.overall_efficiency <= r.steady_efficiency <= 1.0


def test_efficiency_falls_with_degradation_and_starvation():
    def steady(**kw):
        stribeck = stribeck_curve(
            DESIGN, "grease-vg-100", np.linspace(0, 2, 400), axial_load=1000, **kw
        )
        return steady_friction_torque(PARAMS, 1000.0, 50.0, stribeck)

    degraded = [steady(degradation=d) for d in (0.0, 0.25, 0.5, 0.75, 1.0)]
    starved = [steady(starvation=s) for s in (0.0, 0.5, 0.9)]
    assert np.all(np.diff(degraded) > 0) and np.all(np.diff(starved) > 0)
    # and the start-up crosses the boundary regime: a peak above the steady torque
    stribeck = stribeck_curve(DESIGN, "grease-vg-100", np.linspace(0, 2, 400), axial_load=1000)
    r = simulate_friction(PARAMS, 1000.0, 50.0, 0.02, stribeck=stribeck)
    assert r.peak_friction_torque > 1.1 * r.steady_friction_torque


def test_dynamics_friction_torque_follows_the_regime():
    # Mean friction torque (truth) at 300 N, 30 and 300 rad/s. With the regime model it falls
    # as the film builds (seen 0.080 → 0.044 N·m); with a constant coefficient it does not
    # (0.098 → 0.098). Energy balance within 1 % with a degraded lubricant.
    def torque(speed, options=None, health=None):
        run = simulate(
            "paper01",
            health or HealthState(),
            OperatingProfile(duration=0.05, speed=speed, load=300.0),
            "ideal",
            1,
            options=options,
            drive_train=DriveTrain.direct(),  # 300 rad/s: beyond the sized motor's top speed
        )
        return float(np.mean(run.truth["friction_torque"])), run.energy

    (slow, _), (fast, _) = torque(30.0), torque(300.0)
    assert fast < 0.7 * slow, (slow, fast)
    constant = SimulationOptions(lubrication="constant")
    (slow_c, _), (fast_c, _) = torque(30.0, constant), torque(300.0, constant)
    assert fast_c == pytest.approx(slow_c, rel=0.1)
    (degraded, e) = torque(100.0, health=HealthState(lubricant_degradation=1.0))
    assert degraded > 2 * torque(100.0)[0]
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: SimulationOptions(lubrication="wet"), "options.lubrication"),
        (lambda: SimulationOptions(lubricant="olive-oil"), "options.lubricant"),
        (lambda: HealthState(lubricant_degradation=1.5), "health.lubricant_degradation"),
        (lambda: HealthState(lubricant_starvation=-0.1), "health.lubricant_starvation"),
        (lambda: OperatingProfile(temperature=40.0), "profile.temperature"),
    ],
)
def test_bad_lubrication_input_names_the_field(make, field):
    with pytest.raises(ParameterError, match=field):
        make()
