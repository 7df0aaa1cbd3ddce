"""The rollers as assembled: each roller's manufacturing draws from a unit's seed, its share of
uneven wear, and the play the assembly adds by taking up the rollers' pitch errors.

One place for the draws, so the dynamics (which build a run's rollers from them) and the life
model (which needs the clearance the installed unit shows) read the same unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The variation stream's key ("PRSM"): a run's as-built draws come from [seed, this].
VARIATION_STREAM = 0x5052534D


def variation_stream(seed: int) -> np.random.Generator:
    """The generator of a unit's as-built draws (its seed's variation stream)."""
    return np.random.default_rng([seed, VARIATION_STREAM])


@dataclass(frozen=True)
class RollerDraws:
    """A unit's per-roller random draws, in the order the variation stream gives them.

    Attributes
    ----------
    normal : ndarray (6, n)
        Standard normals: pocket angle, pocket radius, screw- and nut-side pitch error,
        transmission error, mesh stiffness (each scaled by its
        :class:`~prsm_health.actuator.states.ManufacturingVariation` tolerance).
    wear : ndarray (n,)
        Each roller's share of uneven wear in [−1, 1], mean zero: uneven load sharing moves
        wear between rollers, it does not make the unit as a whole wear more or less (the
        mean clearance is the wear model's, :mod:`prsm_health.physics.wear`).
    runout : ndarray (n,)
        |standard normal|: each roller's thread runout scale.
    runout_phase : ndarray (n,) [rad]
    """

    normal: np.ndarray
    wear: np.ndarray
    runout: np.ndarray
    runout_phase: np.ndarray

    @classmethod
    def draw(cls, rng: np.random.Generator, n_rollers: int) -> RollerDraws:
        """Draw from ``rng`` (advancing it: the stream's later draws follow these)."""
        normal = rng.standard_normal((6, n_rollers))
        uniform = rng.uniform(-1.0, 1.0, n_rollers)
        runout = np.abs(rng.standard_normal(n_rollers))
        runout_phase = rng.uniform(0.0, 2 * math.pi, n_rollers)
        return cls(normal, mean_preserving(uniform), runout, runout_phase)

    def pitch_errors(self, variation) -> tuple[np.ndarray, np.ndarray]:
        """Each roller's axial thread position error against screw and nut [m]."""
        return variation.pitch_error * self.normal[2], variation.pitch_error * self.normal[3]

    def take_up(self, variation) -> np.ndarray:
        """The half-clearance each roller gains at assembly [m]: a new screw (b = 0) has no
        interference, so a roller whose thread sits Δe off the others' mean gets |Δe|/2 more
        play on each thread side."""
        screw, nut = self.pitch_errors(variation)
        pitch = screw + nut
        return 0.5 * np.abs(pitch - np.mean(pitch))


def mean_preserving(uniform: np.ndarray) -> np.ndarray:
    """A wear pattern of mean zero within [−1, 1] from uniform draws in [−1, 1]: centred, then
    scaled down only where centring pushed a roller beyond ±1."""
    centred = uniform - np.mean(uniform)
    return centred / max(1.0, float(np.max(np.abs(centred))))


def assembly_play(seed: int, n_rollers: int, variation) -> float:
    """The mean half-clearance [m] the assembly adds to a unit built from ``seed``: the rollers'
    mean :meth:`RollerDraws.take_up`. The installed unit's clearance is its threads' mean
    half-clearance plus this (what its zero-load lost motion reads, ÷ 4)."""
    draws = RollerDraws.draw(variation_stream(seed), n_rollers)
    return float(np.mean(draws.take_up(variation)))
