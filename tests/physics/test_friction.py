"""Friction torque and efficiency (paper 02) under the stated reading, and physical invariants."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.core.errors import ConvergenceError, ParameterError
from prsm_health.physics import friction
from prsm_health.physics.friction import (
    FrictionParameters,
    simulate_friction,
    steady_friction_torque,
    with_scale,
)

P = FrictionParameters.paper02()


def test_paper02_derived_quantities():
    # docs/validation.md (paper 02): p_s = 0.79577 mm/rad, ψ = 4.550°, G = −2 with the
    # printed radii, F_n = 94.58 N at 1000 N (exact formulas, rounding of the printed digits).
    assert P.lead_per_radian == pytest.approx(0.79577e-3, rel=1e-5)
    assert math.degrees(P.lead_angle) == pytest.approx(4.550, abs=5e-4)
    assert P.gear_ratio == pytest.approx(-2.0)
    assert P.normal_load(1000.0) == pytest.approx(94.58, abs=0.005)
    assert P.rolling_ratio == pytest.approx(0.400, abs=1e-12)


def test_steady_torque_at_1000_N_within_10_percent_of_paper():
    # Issue: within 10 % of the paper's 0.12 N·m under the stated reading (all contacts):
    # F(μ2 p_s + μ3)/(cos ψ cos β) = 0.1150 N·m.
    r = simulate_friction(P, 1000.0, 1.0, 0.02)
    assert r.steady_friction_torque == pytest.approx(0.1150, abs=5e-4)
    assert r.steady_friction_torque == pytest.approx(0.12, rel=0.10)
    # The simulated end state is the closed form (rollers rolling at 0.4·ω_s).
    assert r.friction_torque[-1] == pytest.approx(r.steady_friction_torque, rel=1e-3)
    assert r.revolution_speed[-1] == pytest.approx(0.4, rel=1e-4)


LOADS = [500.0, 1000.0, 3000.0, 5000.0]
ACCEL = [0.01, 0.03, 0.06, 0.09]


@pytest.mark.parametrize("load", LOADS)
@pytest.mark.parametrize("t_acc", ACCEL)
def test_invariants(load, t_acc):
    r = simulate_friction(P, load, 1.0, t_acc)
    assert r.peak_friction_torque >= r.steady_friction_torque
    assert r.min_efficiency <= r.overall_efficiency <= r.steady_efficiency <= 1.0


@pytest.mark.parametrize("load", LOADS)
def test_shorter_ramp_higher_peak(load):
    peaks = [simulate_friction(P, load, 1.0, t).peak_friction_torque for t in ACCEL]
    assert all(a > b for a, b in zip(peaks, peaks[1:])), peaks


def test_torque_rises_with_load_and_friction_scale():
    torques = [simulate_friction(P, f, 1.0, 0.02).steady_friction_torque for f in LOADS]
    assert all(a < b for a, b in zip(torques, torques[1:]))
    worn = simulate_friction(with_scale(P, 2.0), 1000.0, 1.0, 0.02)
    assert worn.steady_friction_torque == pytest.approx(2 * torques[1], rel=1e-12)
    assert worn.steady_efficiency < simulate_friction(P, 1000.0, 1.0, 0.02).steady_efficiency


def test_literal_one_contact_reading_is_15x_smaller():
    # The notes: read literally, F_fs2 = μ2·F_n and M_fs3 = μ3·F_n are one contact's worth —
    # n_R·n_t = 15 times smaller than the all-contacts reading the model uses.
    literal = P.normal_load(1000.0) * (P.sliding * P.lead_per_radian + P.rolling)
    assert steady_friction_torque(P, 1000.0) / literal == pytest.approx(15.0, rel=1e-12)


def test_drag_torque_makes_efficiency_rise_with_load():
    # The documented modelling choice: a load-independent loss makes η rise with load.
    dragged = FrictionParameters(drag_torque=0.03)
    eta = [simulate_friction(dragged, f, 1.0, 0.02).steady_efficiency for f in LOADS]
    assert all(a < b for a, b in zip(eta, eta[1:]))
    plain = [simulate_friction(P, f, 1.0, 0.02).steady_efficiency for f in LOADS]
    assert np.ptp(plain) < 1e-12


def test_from_design_and_errors():
    params = FrictionParameters.from_design(preset("paper01"))
    assert params.lead_per_radian == pytest.approx(preset("paper01").screw_lead / (2 * math.pi))
    with pytest.raises(ParameterError, match="load"):
        simulate_friction(P, -1.0)
    with pytest.raises(ParameterError, match="duration"):
        simulate_friction(P, 100.0, 1.0, 0.05, duration=0.01)
    with pytest.raises(ParameterError, match="friction.nut_radius"):
        FrictionParameters(nut_radius=1e-3)


def test_integration_failure_is_a_convergence_error(monkeypatch):
    monkeypatch.setattr(
        friction, "solve_ivp", lambda *a, **k: SimpleNamespace(success=False, message="stiff")
    )
    with pytest.raises(ConvergenceError, match=r"friction: Radau.*load = 1000 N.*stiff"):
        simulate_friction(P, 1000.0, 100.0, 0.05)
