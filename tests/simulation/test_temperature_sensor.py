"""The housing temperature channel: its RTD model, the truth it reads, the profiles that fit it,
the indicator that reads it, and a diagnosis with and without it.

Sensor statistics run on synthetic truth at 200 kHz measured at 20 kHz (no simulation); the
simulated runs last 0.02–0.05 s. Tolerances are stated where they are used.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.simulation.decimation import decimate
from prsm_health.simulation.instrumentation import (
    Instrumentation,
    load_instrumentation,
)
from prsm_health.simulation.sensors import SENSOR_CLASSES, TemperatureSensor
from prsm_health.simulation.thermal import (
    CONTACT_TO_HOUSING_RESISTANCE,
    housing_temperature,
    housing_temperature_signal,
)

RATE_IN, FACTOR = 200_000.0, 10
RATE_OUT = RATE_IN / FACTOR
CHANNEL = "housing_temperature"


def _truth(value=313.15, duration=0.05):
    return {CHANNEL: np.full(int(duration * RATE_IN), value)}


def _read(sensor, truth, seed=0):
    rng = np.random.default_rng(seed)
    return sensor.measure(CHANNEL, truth, RATE_IN, FACTOR, rng, {})


def test_the_sensor_is_registered_last_so_the_other_channels_keep_their_streams():
    # Instrumentation.measure gives channel k the k-th draw of the run's stream: appended last,
    # the temperature sensor leaves every other channel's draws (and the shipped model's
    # training data) as they were.
    assert list(SENSOR_CLASSES)[-1] == CHANNEL and SENSOR_CLASSES[CHANNEL] is TemperatureSensor


def test_calibration_error_is_uniform_within_the_class_limit():
    # Class B at 100 °C: limit 0.3 + 0.005·100 = 0.8 K. 400 runs (seeds), no converter error,
    # noise or quantisation: every error within ±0.8 K; its spread is uniform, σ = 0.8/√3 =
    # 0.462 K (sample σ of 400 draws: relative s.e. ≈ 1/√800 = 3.5 %; 15 % is > 4 s.e.); and
    # the draws reach the ends (P(all 400 inside ±0.72 K) = 0.9⁴⁰⁰ ≈ 5e-19).
    sensor = TemperatureSensor(tolerance=0.3, tolerance_slope=0.005)
    value = 373.15
    assert sensor.limit(value) == pytest.approx(0.8)
    errors = np.array([_read(sensor, _truth(value, 0.005), seed)[0] - value for seed in range(400)])
    assert np.max(np.abs(errors)) <= 0.8 + 1e-9
    assert np.max(np.abs(errors)) > 0.72
    assert np.std(errors) == pytest.approx(0.8 / math.sqrt(3), rel=0.15)
    assert abs(np.mean(errors)) < 4 * 0.462 / math.sqrt(400)  # unbiased, 4 s.e.
    # the converter's bound adds its own uniform error: σ² = (0.8² + 0.5²)/3
    both = TemperatureSensor(tolerance=0.3, tolerance_slope=0.005, converter_error=0.5)
    errors = np.array([_read(both, _truth(value, 0.005), seed)[0] - value for seed in range(400)])
    assert np.max(np.abs(errors)) <= 1.3 + 1e-9
    assert np.std(errors) == pytest.approx(math.sqrt((0.64 + 0.25) / 3), rel=0.15)


def test_the_error_is_constant_over_a_run_and_drawn_per_run():
    sensor = TemperatureSensor(tolerance=0.15, tolerance_slope=0.002)
    a, b = _read(sensor, _truth(), 1), _read(sensor, _truth(), 1)
    assert np.array_equal(a, b)  # a seed gives the same reading
    assert np.ptp(a) == 0.0  # an offset: no noise, no drift
    assert _read(sensor, _truth(), 2)[0] != a[0]


def test_noise_rms_and_resolution():
    # One conversion per sample: the reading's σ is the noise (20 000 samples: s.e. of σ 0.5 %).
    noisy = TemperatureSensor(noise=0.05)
    y = _read(noisy, _truth(duration=1.0), 4)
    assert np.std(y) == pytest.approx(0.05, rel=0.03)
    assert np.mean(y) == pytest.approx(313.15, abs=4 * 0.05 / math.sqrt(y.size))
    # Quantised to the LSB: every reading is a multiple of it, within half an LSB of the truth
    lsb = 0.03125
    y = _read(TemperatureSensor(resolution=lsb), _truth(313.16))
    assert np.allclose(y / lsb, np.round(y / lsb), atol=1e-9, rtol=0)
    assert np.all(np.abs(y - 313.16) <= lsb / 2 + 1e-9)


def test_conversions_are_held_between_updates():
    # 20 ms between conversions at 20 kHz: runs of 400 equal samples (the first shorter, at a
    # random phase), each with its own noise draw.
    sensor = TemperatureSensor(noise=0.05, update_interval=0.02)
    y = _read(sensor, _truth(duration=0.5), 7)
    starts = np.r_[0, np.flatnonzero(np.diff(y)) + 1]
    lengths = np.diff(np.r_[starts, y.size])
    assert 1 <= lengths[0] <= 400 and np.all(lengths[1:-1] == 400)
    assert len(starts) in (25, 26)


def test_the_probe_lags_as_a_first_order_system():
    # A 10 K step at 0.1 s, time constant 20 ms (short, so the test stays short; the profiles
    # use 10–30 s): the reading follows 1 − exp(−t/τ). The decimator's anti-alias filter is
    # ≈ 1 ms wide around the step, so the comparison starts 2 ms after it; then it agrees within
    # 0.5 % of the step.
    tau = 0.02
    t_in = np.arange(int(0.3 * RATE_IN)) / RATE_IN
    truth = {CHANNEL: np.where(t_in >= 0.1, 310.0, 300.0)}
    y = _read(TemperatureSensor(time_constant=tau), truth)
    t = np.arange(y.size) / RATE_OUT
    after = t >= 0.102
    expected = 300.0 + 10.0 * (1.0 - np.exp(-(t[after] - 0.1) / tau))
    assert np.max(np.abs(y[after] - expected)) < 0.05
    # started in steady state (the decimator starts within 2e-4 K of it)
    assert np.all(y[t < 0.099] == pytest.approx(300.0, abs=1e-3))
    # at one time constant: 63 % of the step
    k = np.searchsorted(t, 0.1 + tau)
    assert (y[k] - 300.0) / 10.0 == pytest.approx(1 - math.exp(-1), abs=0.01)


def test_the_ideal_sensor_reads_the_decimated_truth():
    truth = {CHANNEL: 300.0 + np.linspace(0.0, 1.0, int(0.05 * RATE_IN))}
    assert np.array_equal(_read(TemperatureSensor(), truth), decimate(truth[CHANNEL], FACTOR))


@pytest.mark.parametrize(
    ("field", "value"),
    [("tolerance", -0.1), ("tolerance_slope", 0.2), ("time_constant", -1.0), ("noise", 20.0)],
)
def test_bad_fields_name_the_field_and_range(field, value):
    with pytest.raises(ParameterError) as err:
        load_instrumentation({"profile": "flight-ema", CHANNEL: {field: value}})
    assert err.value.field == f"instrumentation.{CHANNEL}.{field}"


def test_unknown_key_lists_the_allowed():
    with pytest.raises(ParameterError, match="time_constant"):
        load_instrumentation({"profile": "flight-ema", CHANNEL: {"tau": 3.0}})


@pytest.mark.parametrize(
    ("name", "fitted"),
    [("flight-ema", True), ("lab-rig", True), ("ideal", True), ("minimal", False)],
)
def test_which_profiles_fit_it(name, fitted):
    inst = load_instrumentation(name)
    assert (inst.housing_temperature is not None) is fitted
    if fitted:
        assert inst.describe()["sensors"][CHANNEL]["reads"] == CHANNEL
        assert load_instrumentation(inst.to_dict()) == inst


def test_the_builtin_class_limits_are_iec_60751():
    # class B (flight) ±(0.3 + 0.005|t|), class A (lab) ±(0.15 + 0.002|t|), t in °C
    flight = load_instrumentation("flight-ema").housing_temperature
    lab = load_instrumentation("lab-rig").housing_temperature
    assert (flight.tolerance, flight.tolerance_slope) == (0.3, 0.005)
    assert (lab.tolerance, lab.tolerance_slope) == (0.15, 0.002)
    assert flight.limit(373.15) == pytest.approx(0.8) and lab.limit(373.15) == pytest.approx(0.35)


def test_housing_truth_is_the_contact_less_the_friction_heat_rise():
    assert housing_temperature(330.0, 50.0) == pytest.approx(330.0 - 50.0 * 0.1)
    assert housing_temperature(330.0, -1.0) == 330.0  # no negative heat
    with pytest.raises(ParameterError, match="profile.temperature"):
        housing_temperature(100.0, 0.0)
    signal = housing_temperature_signal(
        320.0, {"friction_torque": np.full(10, 0.2), "screw_speed": np.full(10, 100.0)}
    )
    assert signal.shape == (10,) and np.all(signal == pytest.approx(320.0 - 20.0 * 0.1))


@pytest.fixture(scope="module")
def runs():
    from prsm_health import OperatingProfile, simulate

    profile = OperatingProfile(duration=0.05, load=2000.0, temperature=333.15)
    return {
        name: simulate(profile=profile, instrumentation=name, seed=3)
        for name in ("flight-ema", "lab-rig", "minimal")
    }


def test_simulated_runs_carry_the_truth_always_and_the_channel_where_fitted(runs):
    for name, run in runs.items():
        truth = run.truth[CHANNEL]
        # the steady rise of the run's friction power: the energy book's friction work / time
        power = run.energy["friction"] / 0.05
        assert np.all(truth == truth[0])
        assert truth[0] == pytest.approx(333.15 - CONTACT_TO_HOUSING_RESISTANCE * power, abs=0.05)
        assert truth[0] < 333.15  # the housing runs cooler than the contacts
        if name == "minimal":
            assert CHANNEL not in run.channels
            continue
        sensor = load_instrumentation(name).housing_temperature
        reading = run.channels[CHANNEL]
        bound = sensor.limit(truth[0]) + sensor.converter_error + sensor.resolution / 2
        assert np.all(np.abs(reading - truth) <= bound + 5 * sensor.noise)


def test_the_indicator_reads_the_channel_never_the_truth(runs):
    from prsm_health.signals.features import FEATURES, GROUPS, extract_features

    assert FEATURES["housing_temperature_mean"] == "K"
    assert "housing_temperature_mean" in GROUPS["operating"]
    run = runs["flight-ema"]
    row = extract_features(run)
    assert row["housing_temperature_mean"] == pytest.approx(np.mean(run.channels[CHANNEL]))
    # the minimal run has the truth but no sensor: NaN
    assert math.isnan(extract_features(runs["minimal"])["housing_temperature_mean"])


@pytest.mark.slow  # loads the shipped model (≈ 3 s)
def test_a_recording_with_or_without_the_channel_diagnoses_alike(runs):
    # The shipped model reads the housing temperature (the lubricant's confounder): a recording
    # without the channel is still diagnosed, with a warning naming it, and its clearance stays
    # inside the interval of the recording that has it (one indicator of ~60 missing).
    from prsm_health.diagnostics.diagnosis import diagnose, load_bundle

    bundle = load_bundle()
    assert "housing_temperature_mean" in bundle.feature_names
    run = runs["flight-ema"]
    without = replace(run, channels={k: v for k, v in run.channels.items() if k != CHANNEL})
    a, b = diagnose(run, bundle), diagnose(without, bundle)
    assert not any(CHANNEL in w for w in a.warnings)
    assert any(CHANNEL in w and "missing" in w for w in b.warnings)
    assert a.clearance["lower"] <= b.clearance["estimate"] <= a.clearance["upper"]


def test_the_channel_survives_parquet_and_mcap(runs, tmp_path):
    from prsm_health.io import read_recording
    from prsm_health.io.mcap import write_mcap
    from prsm_health.io.parquet import write_run_parquet

    run = runs["lab-rig"]
    for write, suffix in ((write_run_parquet, "parquet"), (write_mcap, "mcap")):
        back = read_recording(write(run, tmp_path / f"run.{suffix}"))
        assert np.allclose(back.channels[CHANNEL], run.channels[CHANNEL], rtol=0, atol=1e-9)
        assert np.allclose(back.truth[CHANNEL], run.truth[CHANNEL], rtol=0, atol=1e-9)


def test_an_instrumentation_of_the_temperature_alone_is_valid():
    inst = Instrumentation(housing_temperature=TemperatureSensor(device="probe"))
    assert inst.fitted == (CHANNEL,)
