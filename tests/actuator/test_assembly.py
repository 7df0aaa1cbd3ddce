"""The rollers as assembled: a mean-preserving uneven-wear pattern, the pitch errors' take-up,
and the same draws for the dynamics and the life model."""

import numpy as np
import pytest

from prsm_health.actuator.assembly import (
    RollerDraws,
    assembly_play,
    mean_preserving,
    variation_stream,
)
from prsm_health.actuator.states import ManufacturingVariation


@pytest.mark.parametrize("seed", range(20))
def test_the_wear_pattern_keeps_the_mean_and_its_range(seed):
    wear = RollerDraws.draw(variation_stream(seed), 7).wear
    assert abs(np.mean(wear)) < 1e-15
    assert np.max(np.abs(wear)) <= 1.0 + 1e-15


def test_centring_scales_down_only_past_the_bounds():
    inside = np.array([0.5, -0.5, 0.2, -0.2])
    assert mean_preserving(inside) == pytest.approx(inside)
    pushed = mean_preserving(np.array([1.0, 1.0, 1.0, -1.0]))  # centred: ±1.5 scaled to ±1
    assert np.mean(pushed) == pytest.approx(0.0, abs=1e-15)
    assert np.max(np.abs(pushed)) == pytest.approx(1.0)


def test_the_take_up_is_half_each_rollers_pitch_offset():
    draws = RollerDraws.draw(variation_stream(4), 5)
    variation = ManufacturingVariation(pitch_error=3e-6)
    screw, nut = draws.pitch_errors(variation)
    pitch = screw + nut
    assert draws.take_up(variation) == pytest.approx(0.5 * np.abs(pitch - pitch.mean()))
    assert assembly_play(4, 5, variation) == pytest.approx(np.mean(draws.take_up(variation)))
    # scales with the tolerance, zero for an ideal build
    assert assembly_play(4, 5, ManufacturingVariation(pitch_error=6e-6)) == pytest.approx(
        2 * assembly_play(4, 5, variation)
    )
    assert assembly_play(4, 5, ManufacturingVariation.ideal()) == 0.0
