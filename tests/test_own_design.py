"""One's own actuator end to end: a design file (not a preset) travels with its data — recipe →
dataset (manifest, run labels) → indicators → a fleet → a prognostics model of that design.

Runs are short (0.2 s; fleet snapshots 0.05 s) and few; nothing here depends on the exact
trajectory of a run: the design-dependent indicator checked against the design is the healthy
axial baseline frequency, a function of the design and the measured mean load only.
"""

import math
import textwrap
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.design_files import design_fingerprint, design_to_toml, same_design
from prsm_health.core.errors import ParameterError, PRSMHealthError
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.datasets import Dataset, generate, load_recipe
from prsm_health.prognostics import cross_validate_units, fit_prognostics_model, prognose
from prsm_health.signals.features import dataset_features, extract_features

BASE = preset("paper01")
#: paper01 renamed, with a nut twice as heavy: its axial baseline frequency is 1/√2 of paper01's.
MINE = BASE.with_(
    name="acme-ema-24", masses=replace(BASE.masses, nut_mass=2 * BASE.masses.nut_mass)
)

RECIPE = textwrap.dedent(
    """
    name = "own"
    design = "mine.toml"
    duration = 0.2
    sample_rate = 20000
    instrumentation = "ideal"
    seed = 5
    batch_size = 2
    test_fraction = 0.25
    [profile]
    load_profile = "reversing"
    [sweep]
    clearance = [5e-6, 20e-6]
    speed = [100.0]
    load_amplitude = [300.0]
    repeats = 2
    """
)

FLEET = textwrap.dedent(
    """
    name = "own-fleet"
    design = "mine.toml"
    duration = 0.05
    sample_rate = 20000
    instrumentation = "ideal"
    seed = 3
    test_fraction = 0.25
    [profile]
    load_profile = "reversing"
    [options]
    contact_law = "hertz"
    max_step = "auto"
    [sweep]
    mode = "random"
    speed = [60.0, 120.0]
    load_amplitude = [300.0, 2000.0]
    [life]
    units = 4
    snapshots = 3
    """
)


def _write(folder, recipe_text: str):
    (folder / "mine.toml").write_text(design_to_toml(MINE))
    path = folder / "recipe.toml"
    path.write_text(recipe_text)
    return path


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    folder = tmp_path_factory.mktemp("own")
    generate(load_recipe(_write(folder, RECIPE)), folder / "ds", workers=1, progress=False)
    return Dataset(folder / "ds")


def test_the_dataset_carries_its_design(dataset):
    assert dataset.design == MINE  # the name too
    fingerprint = design_fingerprint(MINE)
    assert dataset.manifest["design"] == {"name": "acme-ema-24", "fingerprint": fingerprint}
    assert set(dataset.runs["design"]) == {"acme-ema-24"}
    assert set(dataset.runs["design_fingerprint"]) == {fingerprint}
    assert fingerprint != design_fingerprint("paper01")


def test_indicators_of_a_dataset_of_ones_own_design(dataset):
    table = dataset_features(dataset)
    assert len(table) == 4
    for name in ("axial_baseline_frequency", "mesh_frequency"):
        assert np.isfinite(table[name]).all(), name
    # the design itself was used, not paper01: the baseline √(k/m_N)/2π of the same measured
    # load with the nut twice as heavy (same threads, same k) is paper01's / √2
    run = dataset.run(int(table["run_id"].iloc[0]), truth=False)
    paper01 = extract_features(run, "paper01")["axial_baseline_frequency"]
    assert table["axial_baseline_frequency"].iloc[0] == pytest.approx(
        paper01 / math.sqrt(2), rel=1e-9
    )


def test_a_run_of_ones_own_design_needs_no_design_argument(dataset):
    run = dataset.run(0, truth=False)
    by_itself = extract_features(run)
    given = extract_features(run, MINE)
    assert by_itself["axial_baseline_frequency"] == given["axial_baseline_frequency"]
    # a simulated run's scenario holds the design's dict form, its operating point the name
    simulated = Run(
        run.time,
        run.channels,
        run.sample_rate,
        scenario={"design": MINE.to_dict()},
        operating=run.operating,
    )
    assert extract_features(simulated)["axial_baseline_frequency"] == pytest.approx(
        given["axial_baseline_frequency"], rel=1e-12
    )


