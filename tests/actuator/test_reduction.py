"""The reduction between motor and screw, the motor's current limit, the duty check and the
motor-side angle sensor (issue 26, item 3).

Runs are 0.03–0.08 s of simulated time on the paper-01 screw; statics are means over the steady
second half, spectral lines are compared with the same run without the excitation.
"""

import math

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, SimulationOptions, preset
from prsm_health.actuator.drive_train import DriveTrain, duty_check, load_drive_train
from prsm_health.core.channels import TRUTH_NAMES
from prsm_health.core.errors import ParameterError
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import build_model, initial_state
from prsm_health.simulation.dynamics.simulate import integrate, integration_step, max_stable_step
from prsm_health.simulation.instrumentation import (
    Instrumentation,
    bind_drive_train,
    load_instrumentation,
)
from prsm_health.simulation.sensors import AngleSensor, SpeedEstimate, TorqueEstimate

RATE = 20_000.0


def run(drive_train, profile, options=None):
    """Truth at the integration rate, the final state and the model."""
    options = options or SimulationOptions()
    model = build_model(preset("paper01"), HealthState(), profile, options, 1, drive_train)
    h, _ = integration_step(options.max_step, *max_stable_step(model), RATE)
    y = initial_state(model)  # the motor on the kinematic solution through the reduction
    raw = integrate(model, y, h, int(round(profile.duration / h)))
    return {name: raw[:, k] for k, name in enumerate(TRUTH_NAMES[: raw.shape[1]])}, y, model, h


def test_ratio_one_is_the_direct_drive_bit_for_bit():
    # At N = 1 the gear fields are unused and the kernel takes the direct drive's path.
    profile = OperatingProfile(duration=0.02, load=500.0)
    direct, _, model, _ = run(DriveTrain.direct(), profile)
    same, _, model1, _ = run(
        DriveTrain.direct(
            gear_efficiency=0.9, gear_stiffness=1e3, pinion_teeth=20, gear_backlash=1e-3
        ),
        profile,
    )
    assert model1.params[L.P_GEARED] == 0.0
    np.testing.assert_array_equal(model.params, model1.params)
    for name in direct:
        np.testing.assert_array_equal(direct[name], same[name])


def spectrum_line(x, rate, f):
    """Amplitude of the Hann-windowed spectrum at f [Hz], and the median of its ±20 % band."""
    x = x - np.mean(x)
    amp = np.abs(np.fft.rfft(x * np.hanning(len(x))))
    freqs = np.fft.rfftfreq(len(x), 1.0 / rate)
    k = int(np.argmin(np.abs(freqs - f)))
    band = (freqs > 0.8 * f) & (freqs < 1.2 * f)
    return float(np.max(amp[k - 2 : k + 3])), float(np.median(amp[band]))


def test_motor_turns_n_times_and_the_mesh_order_shows_in_the_drive_torque():
    # Parallel stage N = 3, 20-tooth pinion: mesh at 20 × motor speed. Its line stands well
    # above its neighbourhood and vanishes without the transmission error (factor 10: the
    # line is the TE times the series stiffness, the rest is the screw's own broadband).
    gear = dict(gear_ratio=3.0, gear_kind="parallel", pinion_teeth=20, gear_stiffness=5e3)
    profile = OperatingProfile(duration=0.08, speed=50.0, load=1000.0)
    t, _, _, h = run(DriveTrain.flight_ema(**gear, transmission_error=1e-4), profile)
    quiet, _, _, _ = run(DriveTrain.flight_ema(**gear, transmission_error=0.0), profile)
    half = len(t["motor_speed"]) // 2
    ratio = np.mean(t["motor_speed"][half:]) / np.mean(t["screw_speed"][half:])
    assert ratio == pytest.approx(3.0, rel=1e-3)
    f_mesh = 20 * 3.0 * 50.0 / (2 * math.pi)
    line, floor = spectrum_line(t["motor_torque"][half:], 1.0 / h, f_mesh)
    line0, _ = spectrum_line(quiet["motor_torque"][half:], 1.0 / h, f_mesh)
    assert line > 10 * floor
    assert line > 10 * line0


@pytest.mark.parametrize("drive", ["prescribed", "speed_loop"])
def test_energy_balance_with_the_reduction(drive):
    # (drive + load − dissipated − Δkinetic)/drive within 1 % at constant speed; the elastic
    # energies are bounded and periodic. The gear's mesh loss is in the dissipated energy.
    dt = DriveTrain.flight_ema()
    profile = OperatingProfile(duration=0.06, load=2000.0, drive=drive)
    t, y, model, _ = run(dt, profile)
    nq = model.n_coordinates
    w_drive, w_load, w_diss = (y[2 * nq + k] for k in (L.X_W_DRIVE, L.X_W_LOAD, L.X_W_DISS))
    p = model.params
    d_kin = 0.5 * p[L.P_J_M] * (t["motor_speed"][-1] ** 2 - t["motor_speed"][0] ** 2)
    assert abs(w_drive + w_load - w_diss - d_kin) / w_drive < 0.01
    # the loss is there: the motor gives the screw torque / (N·η), not / N
    half = len(t["motor_torque"]) // 2
    screw = np.mean(t["motor_torque"][half:]) * dt.gear_ratio
    assert w_diss > (1 - dt.gear_efficiency) * w_drive * 0.9
    assert screw > 2000.0 * model.params[L.P_LEAD_EFF] / 0.999


