"""Condition indicators against signals with known answers, and on simulated runs."""

import math

import numpy as np
import pytest

from prsm_health import preset, speed_ratios
from prsm_health.core.channels import CHANNEL_NAMES, TRUTH_NAMES
from prsm_health.core.errors import PRSMHealthError, RecordingError
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import ModelBundle, diagnose
from prsm_health.signals.features import (
    FEATURES,
    GROUPS,
    TRUTH_FEATURES,
    extract_features,
    windows,
)
from prsm_health.signals.indicator_table import indicator_groups
from prsm_health.signals.lost_motion import lost_motion_spread, lost_motion_step

RATE = 20_000.0
D = preset("paper01")


def synthetic(n=20_000, speed=100.0, extra=None, load=None):
    """Measured channels with known indicators; the truth holds a friction torque and the
    rigid-body carrier speed."""
    t = np.arange(n) / RATE
    ratios = speed_ratios(D)
    f_mesh = D.gear.ring_teeth * ratios.carrier * speed / (2 * math.pi)
    ch = {
        "screw_angle": speed * t,
        "screw_speed": np.full(n, speed),
        "nut_position": ratios.nut * speed * t,
        "nut_axial_accel": 0.3 * np.sin(2 * math.pi * 437.3 * t),
        "nut_tangential_accel": 0.02 * np.sin(2 * math.pi * f_mesh * t + 0.3),
        "nut_radial_x_accel": 0.01 * np.sin(2 * math.pi * 2 * f_mesh * t),
        "nut_radial_y_accel": np.zeros(n),
        "drive_torque": np.full(n, 0.2),
        "axial_load": np.full(n, 100.0) if load is None else load(t),
        "housing_temperature": np.full(n, 313.15),
    }
    ch.update(extra or {})
    truth = {
        "carrier_speed": np.full(n, ratios.carrier * speed),
        "friction_torque": 0.03 + 0.001 * np.sin(2 * math.pi * 10 * t),
    }
    return Run(t, ch, RATE, truth=truth, operating=OperatingPoint(design="paper01")), f_mesh


def same(a: dict, b: dict) -> bool:
    """Equal indicator dicts, NaN equal to NaN."""
    return list(a) == list(b) and all(
        (math.isnan(a[k]) and math.isnan(b[k])) or a[k] == b[k] for k in a
    )


def test_every_indicator_has_a_unit_and_a_group_member_exists():
    r, _ = synthetic()
    f = extract_features(r)
    assert list(f) == list(FEATURES)
    assert all(FEATURES[k] for k in FEATURES)
    assert all(set(v) <= set(FEATURES) for v in GROUPS.values())


def test_mesh_lines_recovered():
    r, f_mesh = synthetic()
    f = extract_features(r)
    assert f["mesh_frequency"] == pytest.approx(f_mesh, rel=1e-12)
    # Hann amplitude spectrum, coherent gain corrected: a sinusoid reads its amplitude; the line
    # falls between bins (scalloping ≤ 15 % for Hann), so allow 15 %.
    assert f["tan_mesh_h1"] == pytest.approx(0.02, rel=0.15)
    assert f["rx_mesh_h2"] == pytest.approx(0.01, rel=0.15)
    assert f["tan_mesh_h2"] < 1e-3 * f["tan_mesh_h1"]


def test_order_domain_when_speed_varies():
    # Speed ramps 60 → 120 rad/s: the mesh frequency sweeps, but in the order domain the mesh
    # line stays one line of the same amplitude.
    n = 40_000
    t = np.arange(n) / RATE
    speed = 60.0 + 30.0 * t
    angle = 60.0 * t + 15.0 * t**2
    ratios = speed_ratios(D)
    mesh_phase = D.gear.ring_teeth * ratios.carrier * angle
    r, _ = synthetic(
        n,
        extra={
            "screw_angle": angle,
            "screw_speed": speed,
            "nut_tangential_accel": 0.05 * np.sin(mesh_phase),
        },
    )
    f = extract_features(r)
    assert f["tan_mesh_h1"] == pytest.approx(0.05, rel=0.15)


