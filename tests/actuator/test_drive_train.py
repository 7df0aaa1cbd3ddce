"""The actuator around the screw: drive train statics, contact damping, energy, excitation.

Runs are 0.1–0.3 s of simulated time; the statics are means over the steady second half, the
vibration levels RMS over it — statistics, not single samples of a trajectory.
"""

import math

import numpy as np
import pytest

from prsm_health import (
    HealthState,
    ManufacturingVariation,
    OperatingProfile,
    SimulationOptions,
    preset,
    simulate,
)
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.states import LEAD_GRADES
from prsm_health.core.channels import TRUTH_NAMES
from prsm_health.core.errors import ParameterError
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics._kernels import screw_motion
from prsm_health.simulation.dynamics.model import build_model, initial_state
from prsm_health.simulation.dynamics.simulate import (
    choose_step,
    integrate,
    integration_step,
    linearised_modes,
    max_stable_step,
)


def truth(profile, drive_train=None, health=None, options=None):
    """Truth signals at the integration rate (the kernel's record), steady second half."""
    options = options or SimulationOptions()
    model = build_model(
        preset("paper01"), health or HealthState(), profile, options, 1, drive_train
    )
    h, _ = integration_step(options.max_step, *max_stable_step(model), 20_000.0)
    raw = integrate(model, initial_state(model), h, int(round(profile.duration / h)))
    half = len(raw) // 2
    return {name: raw[half:, k] for k, name in enumerate(TRUTH_NAMES[: raw.shape[1]])}


def test_static_deflections_of_coupling_bearing_and_linkage():
    # At constant speed under 500 N: coupling twist = motor torque / k_c, screw pushed back on
    # its bearing by F/k_b, linkage stretched by F/k_l, and the linkage carries the load. 2 %:
    # the means include the small steady vibration of the excited threads.
    dt = DriveTrain.direct()
    t = truth(OperatingProfile(duration=0.2, load=500.0), dt)
    twist = np.mean(t["motor_angle"] - t["screw_angle"])
    assert twist == pytest.approx(np.mean(t["motor_torque"]) / dt.coupling_stiffness, rel=0.02)
    assert np.mean(t["screw_axial_position"]) == pytest.approx(
        -500.0 / dt.thrust_bearing_stiffness, rel=0.02
    )
    stretch = np.mean(t["nut_position"] - t["payload_position"])
    assert stretch == pytest.approx(500.0 / dt.linkage_stiffness, rel=0.02)
    assert np.mean(t["axial_load"]) == pytest.approx(500.0, rel=0.02)
    assert np.all(t["load_force"] == 500.0)


def test_paper01_drive_train_is_rigid_and_loads_the_nut():
    t = truth(OperatingProfile(duration=0.1, load=100.0), DriveTrain.paper01())
    assert np.array_equal(t["motor_angle"], t["screw_angle"])
    assert np.all(t["screw_axial_position"] == 0.0)
    assert np.array_equal(t["payload_position"], t["nut_position"])
    assert np.all(t["axial_load"] == 100.0)


def test_bearing_play_adds_to_the_screw_deflection():
    play = 5e-6
    t = truth(OperatingProfile(duration=0.1, load=500.0), DriveTrain(thrust_bearing_play=play))
    expected = -(play + 500.0 / DriveTrain.direct().thrust_bearing_stiffness)
    assert np.mean(t["screw_axial_position"]) == pytest.approx(expected, rel=0.02)


@pytest.mark.parametrize("restitution", [0.6, 0.3])
def test_nut_axial_mode_damping_follows_the_restitution(restitution):
    # Linearised paper-01 model, ideal rollers: the mode where the nut moves axially has the
    # damping ratio of the squeeze film ζ(e) = −ln e/√(π² + ln² e) plus the flanks' material
    # 0.03; 0.02 allowance for the other contacts taking part in the mode.
    options = SimulationOptions(
        variation=ManufacturingVariation.ideal(), contact_restitution=restitution
    )
    model = build_model(
        preset("paper01"),
        HealthState.uniform(0.0),
        OperatingProfile(load=100.0),  # build_model takes newtons (no design to resolve a share)
        options,
        1,
        DriveTrain.paper01(),
    )
    values, vectors, free = linearised_modes(model)
    share = np.abs(vectors[free.index(L.Q_ZN)]) / np.linalg.norm(vectors, axis=0)
    mode = values[int(np.argmax(np.where(values.imag > 0, share, 0.0)))]
    log_e = math.log(restitution)
    zeta_film = -log_e / math.sqrt(math.pi**2 + log_e**2)
    expected = zeta_film + options.contact_damping_ratio
    assert -mode.real / abs(mode) == pytest.approx(expected, abs=0.02)


@pytest.mark.parametrize(
    "drive_train, drive",
    [
        (DriveTrain.direct(), "prescribed"),
        (DriveTrain(thrust_bearing_play=3e-6), "speed_loop"),
    ],
)
def test_energy_balance_with_drive_train_payload_and_excitation(drive_train, drive):
    # Mean drive power = output power + dissipated power within 1 % at constant speed (kinetic
    # and elastic energies are bounded and periodic), default excitation on.
    r = simulate(
        "paper01",
        HealthState(),
        OperatingProfile(duration=0.3, drive=drive),
        "ideal",
        3,
        drive_train=drive_train,
    )
    e = r.energy
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)
    assert e["dissipated"] >= 0 and e["friction"] >= 0


