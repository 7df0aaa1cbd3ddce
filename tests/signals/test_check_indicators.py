"""Health-check indicators on a synthetic check recording: phases found by their condition (not
their name), the values each role reads, the reasons given for what a check or a recording
lacks."""

import math

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.core.check_phases import CheckPhases
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.signals.angle_domain import prsm_periods
from prsm_health.signals.check_indicators import (
    CHECK_INDICATORS,
    ROLE_INDICATORS,
    ROLES,
    check_indicators,
    spectral_centroid,
)
from prsm_health.signals.check_roles import find_roles, phase_conditions

RATE = 10_000.0  # the impact band is then 2–4 kHz
DESIGN = preset("paper01")  # C_a ≈ 10.5 kN: 1000 N is 9.6 %, 2500 N 24 %
RAMP = 0.02
#: (name, motion, speed [rad/s], load [N], duration [s], drive torque [N·m]) — names that
#: say nothing, in an order unlike the built-in check's
PHASES = (
    ("p-alpha", "constant", 100.0, 1000.0, 0.10, 0.5),
    ("p-beta", "reversing", 10.0, 2500.0, 0.30, None),
    ("p-gamma", "constant", 50.0, 0.0, 0.12, 0.2),
    ("p-delta", "constant", -100.0, -2500.0, 0.40, 0.9),
    ("p-epsilon", "constant", -10.0, 1000.0, 0.20, 0.7),
)
CENTROID_TONE = 800.0  # Hz: the no-load phase's axial "resonance"


def _check_run(phases=PHASES, *, record=True, load_cell=False, drop=(), locked=True):
    """A check recording: speed, angle, torque, position, temperature and a nut acceleration
    made per phase; ``record`` False drops motion/speed/load from the check record (an older
    file); ``locked`` False gives the high-load burst's ringing a random phase at each pass."""
    rng = np.random.default_rng(5)
    bounds, t0 = [], 0.0
    for k, (name, motion, speed, load, duration, _) in enumerate(phases):
        start = t0 + RAMP
        bounds.append(
            {"index": k, "name": name, "start": start, "end": start + duration}
            | ({"motion": motion, "speed": speed, "load": load} if record else {})
        )
        t0 = start + duration
    time = np.arange(int((t0 + RAMP) * RATE)) / RATE
    check = CheckPhases.from_record({"name": "synthetic", "phases": bounds})
    phase = check.of_samples(time)
    speed = np.zeros_like(time)
    torque = np.zeros_like(time)
    load = np.zeros_like(time)
    for k, (_, motion, w, f, _, level) in enumerate(phases):
        inside = phase == k
        local = time[inside] - bounds[k]["start"]
        if motion == "reversing":
            shape = np.cos(2 * np.pi * local / 0.15)
            speed[inside], load[inside] = w * shape, f * shape
            torque[inside] = 2.0 * shape
        else:
            speed[inside], load[inside] = w, f * np.sign(w)
            torque[inside] = level * np.sign(w)
    angle = np.cumsum(speed) / RATE
    accel = 1e-3 * rng.standard_normal(len(time))
    gamma = phase == 2
    accel[gamma] += np.sin(2 * np.pi * CENTROID_TONE * time[gamma])
    # high-load phase: a 3 kHz burst locked to the nut-pass angle (a nut spall), 72 cycles
    # per pass, on noise
    delta = phase == 3
    nut_pass = prsm_periods(DESIGN, 3.0)["nut_pass"]
    u = np.mod(-angle[delta], nut_pass) / nut_pass
    ringing = 2 * np.pi * 72 * u
    if not locked:  # the resonance an impact rings is not phase-locked to the angle
        passes = np.floor(-angle[delta] / nut_pass).astype(int)
        ringing += rng.uniform(0, 2 * np.pi, passes.max() - passes.min() + 1)[passes - passes.min()]
    accel[delta] += np.exp(-(((u - 0.5) / 0.05) ** 2)) * np.sin(ringing)
    accel[delta] += 0.05 * rng.standard_normal(int(delta.sum()))
    channels = {
        "screw_angle": angle,
        "screw_speed": speed,
        "drive_torque": torque,
        "nut_position": speed_ratios(DESIGN).nut * angle,
        "nut_axial_accel": accel,
        "housing_temperature": np.full_like(time, 310.0),
    }
    if load_cell:
        channels["axial_load"] = load
    for name in drop:
        channels.pop(name)
    return Run(
        time,
        channels,
        RATE,
        check_phase=phase,
        check=check,
        operating=OperatingPoint(design="paper01", gear_ratio=3.0),
    )