def test_speed_loop_saturates_at_the_motor_current_limit():
    # 1 A × 0.49 N·m/A is far below the ≈ 1.25 N·m the 2 kN load needs at the motor.
    dt = DriveTrain.flight_ema(peak_current=1.0)
    profile = OperatingProfile(duration=0.03, load=2000.0, drive="speed_loop", torque_limit=50.0)
    t, _, model, _ = run(dt, profile)
    assert model.params[L.P_TORQUE_LIMIT] == pytest.approx(0.49)
    assert np.max(np.abs(t["motor_torque"])) == pytest.approx(0.49, rel=1e-9)
    assert t["screw_speed"][-1] < 0.9 * profile.speed  # it cannot hold the speed


def test_profile_torque_limit_applies_without_a_current_limit():
    model = build_model(
        preset("paper01"),
        HealthState(),
        OperatingProfile(load=100.0, torque_limit=7.0),
        SimulationOptions(),
        1,
        DriveTrain.direct(),
    )
    assert model.params[L.P_TORQUE_LIMIT] == 7.0


def test_duty_check_warns_and_refuses():
    design, dt = preset("paper01"), DriveTrain.flight_ema()
    # 2.1 kN: 3.9 N·m at the screw, 1.35 N·m at the motor, within its 2.2 N·m
    assert duty_check(dt, design, 2100.0, 100.0) == []
    warnings = duty_check(dt, design, 4200.0, 100.0)  # 2.7 N·m > 2.2 continuous, < 4.43 peak
    assert len(warnings) == 1 and "continuous" in warnings[0]
    with pytest.raises(ParameterError, match="peak torque"):
        duty_check(dt, design, 8000.0, 100.0)
    with pytest.raises(ParameterError, match="max_speed"):
        duty_check(dt, design, 1000.0, 200.0)  # 600 rad/s at the motor > 481.7
    assert duty_check(DriveTrain.direct(), design, 1e5, 1e3) == []  # no motor data: no check


def test_named_drive_trains():
    assert load_drive_train("actuator") == DriveTrain.flight_ema()
    assert load_drive_train("actuator") == DriveTrain()  # the sized drive is the default
    assert load_drive_train("direct") == DriveTrain.direct() != DriveTrain()
    assert not load_drive_train("paper01").coupled
    assert DriveTrain.flight_ema().mesh_order == pytest.approx(16.0)  # 24 · (1 − 1/3)
    with pytest.raises(ParameterError, match="gear_ratio"):
        DriveTrain(gear_ratio=0.5)
    with pytest.raises(ParameterError, match="gear_kind"):
        DriveTrain(gear_kind="worm")


def test_measured_screw_angle_is_the_motor_reading_over_n():
    sensor = AngleSensor(counts_per_rev=4096, harmonic_orders=(2,), harmonic_error=(1e-3,))
    bound = bind_drive_train(Instrumentation(screw_angle=sensor), DriveTrain.flight_ema())
    theta = np.linspace(0.0, 30.0, 2001)
    truth = {"motor_angle": theta}
    rng = np.random.default_rng(1)
    motor = sensor.measure("screw_angle", truth, RATE, 1, np.random.default_rng(1), {})
    out = bound.screw_angle.measure("screw_angle", truth, RATE, 1, rng, {})
    np.testing.assert_allclose(out, motor / 3.0, rtol=0, atol=1e-15)
    # the ratio is the drive train's: not a profile key, not written back
    assert "gear_ratio" not in bound.screw_angle.to_dict()
    with pytest.raises(ParameterError):
        load_instrumentation({"profile": "flight-ema", "screw_angle": {"gear_ratio": 3.0}})


def test_speed_estimate_and_torque_sensor_follow_the_drive_train():
    inst = Instrumentation(
        screw_angle=AngleSensor(),
        screw_speed=SpeedEstimate(exact=True),
        drive_torque=TorqueEstimate(ripple_orders=(6,), ripple=(0.01,)),
    )
    bound = bind_drive_train(inst, DriveTrain.flight_ema())
    speed = bound.screw_speed.measure("screw_speed", {"motor_speed": np.full(10, 300.0)}, RATE, 1,
                                      None, {})  # fmt: skip
    np.testing.assert_allclose(speed, 100.0)
    assert (bound.drive_torque.rated_torque, bound.drive_torque.pole_pairs) == (2.2, 2)
    flight = load_instrumentation("flight-ema")
    assert flight.drive_torque.rated_torque is None  # one declaration: the motor's
    assert "rated_torque" not in flight.drive_torque.to_dict()
    kept = bind_drive_train(
        Instrumentation(drive_torque=TorqueEstimate(rated_torque=1.5, pole_pairs=5)),
        DriveTrain.flight_ema(),
    )
    assert (kept.drive_torque.rated_torque, kept.drive_torque.pole_pairs) == (1.5, 5)
