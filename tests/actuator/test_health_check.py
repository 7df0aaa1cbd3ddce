"""Health check: phases compiled to the kernel's knots, TOML, errors, the profile's check field."""

import math

import numpy as np
import pytest

from prsm_health.actuator.health_check import (
    BUILT_IN,
    CheckPhase,
    HealthCheck,
    load_check,
)
from prsm_health.actuator.states import OperatingProfile
from prsm_health.core.errors import ParameterError

# paper 01's ratings as load_ratings gives them (rounded): the actuator layer takes the dict
RATINGS = {"C_a": 10456.0, "C_0a": 19478.0}
LEAD = 0.01  # paper 01's screw lead [m/rev]


@pytest.fixture(scope="module")
def check():
    return BUILT_IN["health-check"].resolved(RATINGS)


def test_built_in_holds_the_issue_phases_in_order(check):
    kinds = [(p.motion, p.speed, p.load) for p in check.phases]
    # no-load stroke; low and high speed under one load; slow reversal; highest-load stroke
    assert kinds[0][0] == "constant" and kinds[0][2] == 0.0
    assert kinds[1][0] == kinds[2][0] == "constant" and kinds[1][2] == kinds[2][2] > 0
    assert abs(kinds[1][1]) < abs(kinds[2][1])
    assert kinds[3][0] == "reversing" and kinds[3][2] > 0
    assert kinds[4][0] == "constant"
    # the highest load, on the flanks of the service load (aiding a retraction)
    assert abs(kinds[4][2]) == max(abs(p.load) for p in check.phases)
    assert kinds[4][1] < 0 and kinds[4][2] < 0
    assert 0.2 * RATINGS["C_a"] <= abs(kinds[4][2]) <= 0.3 * RATINGS["C_a"]
    # a few simulated seconds, so that datasets of hundreds of checks stay cheap
    assert 1.0 < check.duration < 4.0
    # ≥ 3 carrier turns (ratio 0.375) in the spall phase for a synchronous average
    turns = abs(kinds[4][1]) * check.phases[4].duration / (2 * math.pi) * 0.375
    assert turns >= 3.0


def test_recorded_phases_and_phase_column(check):
    b = check.recorded().phases
    assert [x.name for x in b] == [p.name for p in check.phases]
    t = 0.0
    for x, p in zip(b, check.phases):
        assert x.start == pytest.approx(t + p.ramp_time)
        assert x.end - x.start == pytest.approx(p.duration)
        t = x.end
    assert check.duration == pytest.approx(t + check.phases[-1].ramp_time)
    times = np.arange(0.0, check.duration, 1e-4)
    phase = check.phase_at(times)
    assert phase.dtype == np.int16 and phase[0] == -1  # the first ramp belongs to no phase
    for x in b:  # each phase one contiguous span, −1 between them
        where = np.flatnonzero(phase == x.index)
        assert times[where[0]] >= x.start and times[where[-1]] < x.end
        assert np.all(np.diff(where) == 1)
    assert set(np.unique(phase)) == {-1, *range(len(b))}


def test_knots_continuous_and_on_the_commanded_speeds(check):
    times, speeds, angles = check.motion_knots()
    assert np.all(np.diff(times) > 0)
    assert times[0] == 0 and speeds[0] == 0  # from rest …
    assert times[-1] == pytest.approx(check.duration) and abs(speeds[-1]) < 1e-9  # … to rest
    # speed continuous: raised-cosine ramps in ≥ 16 pieces move at most ~1/10 of a jump a piece
    jumps = np.abs(np.diff(speeds))
    assert jumps.max() < 0.2 * max(abs(p.speed) for p in check.phases)
    # the angle is the integral of the piecewise-linear speed (what the kernel follows)
    assert np.allclose(np.diff(angles), 0.5 * (speeds[1:] + speeds[:-1]) * np.diff(times))
    # inside each phase the commanded speed holds (constant) or swings ±speed (reversing)
    for x, p in zip(check.recorded().phases, check.phases):
        t = np.linspace(x.start, x.end, 201)
        w = np.interp(t, times, speeds)
        if p.motion == "constant":
            assert np.allclose(w, p.speed)
        else:
            assert w.max() == pytest.approx(p.speed, rel=1e-6)
            assert w.min() == pytest.approx(-p.speed, rel=1e-2)  # 16-piece cosine


