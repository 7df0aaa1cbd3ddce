"""The clearance gauge: its algebra on reversals made from the chain itself, and on simulated
reversals (the built-in check's two reversal phases alone, to keep the runs short)."""

import functools
import math

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.health_check import BUILT_IN, HealthCheck
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.core.errors import ParameterError
from prsm_health.diagnostics.clearance_gauge import (
    COMMISSIONED_SCALE,
    CONFORMAL_SCALE,
    STIFFNESS_FACTOR_RANGE,
    Commissioning,
    Gauge,
    gauge_for,
)
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.lost_motion_chain import CLEARANCE_SLOPE
from prsm_health.signals.check_indicators import ReversalStep, check_indicators
from prsm_health.simulation.scenario import Scenario, SimulationOptions

DESIGN = preset("paper01")
C_A = load_ratings(DESIGN).dynamic
SHARES = np.cos((np.arange(64) + 0.5) * (math.pi / 3) / 64)  # |cos φ| ≥ 0.5: settled samples


def reversal(load_share, lost_motion=0.0, name=None, torque=math.nan):
    return ReversalStep(
        name or f"{load_share:.0%}", load_share * C_A, 10.0, lost_motion, SHARES, torque
    )


def synthetic(gauge, b, k, constant_extra=0.0, shares=(0.25, 0.10)):
    """Reversals whose lost motion is the chain's: 4b + C + k·E(F)."""
    out = []
    for share in shares:
        chain = gauge.chain(reversal(share))
        lost = CLEARANCE_SLOPE * b + chain.constant + constant_extra + k * chain.elastic
        out.append(reversal(share, lost))
    return out


def test_two_loads_remove_the_stiffness_and_one_load_does_not():
    gauge = Gauge(DESIGN)
    for k in (0.9, 1.0, 1.3):
        two = gauge.read(synthetic(gauge, 12e-6, k))
        assert two.stiffness_factor == pytest.approx(k, rel=1e-9)
        nominal_offset = sum(o.nominal for o in gauge.offsets.values())
        assert two.estimate == pytest.approx(12e-6 - nominal_offset / 4, abs=1e-12)
        one = gauge.read(synthetic(gauge, 12e-6, k)[:1])
        elastic = gauge.chain(reversal(0.25)).elastic
        # through the nominal chain the stiffness error stays: (k − 1)·E/4 (the nominal
        # offsets' middles shift both alike)
        assert one.estimate - two.estimate == pytest.approx(
            (k - 1) * elastic / CLEARANCE_SLOPE, abs=1e-12
        )
        assert one.stiffness_factor is None and one.budget["stiffness"] > two.budget["stiffness"]


def test_commissioning_fixes_the_constant_offset():
    gauge = Gauge.nominal(DESIGN, instrumentation="flight-ema")
    play = 6e-6  # a bearing play the datasheets do not give
    at_build = gauge.read(synthetic(gauge, 4e-6, 1.1, play))
    commissioning = Commissioning.from_indicators([at_build.indicators()] * 2, 4e-6)
    assert commissioning.stiffness_factor == pytest.approx(1.1) and commissioning.checks == 2
    later = gauge.read(synthetic(gauge, 17e-6, 1.1, play), commissioning)
    assert later.estimate == pytest.approx(17e-6, abs=1e-12)
    # read through the unit's own chain: its later reading needs the heaviest reversal only
    assert gauge.read(synthetic(gauge, 17e-6, 1.1, play)[:1], commissioning).estimate == (
        pytest.approx(17e-6, abs=1e-12)
    )
    assert later.commissioned and "thrust-bearing play" not in later.budget
    nominal = gauge.read(synthetic(gauge, 17e-6, 1.1, play))
    assert not nominal.commissioned and nominal.budget["thrust-bearing play"] > 0
    assert nominal.upper - nominal.lower > later.upper - later.lower
    # the interval is the budget's root sum square times the conformal factor
    assert later.upper - later.estimate == pytest.approx(COMMISSIONED_SCALE * later.sd)
    assert nominal.upper - nominal.estimate == pytest.approx(CONFORMAL_SCALE * nominal.sd)
    with pytest.raises(ParameterError, match="commissioning"):
        Commissioning.from_readings([(math.nan, None, 1e-6)], 4e-6)