def test_a_run_known_only_by_an_unknown_name_says_what_to_pass(dataset, tmp_path):
    run = dataset.run(0, truth=False)
    bare = Run(
        run.time, run.channels, run.sample_rate, operating=OperatingPoint(design="acme-ema-24")
    )
    with pytest.raises(PRSMHealthError) as info:
        extract_features(bare)
    assert str(info.value) == (
        "run of design 'acme-ema-24' carries no design and it is not a preset: "
        "pass design=<PRSMDesign or design file>"
    )
    # the design file given: works
    path = tmp_path / "mine.toml"
    path.write_text(design_to_toml(MINE))
    assert np.isfinite(extract_features(bare, path)["axial_baseline_frequency"])
    assert np.isfinite(extract_features(bare, MINE.to_dict())["axial_baseline_frequency"])


def test_a_prognostics_model_for_a_fleet_of_ones_own_design(tmp_path):
    generate(load_recipe(_write(tmp_path, FLEET)), tmp_path / "fleet", workers=1, progress=False)
    fleet = Dataset(tmp_path / "fleet")
    assert same_design(fleet.design, MINE)
    # the shipped diagnosis model is for paper01: its diagnoses of this fleet are refused
    with pytest.raises(PRSMHealthError, match="diagnosis model is for design 'paper01'"):
        fit_prognostics_model(fleet)
    # histories as a diagnosis of this design would give them: the true clearance ± 0.3 µm
    labels = fleet.runs.sort_values(["unit_id", "age_hours"])
    rng = np.random.default_rng(0)
    value = labels["clearance_mean_true"].to_numpy() + 0.3e-6 * rng.standard_normal(len(labels))
    histories = pd.DataFrame(
        {
            "unit_id": labels["unit_id"].to_numpy(),
            "age_hours": labels["age_hours"].to_numpy(),
            "clearance": value,
            "clearance_lower": value - 0.5e-6,
            "clearance_upper": value + 0.5e-6,
            **{
                k: labels[k].to_numpy()
                for k in ("design", "design_fingerprint", "split", "failure_age_hours")
            },
        }
    )
    model, report = fit_prognostics_model(fleet, histories=histories, n_samples=200)
    assert model.design_id == ("acme-ema-24", design_fingerprint(MINE))
    assert report.threshold_learnt and report.threshold > 0
    assert len(report.train_units) == 3 and len(report.test_units) == 1
    # the physics method too: its rates are the own design's (the fleet's [life] recipe)
    assert set(report.summary) == {"degradation", "similarity", "physics"}
    unit = histories[histories["unit_id"] == report.test_units[0]]
    assert prognose(unit.drop(columns="unit_id"), model).rul_hours["estimate"] >= 0
    physics = prognose(unit.drop(columns="unit_id"), model, method="physics")
    assert physics.model["name"] == "physics" and physics.rul_hours["estimate"] >= 0
    # a paper01 history is another design
    with pytest.raises(PRSMHealthError, match="another design"):
        prognose(unit.assign(design_fingerprint=design_fingerprint("paper01")), model)
    # every unit scored by a model that never saw it: one unit per fold here (the physics
    # method's predictions are the costly part: scored above)
    predictions, summary = cross_validate_units(
        fleet, histories, folds=4, methods=("degradation", "similarity"), n_samples=200
    )
    assert set(summary) == {"degradation", "similarity"}
    assert predictions.groupby("unit_id")["fold"].nunique().eq(1).all()
    assert sorted(predictions["unit_id"].unique()) == sorted(histories["unit_id"].unique())
    assert all(s["n_units"] == 4 for s in summary.values())
    with pytest.raises(ParameterError, match="folds"):
        cross_validate_units(fleet, histories, folds=2)  # 2 training units a fold