def test_classic_indicators_of_a_sine():
    r, _ = synthetic()
    f = extract_features(r)
    assert f["ax_rms"] == pytest.approx(0.3 / math.sqrt(2), rel=1e-3)
    assert f["ax_crest"] == pytest.approx(math.sqrt(2), rel=1e-3)
    assert f["ax_kurtosis"] == pytest.approx(1.5, rel=1e-2)
    # band energies of the Welch PSD integrate to the variance (the tone sits in 300–1000 Hz)
    assert f["ax_band_300_1000"] == pytest.approx((0.3 / math.sqrt(2)) ** 2, rel=0.02)


def test_axial_frequency_sub_bin():
    r, _ = synthetic()
    f = extract_features(r)
    # 512-sample Welch bins are 39 Hz wide; parabolic interpolation locates 437.3 Hz to < 4 Hz.
    assert f["axial_dominant_frequency"] == pytest.approx(437.3, abs=4.0)
    assert f["axial_frequency_shift"] == pytest.approx(
        437.3 - f["axial_baseline_frequency"], abs=4.0
    )


def test_lost_motion_of_a_lagging_nut():
    # Load reversing at 10 Hz; the nut lags the rigid kinematics by ±15 µm with the load sign.
    n = 20_000
    t = np.arange(n) / RATE

    def load(tt):
        return 300 * np.sign(np.sin(2 * math.pi * 10 * tt) + 1e-12)

    lag = 15e-6 * np.sign(np.sin(2 * math.pi * 10 * t) + 1e-12)
    r, _ = synthetic(n, load=load, extra={"nut_position": speed_ratios(D).nut * 100.0 * t - lag})
    assert extract_features(r)["lost_motion"] == pytest.approx(30e-6, rel=1e-6)
    # An LVDT's S-shaped nonlinearity over the stroke (here 200 µm, 13× the lag) is a smooth
    # function of position: removed, the lag still reads 30 µm (1 %: the S-curve is not exactly
    # a 7th-degree polynomial). Without a load cell the load's sign comes from the torque.
    pos = speed_ratios(D).nut * 100.0 * t
    s_curve = 200e-6 * np.sin(2 * math.pi * (pos - pos.mean()) / np.ptp(pos))
    r, _ = synthetic(n, load=load, extra={"nut_position": pos - lag + s_curve})
    assert extract_features(r)["lost_motion"] == pytest.approx(30e-6, rel=0.01)
    r.channels.pop("axial_load")
    r.channels["drive_torque"] = 1e-3 * load(t)
    assert extract_features(r)["lost_motion"] == pytest.approx(30e-6, rel=0.01)
    steady, _ = synthetic(n)
    assert math.isnan(extract_features(steady)["lost_motion"])  # no reversal: not computable


def test_lost_motion_step_averages_the_position_noise_out():
    # The same lagging nut (jump 30 µm between the flank sides) under an LVDT S-curve, read
    # with 2 and 10 µm RMS of position noise: the percentile spread grows with the noise
    # (≈ 2 × 2.33 σ added in quadrature), the fitted step does not — its standard error is
    # σ/√n ≈ 0.07 µm for 20 000 samples; 0.5 µm allowed.
    n = 20_000
    t = np.arange(n) / RATE
    side = np.sign(np.sin(2 * math.pi * 10 * t) + 1e-12)
    pos = speed_ratios(D).nut * 100.0 * t
    s_curve = 200e-6 * np.sin(2 * math.pi * (pos - pos.mean()) / np.ptp(pos))
    angle = 100.0 * t
    rng = np.random.default_rng(3)
    spreads = []
    for sigma in (2e-6, 10e-6):
        measured = pos - 15e-6 * side + s_curve + sigma * rng.normal(size=n)
        step = lost_motion_step(measured, angle, speed_ratios(D).nut, side)
        assert step == pytest.approx(30e-6, abs=0.5e-6)
        spreads.append(lost_motion_spread(measured, angle, speed_ratios(D).nut, side))
    assert spreads[1] > spreads[0] + 10e-6  # the spread: +≈ 18 µm from the noise alone
    assert math.isnan(lost_motion_step(pos, angle, speed_ratios(D).nut, np.ones(n)))  # one side