def test_loads_resolved_and_resisting_the_motion(check):
    knots, amp, freq = check.load_knots()
    assert amp == freq == 0.0
    times, speeds, _ = check.motion_knots()
    assert np.array_equal(knots[0], times)
    for x, p in zip(check.recorded().phases, check.phases):
        t = np.linspace(x.start, x.end, 101)
        load = np.interp(t, knots[0], knots[1])
        w = np.interp(t, times, speeds)
        # kernel sign: positive resists a positive speed; the phase's load resists its motion
        assert p.speed != 0 and np.allclose(load, p.load * w / abs(p.speed))
    assert np.max(np.abs(knots[1])) == pytest.approx(0.25 * RATINGS["C_a"])


def test_unresolved_check_refuses_load_knots_and_resolves_shares():
    raw = BUILT_IN["health-check"]
    assert not raw.is_resolved
    with pytest.raises(ParameterError, match="shares of a rating"):
        raw.load_knots()
    assert raw.motion_knots().shape[0] == 3  # the motion needs no rating
    with pytest.raises(ParameterError, match="needs a design"):
        raw.resolved(None)
    over = HealthCheck("x", [{"name": "a", "speed": 10.0, "load": "120 % C_0a"}])
    with pytest.raises(ParameterError, match="above the design's static load rating"):
        over.resolved(RATINGS)


def test_strokes_return_within_a_plausible_travel():
    low, high = BUILT_IN["health-check"].travel(LEAD)
    # nut travel = lead × revolutions; the strokes alternate so the nut stays within ±50 mm
    assert -0.05 < low < 0 < high < 0.05


TOML = """
[check]
name = "mine"

[[check.phases]]
name = "stroke"
speed = 40.0
load = "4.4 kN"
duration = 0.1

[[check.phases]]
name = "reversal"
motion = "reversing"
speed = 5.0
load = "20 % C_a"
duration = 0.2
reversal_shape = "linear"
reversal_period = 0.1
"""


def test_toml_round_trip(tmp_path):
    path = tmp_path / "check.toml"
    path.write_text(TOML)
    check = load_check(path)
    assert [p.name for p in check.phases] == ["stroke", "reversal"]
    assert check.phases[0].load == 4400.0 and check.phases[1].load == "20 % C_a"
    assert load_check(check.as_dict()) == check
    assert load_check("health-check") is BUILT_IN["health-check"]
    # a linear reversal is a triangle: the speed reaches −5 rad/s at half a period
    t, w, _ = check.resolved(RATINGS).motion_knots()
    start = check.recorded().phases[1].start
    assert np.interp(start + 0.05, t, w) == pytest.approx(-5.0)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[check]\nname = "x"\nphases = []', "at least one phase"),
        (
            '[check]\nname = "x"\n[[check.phases]]\nname = "a"\nsped = 3',
            r"'sped' in \[check\.phases\[0\] \"a\"\]",
        ),
        (
            '[check]\nname = "x"\n[[check.phases]]\nname = "a"\nduration = -1',
            r"phases\[0\] \"a\"\.duration",
        ),
        ('[check]\nname = "x"\n[[check.phases]]\nname = "a"\nmotion = "jog"', r"\.motion.*jog"),
        ('[check]\nname = "x"\n[[check.phases]]\nname = "a"\nload = "3 lbf"', r"\.load.*lbf"),
        ('[check]\nname = "x"\n[[check.phases]]\nname = "a"\nload = "20 % C_b"', r"C_b"),
    ],
    ids=["no-phases", "unknown-key", "negative-duration", "unknown-motion", "unit", "fraction"],
)
def test_errors_name_the_phase_and_key(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        load_check(path)


def test_profile_takes_the_check():
    p = OperatingProfile(check="health-check")
    assert isinstance(p.check, HealthCheck) and p.duration == pytest.approx(p.check.duration)
    assert np.array_equal(p.motion_knots(), p.check.motion_knots())
    r = p.resolved(RATINGS)
    assert np.array_equal(r.load_knots()[0], r.check.resolved(RATINGS).load_knots()[0])
    assert OperatingProfile(**r.as_dict()) == r  # dict round trip (newtons)
    assert OperatingProfile(**p.as_dict()) == p  # and with the shares kept
    with pytest.raises(ParameterError, match="profile.duration"):
        OperatingProfile(check="health-check", duration=1.0)
    with pytest.raises(ParameterError, match="check"):
        OperatingProfile(check="no-such-check")


def test_phase_object_checks_itself():
    with pytest.raises(ParameterError, match="ramp_time"):
        CheckPhase("a", ramp_time=0.0)
    with pytest.raises(ParameterError, match="unique"):
        HealthCheck("x", [CheckPhase("a"), CheckPhase("a")])
