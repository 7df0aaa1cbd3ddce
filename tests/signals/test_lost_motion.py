"""The lost-motion step over the settled samples of a reversal: the whole play, where the step
over every sample reads the crossings as part of it."""

import math

import numpy as np
import pytest

from prsm_health.signals.lost_motion import (
    SETTLED_SHARE,
    lost_motion_step,
    settled_lost_motion_step,
)

LEAD = 10e-3 / (2 * math.pi)


def reversal(play=40e-6, crossing=0.02, rate=20_000.0, duration=0.5, period=0.25):
    """A cosine reversal whose nut lags by ±play/2 with the direction, crossing the play in
    ``crossing`` seconds after each reversal (linearly), as a nut pushed slowly across it."""
    t = np.arange(0.0, duration, 1.0 / rate)
    speed = 10.0 * np.cos(2 * np.pi * t / period)
    angle = np.cumsum(speed) / rate
    side = np.sign(speed)
    # time since the last sign change of the speed
    changes = np.flatnonzero(np.diff(side) != 0) + 1
    since = np.full(t.shape, np.inf)
    for k in changes:
        since[k:] = t[k:] - t[k]
    progress = np.clip(since / crossing, 0.0, 1.0)
    lag = side * play / 2 * (2 * progress - 1)
    lag[since == np.inf] = side[since == np.inf] * play / 2
    return LEAD * angle + lag, angle, speed


def test_the_settled_step_reads_the_whole_play():
    position, angle, speed = reversal()
    every = lost_motion_step(position, angle, LEAD, np.sign(speed))
    settled, shares = settled_lost_motion_step(position, angle, speed, LEAD)
    # the crossings (0.02 s of each 0.125 s branch) pull the step over every sample down
    assert every < 0.9 * 40e-6
    assert settled == pytest.approx(40e-6, rel=1e-3)
    assert shares.min() >= SETTLED_SHARE - 1e-9 and shares.max() == pytest.approx(1.0)


def test_no_speed_or_one_side_reads_nothing():
    position, angle, speed = reversal()
    step, shares = settled_lost_motion_step(position, angle, np.zeros_like(speed), LEAD)
    assert math.isnan(step) and shares.size == 0
    step, shares = settled_lost_motion_step(position, angle, np.abs(speed), LEAD)
    assert math.isnan(step) and shares.size == 0