def test_position_loop_follows_a_reversing_motion():
    # Position loop cascaded on the speed loop: the motor angle follows the reversing motion's
    # angle. Without the speed feed-forward it would lag 50 rad/s / 60 1/s ≈ 0.8 rad; with it,
    # only the 50 Hz speed loop overshoots the 5000 rad/s² reversals (≈ 0.15 rad seen): 0.3.
    profile = OperatingProfile(
        duration=0.3,
        motion="reversing",
        speed=50.0,
        motion_period=0.1,
        accel_time=0.01,
        drive="position_loop",
        load=50.0,
    )
    t = truth(profile, options=SimulationOptions(max_step=5e-6))  # a known step for the times
    knots = profile.motion_knots()
    h = choose_step(5e-6, 20_000.0)[0]
    n = int(round(profile.duration / h))
    time = (n // 2 + np.arange(len(t["motor_angle"]))) * h  # truth() keeps the second half
    reference = np.array([screw_motion(ti, knots)[0] for ti in time[::50]])
    ratio = DriveTrain().gear_ratio  # the motor turns N times the screw's motion
    assert np.max(np.abs(t["motor_angle"][::50] / ratio - reference)) < 0.3
    assert t["motor_speed"].max() > 40.0 and t["motor_speed"].min() < -40.0


@pytest.mark.parametrize("seed", [1, 2])
def test_steady_vibration_is_in_the_documented_band(seed):
    # Paper-01 design at 100 rad/s / 100 N with the default geometric errors (ISO 3408-3 grade
    # 5): nut axial RMS in 0.1–1 m/s² (paper 01 reports about ±1 m/s²; docs/validation.md
    # lists the sources). Without any geometric error it is two orders of magnitude quieter —
    # on the direct drive: the default gearhead's transmission error adds its own mesh line.
    def axial_rms(variation):
        r = simulate(
            "paper01",
            HealthState(),
            OperatingProfile(duration=0.3, load=100.0),
            "ideal",
            seed,
            options=SimulationOptions(variation=variation),
            drive_train=DriveTrain.direct(),
        )
        x = r["nut_axial_accel"][len(r) // 3 :]
        return float(np.std(x))

    level = axial_rms(ManufacturingVariation())
    assert 0.1 < level < 1.0
    assert axial_rms(ManufacturingVariation.ideal()) < 0.05 * level


def test_lead_grades_follow_iso_3408_3():
    for grade, (v_300p, v_2pi) in LEAD_GRADES.items():
        v = ManufacturingVariation.grade(grade)
        assert (v.lead_error_cumulative, v.lead_error_periodic) == (v_300p, v_2pi)
    assert LEAD_GRADES[5] == (23e-6, 8e-6)
    with pytest.raises(ParameterError, match="variation.grade"):
        ManufacturingVariation.grade(4)


def test_cosine_load_reversal_is_smooth():
    profile = OperatingProfile(
        duration=0.2,
        load_profile="reversing",
        load=0.0,
        load_amplitude=300.0,
        load_frequency=10.0,
        load_ramp_time=0.02,
        load_ramp_shape="cosine",
    )
    knots, _, _ = profile.load_knots()
    slopes = np.diff(knots[1]) / np.diff(knots[0])
    # a raised cosine starts and ends flat and peaks at π/2 · 600 N / 20 ms in the middle
    assert np.max(np.abs(slopes)) == pytest.approx(math.pi / 2 * 600.0 / 0.02, rel=0.01)
    # the first of the 16 pieces rises at sin(π/32) ≈ 0.1 of the peak slope (a linear ramp: 1)
    assert np.min(np.abs(slopes[slopes != 0])) < 0.15 * np.max(np.abs(slopes))


@pytest.mark.parametrize(
    "field, value",
    [
        ("coupling_stiffness", 0.0),
        ("thrust_bearing_play", -1e-6),
        ("load_application", "rod"),
        ("payload_mass", 0.0),
        ("coupled", "yes"),
    ],
)
def test_drive_train_errors_name_the_field(field, value):
    with pytest.raises(ParameterError, match=f"drive_train.{field}"):
        DriveTrain(**{field: value})


def test_drive_train_from_names_files_scenarios_and_recipes(tmp_path):
    from prsm_health.actuator.drive_train import load_drive_train
    from prsm_health.datasets import Recipe
    from prsm_health.simulation.scenario import Scenario

    assert load_drive_train("paper01") == DriveTrain.paper01()
    assert load_drive_train("actuator") == DriveTrain()
    path = tmp_path / "ema.toml"
    path.write_text("payload_mass = 25.0\nthrust_bearing_play = 2e-6\n")
    assert load_drive_train(path) == DriveTrain(payload_mass=25.0, thrust_bearing_play=2e-6)
    path.write_text("payload = 25.0\n")
    with pytest.raises(
        ParameterError,
        match=r"unknown key 'payload' in \[drive_train\] \(did you mean 'payload_mass'\?\); allowed: motor_inertia",
    ):
        load_drive_train(path)
    with pytest.raises(ParameterError, match="actuator, paper01"):
        load_drive_train("nope")
    scenario = Scenario.from_dict({"drive_train": {"payload_mass": 25.0}})
    (tmp_path / "s.toml").write_text(scenario.to_toml())
    assert Scenario.from_toml(tmp_path / "s.toml") == scenario
    recipe = Recipe.from_dict(
        {
            "name": "dt",
            "design": "paper01",
            "duration": 0.05,
            "sample_rate": 20000,
            "seed": 1,
            "sweep": {"speed": [50.0]},
            "drive_train": {"load_application": "nut", "payload_mass": 3.0},
        }
    )
    spec = recipe.runs()[0]
    assert spec.scenario().drive_train == DriveTrain(load_application="nut", payload_mass=3.0)
