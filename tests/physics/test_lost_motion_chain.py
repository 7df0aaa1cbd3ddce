"""The compliance chain between the angle and the position sensor: each term as physics says, and
the chain against the simulator's slow reversal (the built-in check's, alone)."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.health_check import BUILT_IN, HealthCheck
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.core.errors import ParameterError
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.lost_motion_chain import (
    CLEARANCE_SLOPE,
    clearance_from_lost_motion,
    compliance_chain,
)
from prsm_health.signals.lost_motion import lost_motion_step
from prsm_health.simulation.instrumentation import load_instrumentation
from prsm_health.simulation.scenario import simulate
from prsm_health.simulation.sensors import channel_group_delay

DESIGN = preset("paper01")
LOAD = 0.25 * load_ratings(DESIGN).dynamic  # the check's ±25 % C_a
LEAD = speed_ratios(DESIGN).nut


def _chain(shape="constant", **changes):
    return compliance_chain(DESIGN, DriveTrain(**changes), LOAD, reversal_shape=shape)


def test_elastic_terms_scale_with_the_compliance():
    base = _chain()
    stiff = _chain(thrust_bearing_stiffness=3e8, coupling_stiffness=1e6, gear_stiffness=1e6)
    assert stiff.thrust_bearing == pytest.approx(base.thrust_bearing / 2, rel=1e-12)
    # 1/k_g + 1/k_c: 1/2.2e3 + 1/1.5e3 against 2/1e6
    ratio = (2e-6) / (1 / 2.2e3 + 1 / 1.5e3)
    assert stiff.gear_coupling_twist == pytest.approx(base.gear_coupling_twist * ratio, rel=1e-9)
    # the twist is the screw torque F·p/η on the torsion springs, seen through the lead p
    expected = 2 * LOAD * LEAD / 0.85 * (1 / 2.2e3 + 1 / 1.5e3) * LEAD
    assert base.gear_coupling_twist == pytest.approx(expected, rel=1e-12)


def test_plays_add_whole():
    base = _chain()
    played = _chain(thrust_bearing_play=5e-6)
    assert played.thrust_bearing_play - base.thrust_bearing_play == pytest.approx(10e-6, rel=1e-9)
    assert base.gear_backlash == pytest.approx(2 * DriveTrain().gear_backlash * LEAD, rel=1e-12)
    assert _chain(gear_backlash=0.0).gear_backlash == 0.0
    # a play is crossed whole whatever the load's shape; elastic terms read less in a cosine
    cos_played, cos_base = _chain("cosine", thrust_bearing_play=5e-6), _chain("cosine")
    assert cos_played.thrust_bearing_play - cos_base.thrust_bearing_play == pytest.approx(
        10e-6, rel=1e-9
    )
    assert cos_base.gear_backlash == base.gear_backlash
    assert cos_base.gear_coupling_twist == pytest.approx(
        base.gear_coupling_twist * 2 / math.pi, rel=1e-5
    )


def test_thread_term_is_hertzian_and_rigid_drive_has_none():
    # thread contacts soften less than linearly: doubling F less than doubles the deflection
    # (Hertz δ ∝ F^(2/3), the teeth linear), and the cosine reading sits between 2/π and 1
    one = compliance_chain(DESIGN, DriveTrain(), LOAD).thread_contacts
    two = compliance_chain(DESIGN, DriveTrain(), 2 * LOAD).thread_contacts
    assert 2 ** (2 / 3) < two / one < 2
    cosine = _chain("cosine").thread_contacts / one
    assert 2 / math.pi < cosine < 1
    rigid = compliance_chain(DESIGN, DriveTrain.paper01(), LOAD)
    assert rigid.total == rigid.thread_contacts > 0
    chain = _chain()
    assert chain.total == pytest.approx(sum(chain.terms.values()))


def test_sensor_lag_is_the_delay_difference_times_the_mean_speed():
    def lag(shape="cosine", speed=10.0, **delays):
        chain = compliance_chain(
            DESIGN,
            DriveTrain(),
            LOAD,
            reversal_shape=shape,
            speed_amplitude=speed,
            sensor_delays=delays,
        )
        return chain.sensor_lag

    tau = 3e-4
    # 2·τ·p·ω held at constant speed, 2/π of it read over a cosine reversal
    assert lag("constant", nut_position=tau) == pytest.approx(2 * tau * LEAD * 10.0, rel=1e-12)
    assert lag(nut_position=tau) == pytest.approx(2 * tau * LEAD * 10.0 * 2 / math.pi, rel=1e-4)
    assert lag(speed=20.0, nut_position=tau) == pytest.approx(2 * lag(nut_position=tau))
    assert lag(nut_position=2 * tau) == pytest.approx(2 * lag(nut_position=tau))
    # the angle's delay counts against the position's; a delay common to both cancels
    assert lag(screw_angle=tau) == pytest.approx(-lag(nut_position=tau))
    assert lag(nut_position=tau, screw_angle=tau) == pytest.approx(0.0, abs=1e-15)
    assert _chain("cosine").sensor_lag == 0.0
    with pytest.raises(ParameterError, match="speed_amplitude"):
        compliance_chain(DESIGN, DriveTrain(), LOAD, sensor_delays={"nut_position": tau})
    with pytest.raises(ParameterError, match="sensor_delays"):
        compliance_chain(
            DESIGN, DriveTrain(), LOAD, speed_amplitude=10.0, sensor_delays={"screw_speed": tau}
        )


def test_clearance_inverts_the_chain():
    chain = _chain("cosine")
    assert clearance_from_lost_motion(chain.total + CLEARANCE_SLOPE * 12e-6, chain) == (
        pytest.approx(12e-6)
    )
    with pytest.raises(ParameterError, match="lost_motion"):
        clearance_from_lost_motion(math.nan, chain)
    with pytest.raises(ParameterError, match="reversal_shape"):
        compliance_chain(DESIGN, DriveTrain(), LOAD, reversal_shape="square")


#: The built-in check's slow reversal alone (the phase the lost-motion step is read on).
REVERSAL = HealthCheck(
    "slow-reversal",
    tuple(p for p in BUILT_IN["health-check"].phases if p.name == "slow reversal"),
)


@functools.lru_cache(maxsize=4)
def _simulated_run(clearance: float, instrumentation: str = "ideal"):
    run = simulate(
        DESIGN, HealthState.uniform(clearance), OperatingProfile(check=REVERSAL), instrumentation
    )
    c = run.phases()["slow reversal"].channels
    step = lost_motion_step(c["nut_position"], c["screw_angle"], LEAD, np.sign(c["screw_speed"]))
    return step, 1.0 / run.scenario["integration_step"]


def _simulated_step(clearance: float, instrumentation: str = "ideal") -> float:
    return _simulated_run(clearance, instrumentation)[0]


def test_chain_predicts_the_simulated_reversal():
    """The built-in check's slow reversal alone, ideal sensors, default drive train: the chain
    read as the fitted step of a cosine reversal predicts the lost motion at b = 0, and the
    play adds 4b.

    Tolerance of the intercept, 3 µm: the chain takes the screw torque at the drive train's
    estimated efficiency 0.85, the simulator has its own friction (friction ×1.5 / ×0.7 moved
    the check's lost motion by +1.5 / −0.8 µm), and the kernel's thread law is a power law
    fitted to the distributed one over 0.1–3 × the operating load (a few % of the 13 µm thread
    term). Slope 4 ± 0.3: the simulated units read 3.80 with uneven wear (load shares)."""
    chain = _chain("cosine")
    at_zero, at_ten = _simulated_step(0.0), _simulated_step(10e-6)
    assert at_zero == pytest.approx(chain.total, abs=3e-6)
    slope = (at_ten - at_zero) / 10e-6
    assert slope == pytest.approx(CLEARANCE_SLOPE, abs=0.3)
    assert clearance_from_lost_motion(at_ten, chain) == pytest.approx(10e-6, abs=1e-6)


def test_sensor_lag_explains_the_flight_sensors():
    """The slow reversal at b = 0, same unit (seed 0), flight-ema against ideal sensors: the
    LVDT's 500 Hz demodulator delays the position 0.318 ms behind the resolver (no filter), and
    the chain's sensor term predicts the difference of the two readings.

    Tolerance 0.6 µm (≈ 10 % of the 6.45 µm term, 0.15 µm of b): seeds 0–4 read 6.21–6.31 µm;
    the rest is measured — the 0.318 ms as a pure delay reads +6.64 µm (the fit's polynomial and
    the nut's elastic motion), the speed estimate's 0.34 ms delay of the direction −0.12 µm,
    and the resolver's harmonics, quantisation and LVDT errors about −0.2 µm together."""
    ideal, rate = _simulated_run(0.0)
    flight = _simulated_step(0.0, "flight-ema")
    instrumentation = load_instrumentation("flight-ema")
    frequency = 1.0 / REVERSAL.phases[0].reversal_period
    delays = {
        c: channel_group_delay(instrumentation, c, frequency, rate)
        for c in ("nut_position", "screw_angle")
    }
    assert delays["nut_position"] == pytest.approx(1 / (2 * math.pi * 500.0), rel=1e-3)
    chain = compliance_chain(
        DESIGN,
        DriveTrain(),
        LOAD,
        reversal_shape="cosine",
        speed_amplitude=REVERSAL.phases[0].speed,
        sensor_delays=delays,
    )
    assert flight - ideal == pytest.approx(chain.sensor_lag, abs=0.6e-6)