def test_bad_windows():
    r, _ = synthetic(100)
    with pytest.raises(PRSMHealthError, match="too short"):
        extract_features(r)
    r, _ = synthetic()
    r.channels["nut_axial_accel"][10] = np.nan
    with pytest.raises(PRSMHealthError, match="NaN"):
        extract_features(r)
    # a drive that logs only its torque (the minimal profile): torque indicators, the rest NaN
    torque_only = extract_features(Run(r.time, {"drive_torque": r.channels["drive_torque"]}, RATE))
    assert np.isfinite(torque_only["drive_torque_mean"])
    assert math.isnan(torque_only["ax_rms"]) and math.isnan(torque_only["lost_motion"])
    groups = indicator_groups(torque_only, ["drive_torque"])
    assert groups["torque"] == "computed"
    assert groups["axial_frequency"] == "missing channel(s) nut_axial_accel"
    assert groups["lost_motion"] == "missing channel(s) nut_position, screw_angle"
    assert len(list(windows(synthetic()[0], 0.25))) == 4


# ----------------------------------------------------------------------------- truth apart
def test_truth_is_never_read_by_default():
    r, _ = synthetic()
    n = len(r)
    reference = extract_features(Run(r.time, r.channels, RATE, r.labels))
    rng = np.random.default_rng(0)
    # Every truth signal present, with values no sensor would give, then all NaN: a feature
    # that read any of them would change (or the NaN would stop the extraction).
    for fill in (lambda: 1e6 * rng.standard_normal(n), lambda: np.full(n, np.nan)):
        r.truth = {name: fill() for name in TRUTH_NAMES}
        assert same(extract_features(r), reference)
    assert not any(k.startswith("truth_") or k.startswith("friction_") for k in reference)


def test_a_run_with_only_truth_has_no_features():
    r, _ = synthetic()
    truth_only = Run(r.time, {}, RATE, r.labels, truth={**r.channels, **r.truth})
    with pytest.raises(RecordingError, match="no contract channel"):
        extract_features(truth_only)
    # Under their file column names they are not channels either.
    prefixed = Run(r.time, {"truth_" + k: v for k, v in r.channels.items()}, RATE, r.labels)
    with pytest.raises(PRSMHealthError, match="no usable channels"):
        extract_features(prefixed)


def test_truth_indicators_only_when_asked():
    r, f_mesh = synthetic()
    f = extract_features(r, truth=("friction_torque",))
    assert list(f) == [*FEATURES, *TRUTH_FEATURES["friction_torque"]]
    assert f["friction_torque_mean"] == pytest.approx(0.03, rel=1e-6)
    assert f["friction_torque_ripple"] == pytest.approx(0.001 / math.sqrt(2), rel=1e-3)
    # The true carrier speed, 2 % off the rigid-body ratio (rollers slip), moves the mesh line
    # only when asked for.
    r.truth["carrier_speed"] = 1.02 * r.truth["carrier_speed"]
    assert extract_features(r)["mesh_frequency"] == pytest.approx(f_mesh, rel=1e-12)
    slipping = extract_features(r, truth=("carrier_speed",))
    assert list(slipping) == list(FEATURES)
    assert slipping["mesh_frequency"] == pytest.approx(1.02 * f_mesh, rel=1e-12)
    for truth, needle in [
        (("motor_angle",), "no truth indicator reads 'motor_angle'"),
        ("friction_torque", "give a tuple"),
    ]:
        with pytest.raises(PRSMHealthError, match=needle):
            extract_features(r, truth=truth)
    recording = Run(r.time, r.channels, RATE, r.labels)
    with pytest.raises(PRSMHealthError, match="only simulated runs have truth"):
        extract_features(recording, truth=("friction_torque",))
    r.truth["friction_torque"][5] = np.nan  # asked for: checked like a channel
    with pytest.raises(RecordingError, match="truth friction_torque contains NaN"):
        extract_features(r, truth=("friction_torque",))


