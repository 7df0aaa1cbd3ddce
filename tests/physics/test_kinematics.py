"""Rigid-body kinematics against closed forms and papers 01, 03, 04."""

import math

import pytest

from prsm_health.actuator.design import PRESETS, preset
from prsm_health.physics.kinematics import characteristic_frequencies, speed_ratios

STANDARD = [n for n in sorted(PRESETS) if preset(n).variant == "standard"]


def test_paper01_carrier_ratio_is_0375():
    # Paper 01: rigid-body ratio r_s/(2(r_s + r_c)) = 9.75/26.
    assert speed_ratios(preset("paper01")).carrier == pytest.approx(0.375, rel=1e-12)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_roller_spin_closed_form(name):
    # Paper 03 eqs. (25) + (27) force ω_r = −(d_s / 2d_r)·ω_s for a concentric design.
    d = preset(name)
    expected = -d.screw_diameter / (2 * d.roller_diameter)
    assert speed_ratios(d).roller_spin == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("name", STANDARD)
def test_gear_constraint_holds(name):
    # Independent check: the roller gear rolls on the fixed ring gear, so relative to the
    # carrier (ω_r − ω_c)·z_roller = (0 − ω_c)·z_ring.
    d = preset(name)
    r = speed_ratios(d)
    assert r.roller_spin_relative * d.gear.roller_teeth == pytest.approx(
        -r.carrier * d.gear.ring_teeth, rel=1e-12
    )


@pytest.mark.parametrize("name", STANDARD)
def test_effective_lead_equals_screw_lead(name):
    # A standard PRSM with n_s = d_s/d_r + 2 advances one screw lead per screw turn.
    d = preset(name)
    assert speed_ratios(d).effective_lead == pytest.approx(d.screw_lead, rel=1e-12)


def test_paper01_mesh_frequency():
    f = characteristic_frequencies(preset("paper01"), 100.0)
    assert f.carrier == pytest.approx(100 * 0.375 / (2 * math.pi))
    assert f.gear_mesh == pytest.approx(65 * 100 * 0.375 / (2 * math.pi))  # 387.9 Hz
    # The mesh frequency seen from the roller side is the same: z_roller·|f_r − f_c|.
    assert f.gear_mesh == pytest.approx(13 * f.roller_spin)
    assert f.roller_reset is None


def test_paper03_recirculating_numbers():
    # Paper 03 §4: screw 40π rad/s; nut travel in 0.1 s = 2.000 mm, v_n = 20.00 mm/s
    # (docs/validation.md: the paper's 1.996 / 19.79 are simulation readings).
    d = preset("paper03")
    w_s = 40 * math.pi
    r = speed_ratios(d)
    assert r.nut * w_s * 0.1 == pytest.approx(2.000e-3, rel=1e-9)
    assert r.nut * w_s == pytest.approx(20.00e-3, rel=1e-9)
    # Reconstructed geometry (orbit radius 19.75 mm): ω_c = 50.90, ω_r = −268.08 rad/s.
    assert r.carrier * w_s == pytest.approx(50.90, abs=0.005)
    assert r.roller_spin * w_s == pytest.approx(-268.08, abs=0.005)
    f = characteristic_frequencies(d, w_s)
    assert f.gear_mesh is None
    assert f.roller_reset == pytest.approx(d.n_rollers * f.carrier)


def test_frequencies_scale_with_speed_and_ignore_sign():
    d = preset("paper01")
    f1 = characteristic_frequencies(d, 10.0).as_dict()
    f2 = characteristic_frequencies(d, -20.0).as_dict()
    for key, value in f1.items():
        if value is not None:
            assert f2[key] == pytest.approx(2 * value)


def test_defect_frequencies_follow_the_rolling_kinematics():
    import json
    import subprocess
    import sys

    from prsm_health import defect_frequencies

    d = preset("paper01")
    f = characteristic_frequencies(d, 100.0)
    r = speed_ratios(d)
    f_s = 100.0 / (2 * math.pi)
    got = defect_frequencies(d, 100.0)
    # a fixed flank point is passed by every roller; a roller point meets screw and nut per spin
    assert got["screw_flank"] == pytest.approx(7 * (1 - r.carrier) * f_s)
    assert got["nut_flank"] == pytest.approx(7 * r.carrier * f_s)
    assert got["roller_flank"] == pytest.approx(2 * abs(r.roller_spin_relative) * f_s)
    assert got["ring_gear_tooth"] == pytest.approx(7 * f.carrier)
    assert got["roller_gear_tooth"] == pytest.approx(f.roller_spin)
    assert got["carrier"] == pytest.approx(f.carrier)
    assert defect_frequencies(d, -100.0) == got  # magnitudes
    assert "ring_gear_tooth" not in defect_frequencies(preset("paper03"), 100.0)  # no gears
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "prsm_health.apps.cli",
            "kinematics",
            "--design",
            "paper01",
            "--speed",
            "100",
            "--json",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(out.stdout)["defect_frequencies"] == pytest.approx(got)
