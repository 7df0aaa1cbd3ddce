"""Instrumentation profiles: the built-ins, each sensor's error model, overrides and errors.

Synthetic truth signals at 200 kHz (no simulation), measured at 20 kHz: every test is fast.
Statistical checks state their tolerance and why it holds at the sample size used.
"""

import math

import numpy as np
import pytest

from prsm_health.core.channels import MEASURED_NAMES
from prsm_health.core.errors import ParameterError
from prsm_health.simulation.decimation import decimate
from prsm_health.simulation.instrumentation import (
    Instrumentation,
    list_profiles,
    load_instrumentation,
)
from prsm_health.simulation.sensors import (
    ARCMIN,
    SENSOR_CLASSES,
    STANDARD_GRAVITY,
    Accelerometer,
    LoadCell,
    TorqueEstimate,
)

RATE_IN, FACTOR = 200_000.0, 10
RATE_OUT = RATE_IN / FACTOR
ACCELS = ("nut_axial_accel", "nut_tangential_accel", "nut_radial_x_accel", "nut_radial_y_accel")
SOURCE = {
    "screw_angle": "motor_angle",
    "screw_speed": "motor_speed",
    "drive_torque": "motor_torque",
}


def truth(duration=0.5, speed=2 * np.pi * 8, seed=0):
    """Truth at RATE_IN: a motor turning at ``speed`` (8 rev/s: whole revolutions in 0.5 s),
    a nut moving 1.6 mm/rad of motor, a varying torque and load, random accelerations."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * RATE_IN)) / RATE_IN
    out = {
        "motor_angle": speed * t,
        "motor_speed": np.full_like(t, speed),
        "motor_torque": 0.4 + 0.1 * np.sin(2 * np.pi * 10 * t),
        "nut_position": 1.6e-3 * speed * t,
        "axial_load": 300.0 * np.sin(2 * np.pi * 10 * t),
        "housing_temperature": np.full_like(t, 313.15),
    }
    out.update({name: rng.normal(0.0, 5.0, t.shape) for name in ACCELS})
    return out


def measure(profile, signals=None, seed=3):
    inst = load_instrumentation(profile)
    return inst.measure(signals or truth(), RATE_IN, np.random.default_rng(seed))


EXPECTED = {
    "ideal": set(MEASURED_NAMES),
    "lab-rig": set(MEASURED_NAMES) - {"nut_radial_y_accel"},
    "flight-ema": {
        "screw_angle",
        "screw_speed",
        "nut_position",
        "nut_axial_accel",
        "drive_torque",
        "housing_temperature",
    },
    "minimal": {"screw_angle", "screw_speed", "drive_torque"},
}


def test_the_sensor_classes_cover_the_measured_channels():
    assert set(SENSOR_CLASSES) == set(MEASURED_NAMES)
    assert set(list_profiles()) == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_builtin_profiles_fit_what_the_contract_says(name):
    inst = load_instrumentation(name)
    assert inst.name == name and inst.description
    assert set(inst.fitted) == EXPECTED[name]
    assert inst.sample_rate == 20_000.0
    assert all(spec.device for spec in inst.sensors().values())
    assert load_instrumentation(inst.to_dict()) == inst  # the dict form round-trips
    out = measure(name)
    assert set(out) == EXPECTED[name]
    assert all(len(v) == len(out["screw_angle"]) and np.all(np.isfinite(v)) for v in out.values())


def test_ideal_returns_the_decimated_truth_exactly():
    signals = truth()
    out = measure("ideal", signals)
    for channel, values in out.items():
        expected = decimate(signals[SOURCE.get(channel, channel)], FACTOR)
        assert np.array_equal(values, expected), channel


def test_a_seed_gives_a_bit_identical_run_and_sensors_draw_independently():
    a, b = measure("lab-rig", seed=5), measure("lab-rig", seed=5)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    other = measure("lab-rig", seed=6)
    assert not np.array_equal(a["nut_axial_accel"], other["nut_axial_accel"])
    # one child stream per channel: removing a sensor leaves every other channel unchanged
    fewer = measure({"profile": "lab-rig", "nut_tangential_accel": {"fitted": False}}, seed=5)
    assert "nut_tangential_accel" not in fewer
    assert all(np.array_equal(fewer[k], a[k]) for k in fewer)


def test_accelerometer_noise_rms_is_density_times_root_bandwidth():
    # Zero truth: the output is the noise alone. White noise of density d over the logged band
    # 0…f_s/2 has RMS d·√(f_s/2); 2 s at 20 kHz = 40 000 samples estimate the RMS within
    # 1/√(2·40 000) = 0.35 % (1σ), so 2 % is a > 5σ bound.
    signals = {k: np.zeros(int(2 * RATE_IN)) for k in ACCELS}
    spec = load_instrumentation("flight-ema").nut_axial_accel
    inst = Instrumentation(nut_axial_accel=spec)
    out = inst.measure(signals, RATE_IN, np.random.default_rng(1))["nut_axial_accel"]
    assert spec.noise_density == pytest.approx(25e-6 * STANDARD_GRAVITY)  # 25 µg/√Hz
    assert np.std(out) == pytest.approx(spec.noise_density * math.sqrt(RATE_OUT / 2), rel=0.02)
    # A 1 kHz first-order sensor bandwidth shapes the noise like the signal. The bilinear
    # filter's equivalent noise bandwidth is f_s·a/(2(1 + a)), a = tan(π·f_c/f_s): 1367 Hz here
    # (the analogue π/2·f_c = 1571 Hz, compressed by the warping). The filtered noise has fewer
    # independent samples (correlation time ≈ 1/(2·ENBW)): ≈ 1 % (1σ), so 4 % is a 4σ bound.
    narrow = Instrumentation(nut_axial_accel=Accelerometer(noise_density=1e-3, bandwidth=1e3))
    out = narrow.measure(signals, RATE_IN, np.random.default_rng(2))["nut_axial_accel"]
    a = math.tan(math.pi * 1e3 / RATE_OUT)
    assert np.std(out) == pytest.approx(1e-3 * math.sqrt(RATE_OUT * a / (2 * (1 + a))), rel=0.04)


def test_a_clipped_channel_never_exceeds_the_range():
    # Twice the ±50 g range, a resonance that overshoots, noise on top: never beyond ±50 g.
    t = np.arange(int(0.5 * RATE_IN)) / RATE_IN
    signals = {"nut_axial_accel": 2 * 50 * STANDARD_GRAVITY * np.sign(np.sin(2 * np.pi * 300 * t))}
    inst = Instrumentation(
        nut_axial_accel=Accelerometer(
            noise_density=1e-2, range=50 * STANDARD_GRAVITY, resonance_frequency=21e3
        )
    )
    out = inst.measure(signals, RATE_IN, np.random.default_rng(0))["nut_axial_accel"]
    assert np.max(np.abs(out)) <= 50 * STANDARD_GRAVITY
    assert np.max(out) == 50 * STANDARD_GRAVITY  # it does saturate


def test_resolver_angle_error_has_the_specified_harmonics():
    # flight-ema's resolver: 5′ at the 1st and 7.5′ at the 2nd harmonic of the (1X) angle.
    # 8 rev/s for 0.5 s: whole periods, so a Fourier projection gives each amplitude; the
    # quantisation (0.33′ step) and 0.33′ RMS noise add < 0.01′ to a 10 000-sample projection.
    signals = truth()
    out = measure("flight-ema", signals)["screw_angle"]
    theta = decimate(signals["motor_angle"], FACTOR)
    error = out - theta
    for order, arcmin in ((1, 5.0), (2, 7.5), (3, 0.0)):
        amplitude = 2 * abs(np.mean(error * np.exp(-1j * order * theta)))
        assert amplitude / ARCMIN == pytest.approx(arcmin, abs=0.05), order
    assert np.allclose(out / (2 * np.pi / 65536), np.round(out / (2 * np.pi / 65536)))


def test_speed_estimate_is_the_filtered_difference_of_the_measured_angle():
    out = measure("flight-ema")
    # mean of the difference of the angle = the speed (errors are periodic over whole turns)
    assert np.mean(out["screw_speed"][1000:]) == pytest.approx(2 * np.pi * 8, rel=1e-3)
    ideal = measure("ideal")
    assert np.allclose(ideal["screw_speed"], 2 * np.pi * 8, rtol=1e-12)  # the truth speed
    with pytest.raises(ParameterError, match="screw_speed"):
        load_instrumentation({"profile": "minimal", "screw_angle": {"fitted": False}})


def _torque_gain(seed):
    # Constant truth torque 1 N·m, no noise, no ripple: the estimate is k_t,nom/k_t = g exactly
    # (the current-loop filter starts in steady state).
    inst = load_instrumentation(
        {
            "profile": "minimal",
            "drive_torque": {"noise": 0.0, "ripple_orders": [], "ripple": []},
        }
    )
    signals = {"motor_torque": np.ones(2000), "motor_angle": np.zeros(2000)}
    out = inst.measure(signals, RATE_IN, np.random.default_rng(seed))["drive_torque"]
    assert np.ptp(out) < 1e-12
    return out[0]


def test_torque_constant_error_is_drawn_per_run_from_the_seed():
    assert _torque_gain(4) == _torque_gain(4)
    gains = np.array([_torque_gain(seed) for seed in range(200)])
    assert len(set(gains)) == 200
    # σ = 5 % (±10 % data tolerance read as 2σ); 200 draws estimate σ within 1/√398 = 5 % (1σ),
    # so ±20 % is a 4σ bound; the mean within 4σ/√200 = 1.4 %.
    assert np.std(gains) == pytest.approx(0.05, rel=0.2)
    assert np.mean(gains) == pytest.approx(1.0, abs=0.014)


def test_torque_ripple_at_the_electrical_orders():
    inst = load_instrumentation(
        {"profile": "minimal", "drive_torque": {"noise": 0.0, "gain_sigma": 0.0}}
    )
    signals = truth()
    out = inst.measure(signals, RATE_IN, np.random.default_rng(0))["drive_torque"]
    error = out - decimate(signals["motor_torque"], FACTOR)
    # not bound to a drive train: the estimate's fallback motor (1 N·m, 4 pole pairs)
    theta = TorqueEstimate.UNBOUND_POLE_PAIRS * decimate(signals["motor_angle"], FACTOR)
    # 1 % of 1 N·m at the 6th electrical harmonic; the 1.5 kHz current-loop lag on the 10 Hz
    # torque leaves < 0.1 % of 0.1 N·m in the error, far from 144 Hz.
    assert 2 * abs(np.mean(error[2000:] * np.exp(-6j * theta[2000:]))) == pytest.approx(
        0.01, rel=0.02
    )


def test_position_sensor_nonlinearity_and_resolution():
    inst = load_instrumentation(
        {
            "profile": "flight-ema",
            "nut_position": {"noise": 0.0, "gain_sigma": 0.0, "drift_sigma": 0.0, "bandwidth": 0.0},
        }
    )
    spec = inst.nut_position
    x = np.linspace(-0.15, 0.15, 200_001)
    out = inst.measure(
        {**truth(duration=1.0), "nut_position": x}, RATE_IN, np.random.default_rng(0)
    )["nut_position"]
    error = out - decimate(x, FACTOR)
    # The S-curve peaks at ±0.25 % of the 0.3 m span (± a quantisation step of 4.6 µm).
    assert np.max(np.abs(error)) == pytest.approx(0.0025 * 0.3, abs=spec.resolution)
    assert np.allclose(out / spec.resolution, np.round(out / spec.resolution))


def test_overrides_and_the_toml_form(tmp_path):
    inst = load_instrumentation(
        {
            "profile": "flight-ema",
            "sample_rate": 10_000,
            "name": "flight-ema-noisy",
            "nut_axial_accel": {"noise_density_ug": 40.0, "range_g": 20.0},
            "nut_position": {"fitted": False},
            "axial_load": {"full_scale": 2000.0, "noise": 0.5},
        }
    )
    assert inst.sample_rate == 10_000 and inst.name == "flight-ema-noisy"
    assert inst.nut_axial_accel.noise_density == pytest.approx(40e-6 * STANDARD_GRAVITY)
    assert inst.nut_axial_accel.range == pytest.approx(20 * STANDARD_GRAVITY)
    # the fields not overridden keep the profile's values
    assert inst.nut_axial_accel.resonance_frequency == 21_000.0
    assert inst.nut_position is None
    assert inst.axial_load == LoadCell(full_scale=2000.0, noise=0.5)
    # a profile file starting from another file, relative to its own folder
    (tmp_path / "base.toml").write_text(
        'name = "base"\n[screw_angle]\ncounts_per_rev = 4096\n[screw_speed]\nbandwidth = 300.0\n'
    )
    (tmp_path / "derived.toml").write_text(
        'profile = "base.toml"\n[screw_speed]\nbandwidth = 800.0\n'
    )
    derived = load_instrumentation(tmp_path / "derived.toml")
    assert derived.name == "base" and derived.screw_angle.counts_per_rev == 4096
    assert derived.screw_speed.bandwidth == 800.0 and derived.fitted == (
        "screw_angle",
        "screw_speed",
    )
    assert load_instrumentation("derived.toml", base=tmp_path) == derived
    # the TOML tables round-trip too
    (tmp_path / "full.toml").write_text("\n".join(inst.toml_tables()) + "\n")
    assert load_instrumentation(tmp_path / "full.toml") == inst


def test_unknown_profile_lists_the_builtins():
    with pytest.raises(ParameterError) as err:
        load_instrumentation("flight-emma")
    assert err.value.field == "instrumentation"
    assert all(name in str(err.value) for name in list_profiles())


@pytest.mark.parametrize(
    "data, field, listed",
    [
        ({"profile": "ideal", "sensors": {}}, "instrumentation.sensors", "nut_axial_accel"),
        (
            {"profile": "ideal", "nut_axial_accel": {"noise": 1.0}},
            "instrumentation.nut_axial_accel.noise",
            "noise_density_ug",
        ),
        (
            {"profile": "ideal", "nut_axial_accel": {"noise_density_ug": -1.0}},
            "instrumentation.nut_axial_accel.noise_density_ug",
            "noise_density",
        ),
        (
            {
                "profile": "ideal",
                "screw_angle": {"harmonic_orders": [1, 2], "harmonic_error": [0.0]},
            },
            "instrumentation.screw_angle.harmonic_error",
            "harmonic_orders",
        ),
        (
            {"profile": "ideal", "axial_load": {"fitted": False, "noise": 1.0}},
            "instrumentation.axial_load",
            "fitted = false",
        ),
        ({"profile": "ideal", "sample_rate": 10.0}, "instrumentation.sample_rate", "Hz"),
        ({"profile": 3}, "instrumentation.profile", "flight-ema"),
        ({"name": "empty"}, "instrumentation", "fit at least one"),
    ],
)
def test_errors_name_the_table_and_key(data, field, listed):
    with pytest.raises(ParameterError) as err:
        load_instrumentation(data)
    assert err.value.field == field, str(err.value)
    assert listed in str(err.value)


def test_sample_rate_must_divide_the_integration_rate():
    inst = load_instrumentation({"profile": "ideal", "sample_rate": 30_000})
    with pytest.raises(ParameterError, match="instrumentation.sample_rate"):
        inst.measure(truth(duration=0.01), RATE_IN, np.random.default_rng(0))


def test_describe_gives_every_parameter_with_its_unit():
    info = load_instrumentation("lab-rig").describe()
    accel = info["sensors"]["nut_axial_accel"]
    assert accel["kind"] == "accelerometer" and accel["reads"] == "nut_axial_accel"
    units = {p["name"]: p["unit"] for p in accel["parameters"]}
    assert units["noise_density"] == "m/s^2/sqrt(Hz)" and units["range"] == "m/s^2"
    assert info["sensors"]["screw_speed"]["reads"] == "screw_angle (measured)"


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_simulated_run_keeps_every_truth_signal_out_of_its_measurements(name):
    # Must-show of the instrumentation issue: whatever the profile, the run's channels are
    # measured channels of the contract only; every truth signal is in run.truth, apart.
    from prsm_health import OperatingProfile, simulate
    from prsm_health.core.channels import CHANNEL_NAMES, RECIRCULATING_TRUTH, TRUTH_NAMES

    run = simulate(profile=OperatingProfile(duration=0.02), instrumentation=name, seed=1)
    assert set(run.channels) == EXPECTED[name] and set(run.channels) <= set(CHANNEL_NAMES)
    truth_only = set(TRUTH_NAMES) - set(CHANNEL_NAMES)
    standard = [n for n in TRUTH_NAMES if n not in RECIRCULATING_TRUTH]  # no cam ring here
    assert truth_only.isdisjoint(run.channels) and list(run.truth) == standard
    assert not any(k.startswith("truth_") for k in run.channels)