@pytest.fixture(scope="module")
def reading():
    return check_indicators(_check_run(), DESIGN)


def test_roles_found_by_condition_not_name(reading):
    assert reading.roles == {
        "no_load": "p-gamma",
        "torque_pair": "p-epsilon / p-alpha",  # the slow phase first
        "reversal": "p-beta",
        "high_load": "p-delta",
    }
    assert reading.missing == {}
    assert list(reading.indicators) == list(CHECK_INDICATORS)
    assert set().union(*ROLE_INDICATORS.values()) == set(CHECK_INDICATORS)


def test_torque_ratio_temperature_and_centroid(reading):
    values = reading.indicators
    # constant torque levels: the means are exact
    assert values["check_torque_low"] == pytest.approx(0.7, rel=1e-12)
    assert values["check_torque_high"] == pytest.approx(0.5, rel=1e-12)
    assert values["check_torque_ratio"] == pytest.approx(1.4, rel=1e-12)
    assert values["check_temperature"] == pytest.approx(310.0, rel=1e-12)
    # a tone of amplitude 1 over noise 1e-3: the centroid is the tone's frequency, to the
    # asymmetry of the Hann leakage about it (bins of 19.5 Hz; measured < 1 Hz); ± 5 Hz
    assert values["check_noload_centroid"] == pytest.approx(CENTROID_TONE, abs=5.0)
    assert values["check_noload_rms"] == pytest.approx(1 / math.sqrt(2), rel=0.02)
    # reversal indicators read (lost motion of a rigid nut: the LVDT follows the angle)
    assert values["check_reversal_torque_rattle_rate"] > 0
    assert values["check_reversal_lost_motion"] == pytest.approx(0.0, abs=1e-9)
    assert values["check_reversal_lost_motion_step"] == pytest.approx(0.0, abs=1e-9)
    assert math.isnan(values["check_reversal_efficiency"])  # no load cell


def test_high_load_phase_reads_a_nut_pass_burst(reading):
    values = reading.indicators
    # the burst repeats every nut pass, angle-locked: nearly all its band energy is periodic
    # at the nut pass (SNR ≫ 1); at the roller spin (7 nut passes = 5 spins) it is not, and
    # the screw and carrier averages see it only through the common orders
    assert values["check_highload_snr_nut_pass"] > 5.0
    assert values["check_highload_snr_roller_spin"] < 0.5 * values["check_highload_snr_nut_pass"]
    assert values["check_highload_kurtosis"] > 4.0  # bursts: peaky
    assert values["check_highload_crest"] > 3.0
    assert np.isfinite(values["check_highload_position_snr"])
    assert values["check_highload_position_contrast"] >= 1.0


def test_envelope_averages_keep_an_impact_train_whose_ringing_is_not_phase_locked(reading):
    locked = reading.indicators
    unlocked = check_indicators(_check_run(locked=False), DESIGN).indicators
    # locked: both averages see the burst at the nut pass
    assert locked["check_highload_envelope_snr_nut_pass"] > 5.0
    # a random ringing phase per pass: the waveform's average cancels (its expected SNR is
    # the burst's energy left over n passes, ≈ 1/n of the locked one's, n ≈ 40 passes here)
    # while the squared envelope — the Gaussian window squared, the same at every pass —
    # stays periodic; noise 0.05 against a burst of 1: the envelope SNR stays ≫ 1
    assert unlocked["check_highload_snr_nut_pass"] < 0.1 * locked["check_highload_snr_nut_pass"]
    assert unlocked["check_highload_envelope_snr_nut_pass"] > 5.0
    # (not equal to the locked one: the filter's edge reshapes a burst whose phase jumps)
    assert (
        unlocked["check_highload_envelope_snr_nut_pass"]
        > 0.5 * (locked["check_highload_envelope_snr_nut_pass"])
    )
    # at the roller spin (5 spins = 7 nut passes) the envelope is not periodic either
    assert (
        unlocked["check_highload_envelope_snr_roller_spin"]
        < 0.5 * (unlocked["check_highload_envelope_snr_nut_pass"])
    )