# ----------------------------------------------------------------------------- missing channels
def test_missing_channels_give_nan_indicators_of_a_fixed_set():
    r, _ = synthetic()
    full = extract_features(r)
    # A profile with an axial accelerometer, the drive and no load cell.
    fitted = ("screw_angle", "screw_speed", "nut_position", "nut_axial_accel", "drive_torque")
    sparse = extract_features(Run(r.time, {k: r.channels[k] for k in fitted}, RATE, r.labels))
    assert list(sparse) == list(FEATURES)
    for key in ("tan_rms", "rx_mesh_h2", "ry_kurtosis", "load_mean", "load_range", "efficiency"):
        assert math.isnan(sparse[key]), key
    for key in ("ax_rms", "axial_dominant_frequency", "mesh_frequency", "drive_torque_mean"):
        assert sparse[key] == full[key], key
    # Without the load cell the axial baseline is taken at the nominal 100 N.
    assert sparse["axial_baseline_frequency"] == pytest.approx(full["axial_baseline_frequency"])


def test_a_recording_without_a_channel_the_model_was_trained_with_is_warned_not_guessed():
    r, _ = synthetic()
    no_load_cell = {k: v for k, v in r.channels.items() if k != "axial_load"}
    bundle = ModelBundle(None, None, list(FEATURES), {"name": "m", "channels": list(CHANNEL_NAMES)})
    d = diagnose(Run(r.time, no_load_cell, RATE, r.labels), bundle)
    assert any("channel(s) axial_load missing: model 'm'" in w for w in d.warnings)
    assert d.observability == {"clearance": 0.0, "fault": 0.0}
    # Trained without the load cell: its indicators were NaN in training, the recording's are
    # not used; a bundle without a channel record is not checked.
    fitted = [c for c in CHANNEL_NAMES if c != "axial_load"]
    for metadata in ({"channels": fitted}, {}):
        bundle = ModelBundle(None, None, list(FEATURES), metadata)
        assert diagnose(Run(r.time, no_load_cell, RATE, r.labels), bundle).windows
        assert diagnose(r, bundle).windows


def test_simulated_clearance_signature(reversing_run):
    # Reversing ±300 N load (docs/validation.md): lost motion grows by ≈ 4·15 µm per step (robust
    # to the impact sequence) and the impact RMS rises. The dominant axial frequency is not
    # asserted: with the drive train it is not monotone in b (clearance-signature map).
    lost, rms = [], []
    for b in (5e-6, 20e-6, 35e-6):
        f = extract_features(reversing_run(b, duration=0.3, seed=2))
        lost.append(f["lost_motion"])
        rms.append(f["ax_rms"])
    assert lost[0] < lost[1] < lost[2]
    assert rms[0] < rms[2]


def test_efficiency_from_the_energy_balance_survives_a_reversing_load():
    # Paper 02's form F·p_s/(F·p_s + 2π·T_loss): a load of ±500 N at 10 Hz (driving, then
    # back-driving) through a screw of efficiency η each way. Input power T·ω: F·v/η driving,
    # F·v·η back-driven; the window's efficiency is then 1/(1 + (1/η − η)/2) exactly.
    eta, force = 0.85, 500.0
    r, _ = synthetic(load=lambda t: force * np.sign(np.sin(2 * math.pi * 10 * t + 0.1)))
    ch = r.channels
    v = np.gradient(ch["nut_position"], r.time)
    p_out = ch["axial_load"] * v
    ch["drive_torque"] = np.where(p_out > 0, p_out / eta, p_out * eta) / ch["screw_speed"]
    expected = 1.0 / (1.0 + (1.0 / eta - eta) / 2.0)
    assert extract_features(r)["efficiency"] == pytest.approx(expected, rel=1e-9)
    # more friction, lower efficiency; a steady driving load gives η itself
    ch["drive_torque"] = np.where(p_out > 0, p_out / 0.7, p_out * 0.7) / ch["screw_speed"]
    assert extract_features(r)["efficiency"] < expected
    steady, _ = synthetic()
    p = steady.channels["axial_load"] * np.gradient(steady.channels["nut_position"], steady.time)
    steady.channels["drive_torque"] = p / eta / steady.channels["screw_speed"]
    assert extract_features(steady)["efficiency"] == pytest.approx(eta, rel=1e-9)


