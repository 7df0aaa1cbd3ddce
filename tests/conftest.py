"""Shared fixtures: the documented reversing-load recording, built in one place.

Tests marked ``slow`` (registered in pyproject.toml) train models or simulate seconds of signal;
``pytest -m "not slow"`` runs the rest in a couple of minutes.
"""

import functools
import os

# One OpenMP thread for the boosted trees: the models here are small, and with more threads
# than free cores (parallel jobs, a loaded CI machine) OpenMP spin-waiting made single tests
# take minutes (one took 543 s with helpers running). Set before scikit-learn loads its runtime.
os.environ.setdefault("OMP_NUM_THREADS", "1")

import pytest  # noqa: E402

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate  # noqa: E402
from prsm_health.actuator.health_check import CheckPhase, HealthCheck  # noqa: E402

#: The regime in which the clearance is observable (docs/validation.md): a ±300 N load
#: reversing at 10 Hz with 2 ms edges around a zero mean, Hertzian thread flanks.
REVERSING_LOAD = dict(
    load=0.0, load_profile="reversing", load_amplitude=300.0, load_frequency=10.0, accel_time=0.002
)


@functools.lru_cache(maxsize=32)
def _reversing_run(clearance, duration, seed, speed, sample_rate, overrides):
    profile = {**REVERSING_LOAD, **dict(overrides)}
    return simulate(
        "paper01",
        HealthState.uniform(clearance),
        OperatingProfile(duration=duration, speed=speed, **profile),
        {"profile": "ideal", "sample_rate": sample_rate},
        seed,
        options=SimulationOptions(contact_law="hertz"),
    )


@pytest.fixture(scope="session")
def reversing_run():
    """Factory ``reversing_run(clearance, duration=0.4, seed=9, speed=100.0, **profile)`` → Run.

    Runs are cached for the session (same arguments, same object): do not modify them.
    """

    def make(clearance, duration=0.4, seed=9, speed=100.0, sample_rate=20_000.0, **profile):
        return _reversing_run(
            clearance, duration, seed, speed, sample_rate, tuple(sorted(profile.items()))
        )

    return make


# A short check with every role (1.0 s instead of the built-in 2.07 s, to keep the test cheap):
# the built-in's conditions, shorter settled parts.
SHORT_CHECK = HealthCheck(
    "short-check",
    (
        CheckPhase("quiet", "constant", speed=50.0, load=0.0, duration=0.1, ramp_time=0.02),
        CheckPhase("slow", "constant", speed=-10.0, load="10 % C_a", duration=0.1, ramp_time=0.02),
        CheckPhase("fast", "constant", speed=100.0, load="10 % C_a", duration=0.06, ramp_time=0.02),
        CheckPhase(
            "swing",
            "reversing",
            speed=10.0,
            load="25 % C_a",
            duration=0.25,
            ramp_time=0.02,
            reversal_period=0.125,
        ),
        CheckPhase(
            "heavy", "constant", speed=-100.0, load="-25 % C_a", duration=0.3, ramp_time=0.02
        ),
    ),
)


@functools.lru_cache(maxsize=8)
def _short_check_run(clearance, seed):
    health = None if clearance is None else HealthState.uniform(clearance)
    return simulate("paper01", health, OperatingProfile(check=SHORT_CHECK), "flight-ema", seed)


@pytest.fixture(scope="session")
def short_check_run():
    """Factory ``short_check_run(clearance=None, seed=4)`` → a recording of :data:`SHORT_CHECK`
    (flight-ema sensors; None: the default health state). Cached for the session: do not
    modify the runs."""

    def make(clearance=None, seed=4):
        return _short_check_run(clearance, seed)

    return make