def test_reversals_that_disagree_fall_back_to_one_with_a_note():
    gauge = Gauge(DESIGN)
    heavy, light = synthetic(gauge, 10e-6, 1.0)
    # the light reversal reading more than the heavy one: a negative stiffness
    odd = gauge.read([heavy, reversal(0.10, heavy.lost_motion + 5e-6)])
    assert odd.stiffness_factor is None and len(odd.reversals) == 1
    assert any(f"{STIFFNESS_FACTOR_RANGE[0]:g}" in n for n in odd.notes)
    close = gauge.read([heavy, reversal(0.22, heavy.lost_motion)])
    assert close.stiffness_factor is None and any("too close" in n for n in close.notes)
    assert gauge.read([]) is None


def test_the_measured_torque_sets_the_torsion():
    gauge = Gauge(DESIGN)
    nominal = gauge.chain(reversal(0.25))
    measured = gauge.chain(reversal(0.25, torque=2.0))
    dt = DriveTrain()
    screw_torque = 2.0 * dt.gear_ratio * dt.gear_efficiency
    lead = speed_ratios(DESIGN).nut
    compliance = 1 / dt.coupling_stiffness + 1 / dt.gear_stiffness
    assert measured.gear_coupling_twist == pytest.approx(2 * screw_torque * compliance * lead)
    assert measured.thread_contacts == nominal.thread_contacts


def test_a_bundle_gives_its_recipe_s_gauge():
    metadata = {
        "trained_on": {
            "recipe": {"drive_train": {"coupling_stiffness": 3e3}, "instrumentation": "flight-ema"}
        }
    }
    gauge = gauge_for(DESIGN, metadata, {"gauge": {"conformal_scale": 2.0}})
    assert gauge.drive_train.coupling_stiffness == 3e3 and gauge.conformal_scale == 2.0
    assert gauge.sensor_delays["nut_position"] > 0  # the LVDT's demodulator
    assert gauge_for(None, metadata) is None
    assert gauge_for(DESIGN, {}).sensor_delays is None  # no instrumentation known


# ---------------------------------------------------------------------------- simulated
REVERSALS = HealthCheck(
    "two-reversals",
    tuple(p for p in BUILT_IN["health-check"].phases if p.motion == "reversing"),
)


@functools.lru_cache(maxsize=8)
def _simulated(clearance: float, bearing: float = 1.5e8):
    run = Scenario(
        DESIGN,
        HealthState.uniform(clearance),
        OperatingProfile(check=REVERSALS),
        "ideal",
        SimulationOptions(contact_law="hertz"),
        0,
        DriveTrain(thrust_bearing_stiffness=bearing),
    ).simulate()
    labels = run.labels
    real = 0.5 * (labels["clearance_screw_realised_mean"] + labels["clearance_nut_realised_mean"])
    return check_indicators(run, DESIGN).reversals, real


@pytest.mark.parametrize("bearing", [1.0e8, 2.0e8])
def test_a_commissioned_unit_reads_its_realised_clearance(bearing):
    """Commissioned at b = 5 µm, read at 15 µm (ideal sensors, even wear): the realised mean
    clearance within 0.4 µm whatever the bearing's stiffness — measured +0.12 / +0.13 µm at
    1.0 / 2.0e8 N/m (the settled step's slope ≈ 4.05 against 4 at the heavier reversal: 0.12 µm
    over 10 µm; seeds move it by about ±0.1); through one reversal and the nominal chain, not
    commissioned, the same runs read +3.1 / −2.5 µm, so the bound tests the unit's own chain."""
    gauge = Gauge.nominal(DESIGN, DriveTrain(), None)
    reversals, as_built = _simulated(5e-6, bearing)
    assert [r.phase for r in reversals] == ["slow reversal", "light reversal"]
    commissioning = Commissioning.from_indicators([gauge.read(reversals).indicators()], as_built)
    worn, real = _simulated(15e-6, bearing)
    reading = gauge.read(worn, commissioning)
    assert reading.estimate == pytest.approx(real, abs=0.4e-6)
    assert reading.lower < real < reading.upper