def test_missing_phases_say_which_condition_is_absent():
    without = [p for p in PHASES if p[1] != "reversing" and p[3] != 0.0]
    reading = check_indicators(_check_run(tuple(without)), DESIGN)
    assert reading.missing["reversal"] == "no reversing phase under load"
    assert reading.missing["no_load"].startswith("no constant-speed phase without load")
    for role in ("reversal", "no_load"):
        assert role not in reading.roles
        assert all(math.isnan(reading.indicators[k]) for k in ROLE_INDICATORS[role] if k)
    # one speed under each load: no torque pair
    one_speed = [p for p in PHASES if p[0] != "p-epsilon"]
    reading = check_indicators(_check_run(tuple(one_speed)), DESIGN)
    assert reading.missing["torque_pair"] == (
        "no two constant-speed phases under one load at different speeds"
    )
    assert math.isnan(reading.indicators["check_torque_ratio"])


def test_missing_channels_are_named_and_give_nan():
    reading = check_indicators(_check_run(drop=("nut_axial_accel",)), DESIGN)
    assert reading.roles["no_load"] == "p-gamma"
    assert reading.missing["no_load"] == "missing channel(s) nut_axial_accel"
    assert reading.missing["high_load"] == "missing channel(s) nut_axial_accel"
    assert all(math.isnan(reading.indicators[k]) for k in ROLE_INDICATORS["high_load"])
    assert reading.indicators["check_torque_ratio"] == pytest.approx(1.4)


def test_an_older_record_falls_back_to_the_measured_condition():
    # no motion, speed or load in the record: the motion from the speed's sign changes, no
    # load known — so no no-load phase, no pair, no high-load phase; the reversal counts
    conditions = phase_conditions(_check_run(record=False))
    assert [c.motion for c in conditions] == [p[1] for p in PHASES]
    assert [c.load for c in conditions] == [None] * len(PHASES)
    assert conditions[3].speed == pytest.approx(-100.0)
    reading = check_indicators(_check_run(record=False), DESIGN)
    assert reading.roles == {"reversal": "p-beta"}
    assert "known load" in reading.missing["no_load"]
    # a load cell gives the loads back (resisting the motion: the sign of the record's)
    # (constant: the mean, exact; reversing: the 95th percentile of |load| over whole periods
    # of a cosine swing, sin(0.475π) = 0.9969 of the amplitude)
    with_cell = phase_conditions(_check_run(record=False, load_cell=True))
    for condition, p in zip(with_cell, PHASES):
        expected = p[3] * (math.sin(0.475 * math.pi) if p[1] == "reversing" else 1.0)
        assert condition.load == pytest.approx(expected, rel=1e-3, abs=1e-6)
    reading = check_indicators(_check_run(record=False, load_cell=True), DESIGN)
    assert set(reading.roles) == set(ROLES)


def test_find_roles_picks_the_largest_speed_ratio_and_the_largest_load():
    conditions = phase_conditions(_check_run())
    found, missing = find_roles(conditions, rating=1e4)
    assert found["high_load"].name == "p-delta" and not missing
    # with a rating so small that every load is "no load" except none: all constant phases
    # unloaded → no pair, no high load, and the longest unloaded phase is the no-load one
    found, missing = find_roles(conditions, rating=1e9)
    assert found["no_load"].name == "p-delta"
    assert "high_load" in missing and "torque_pair" in missing


def test_no_check_gives_all_roles_missing():
    run = _check_run()
    plain = Run(run.time, run.channels, run.sample_rate, operating=run.operating)
    reading = check_indicators(plain, DESIGN)
    assert reading.roles == {}
    assert set(reading.missing) == set(ROLES)
    assert all(math.isnan(v) for v in reading.indicators.values())
    assert math.isnan(spectral_centroid(np.zeros(100), RATE))