def _reversing_drive(rate: float, seconds: float = 4.0) -> Run:
    """Slow drive channels at ``rate``: speed reversing at 0.5 Hz, a torque that rattles."""
    t = np.arange(int(seconds * rate)) / rate
    speed = 20.0 * np.sin(2 * math.pi * 0.5 * t)
    angle = np.cumsum(speed) / rate
    torque = 0.2 * np.sign(speed) + 0.05 * np.sin(2 * math.pi * 180.0 * t)
    ch = {
        "screw_angle": angle,
        "screw_speed": speed,
        "nut_position": speed_ratios(D).nut * angle,
        "nut_axial_accel": 0.3 * np.sin(2 * math.pi * 437.3 * t),
        "drive_torque": torque,
    }
    return Run(t, ch, rate, operating=OperatingPoint(design="paper01"))


def test_a_group_whose_band_lies_above_the_recording_is_nan_and_says_the_rate_it_needs():
    from prsm_health.signals.indicator_table import GROUP_CHANNELS, usable_groups

    rattle = GROUP_CHANNELS["torque_rattle"].min_rate
    axial = GROUP_CHANNELS["axial_frequency"].min_rate
    assert 0 < rattle < 1000.0 < axial  # a 1 kHz logger resolves the bounces, not the mode
    for rate, rattle_read, axial_read in ((250.0, False, False), (2000.0, True, False)):
        run = _reversing_drive(rate)
        row = extract_features(run)
        assert math.isfinite(row["torque_rattle_rate"]) == rattle_read, rate
        assert math.isfinite(row["axial_dominant_frequency"]) == axial_read, rate
        said = indicator_groups(row, run.channels, rate)
        assert (
            said["axial_frequency"] == f"sample rate {rate:g} Hz below the {axial:.0f} Hz it needs"
        )
        assert (said["torque_rattle"] == "computed") == rattle_read
        usable = usable_groups(run.channels, rate)
        assert usable["axial_frequency"] == said["axial_frequency"]
        assert usable["generic"] == usable["statistics"] == "usable"
        assert usable["mesh"].startswith("missing channel(s) ")
    # the same signals at 20 kHz read both
    row = extract_features(_reversing_drive(RATE, 2.5))
    assert math.isfinite(row["torque_rattle_rate"])
    assert math.isfinite(row["axial_dominant_frequency"])


def test_channel_statistics_are_every_channels_and_no_model_indicator():
    from prsm_health.signals.channel_statistics import CHANNEL_STATISTICS
    from prsm_health.signals.indicator_table import NOT_INDICATORS

    r, _ = synthetic()
    row = extract_features(r)
    assert row["stat_drive_torque_mean"] == pytest.approx(0.2)
    assert row["stat_axial_load_max"] == pytest.approx(100.0)
    assert row["stat_nut_axial_accel_std"] == pytest.approx(0.3 / math.sqrt(2), rel=1e-3)
    assert GROUPS["statistics"] == list(CHANNEL_STATISTICS) and "statistics" in NOT_INDICATORS
    # a statistic belongs to no indicator group (the torque group's drive_torque_mean is not
    # stat_drive_torque_mean)
    others = {n for g, members in GROUPS.items() if g != "statistics" for n in members}
    assert not others & set(CHANNEL_STATISTICS)
    without = Run(r.time, {"drive_torque": r.channels["drive_torque"]}, RATE, operating=r.operating)
    assert math.isnan(extract_features(without)["stat_axial_load_mean"])
