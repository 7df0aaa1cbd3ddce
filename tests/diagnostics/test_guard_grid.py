"""A model trained on a speed grid (80 and 100 rad/s) diagnoses a recording between the grid's
speeds in distribution, and one beyond them as "cannot tell", naming the factor and what to
sweep (issue 44: the guard interpolates, the model does not extrapolate)."""

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.datasets import Recipe, generate
from prsm_health.diagnostics.diagnosis import OOD_LIMIT, diagnose, load_bundle
from prsm_health.simulation.scenario import SimulationOptions
from prsm_health.training.train import train

PROFILE = dict(
    load_profile="reversing", load_amplitude=1000.0, load_frequency=10.0, accel_time=0.002
)
GRID = dict(
    name="speed-grid",
    design="paper01",
    duration=0.2,
    sample_rate=5000,
    instrumentation="flight-ema",
    seed=3,
    test_fraction=0.25,
    options={"contact_law": "hertz"},
    profile=PROFILE,
    sweep=dict(clearance=[4e-6, 12e-6, 20e-6, 28e-6], speed=[80.0, 100.0], repeats=4),
)


def _recording(speed, seed):
    return simulate(
        "paper01",
        HealthState.uniform(15e-6),
        OperatingProfile(duration=0.2, speed=speed, **PROFILE),
        {"profile": "flight-ema", "sample_rate": 5000},
        seed,
        options=SimulationOptions(contact_law="hertz"),
    )


@pytest.mark.slow  # 32 runs of 0.2 s, a model trained, 6 recordings: ≈ 30 s
def test_a_speed_grid_model_reads_between_its_speeds_and_refuses_beyond(tmp_path):
    generate(Recipe.from_dict(GRID), tmp_path / "grid", workers=1, progress=False)
    train(tmp_path / "grid", tmp_path / "grid.skops", target="clearance", cv=3, progress=False)
    bundle = load_bundle(tmp_path / "grid.skops")
    assert bundle.guard.n_between_ > 0  # midpoints between the two speeds' windows
    # 90 rad/s, between the levels: in distribution (the median over three recordings: a
    # reversing load's impacts make each window's score scatter; measured 0.57–0.71 here)
    between = [diagnose(_recording(90.0, seed), bundle) for seed in (21, 22, 23)]
    assert np.median([d.ood_score for d in between]) <= OOD_LIMIT
    assert not any("outside the trained" in w for d in between for w in d.warnings)
    # 150 rad/s, beyond them: cannot tell, and why — the factor, its range, what to sweep
    beyond = diagnose(_recording(150.0, 21), bundle)
    assert beyond.observability["clearance"] == 0.0
    said = [w for w in beyond.warnings if "outside the trained speed range" in w]
    assert said and "[sweep] speed covers 150" in said[0] and "79.99 … 100 rad/s" in said[0]
    span = bundle.metadata["clearance_range"]  # no reading: the whole trained range
    assert [beyond.clearance["lower"], beyond.clearance["upper"]] == pytest.approx(span)
