"""Condition indicators against signals with known answers, and on simulated runs."""

import math

import numpy as np
import pytest

from prsm_health import (
    preset,
    speed_ratios,
)
from prsm_health.errors import PRSMHealthError
from prsm_health.features import FEATURES, GROUPS, extract_features, windows
from prsm_health.run import Run

RATE = 20_000.0
D = preset("paper01")


def synthetic(n=20_000, speed=100.0, extra=None, load=None):
    t = np.arange(n) / RATE
    ratios = speed_ratios(D)
    f_mesh = D.gear.ring_teeth * ratios.carrier * speed / (2 * math.pi)
    ch = {
        "screw_angle": speed * t,
        "screw_speed": np.full(n, speed),
        "carrier_speed": np.full(n, ratios.carrier * speed),
        "nut_position": ratios.nut * speed * t,
        "nut_axial_accel": 0.3 * np.sin(2 * math.pi * 437.3 * t),
        "nut_tangential_accel": 0.02 * np.sin(2 * math.pi * f_mesh * t + 0.3),
        "nut_radial_x_accel": 0.01 * np.sin(2 * math.pi * 2 * f_mesh * t),
        "nut_radial_y_accel": np.zeros(n),
        "drive_torque": np.full(n, 0.2),
        "friction_torque": 0.03 + 0.001 * np.sin(2 * math.pi * 10 * t),
        "axial_load": np.full(n, 100.0) if load is None else load(t),
    }
    ch.update(extra or {})
    return Run(t, ch, RATE, {"design": "paper01"}), f_mesh


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
            "carrier_speed": ratios.carrier * speed,
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
    steady, _ = synthetic(n)
    assert math.isnan(extract_features(steady)["lost_motion"])  # no reversal: not computable


def test_bad_windows():
    r, _ = synthetic(100)
    with pytest.raises(PRSMHealthError, match="too short"):
        extract_features(r)
    r, _ = synthetic()
    r.channels["nut_axial_accel"][10] = np.nan
    with pytest.raises(PRSMHealthError, match="NaN"):
        extract_features(r)
    empty = Run(r.time, {"drive_torque": r.channels["drive_torque"]}, RATE)
    with pytest.raises(PRSMHealthError, match="no usable channels"):
        extract_features(empty)
    assert len(list(windows(synthetic()[0], 0.25))) == 4


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
