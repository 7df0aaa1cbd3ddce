"""prsm_health.training.train: datasets too small to train on, the model-file suffix, useless models.

Generating runs is the expensive part, so one tiny dataset (8 runs of 0.1 s at 5 kHz) is
generated per module; it is too small to train on, which is what the refusal tests need. The
useless-model test replaces the indicators by constants (no simulation, nothing to learn).
"""

import gc
import json
import shutil
import warnings

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.states import HealthState
from prsm_health.apps.cli import main
from prsm_health.core.errors import PRSMHealthError
from prsm_health.datasets import Dataset, FaultThresholds, Recipe, generate
from prsm_health.diagnostics.model_files import load_model
from prsm_health.signals.features import FEATURES
from prsm_health.training import train as training
from prsm_health.training.train import (
    calibration_minimums,
    fit_minimum,
    operating_point,
    train,
    training_problems,
)

TINY = dict(
    name="train-tiny",
    design="paper01",
    duration=0.1,
    sample_rate=5000,
    instrumentation="ideal",
    seed=7,
    test_fraction=0.25,
    profile=dict(
        load_profile="reversing", load_amplitude=300.0, load_frequency=10.0, accel_time=0.002
    ),
    sweep=dict(clearance=[2e-6, 34e-6], speed=[60.0, 100.0], friction_scale=[1.0, 2.2]),
)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("train") / "tiny"
    generate(Recipe.from_dict(TINY), out, workers=1, progress=False)
    return out


def labels_table(n_train, n_test, *, seed=0, classes=None):
    """A runs table like runs.parquet: distinct operating points, classes by the thresholds."""
    rng = np.random.default_rng(seed)
    n = n_train + n_test
    clearance = rng.uniform(0.0, 40e-6, n)
    friction = rng.choice([1.0, 2.2], n)
    faults = FaultThresholds()
    return pd.DataFrame(
        {
            "run_id": np.arange(n),
            "split": ["train"] * n_train + ["test"] * n_test,
            "fault_class": classes
            if classes is not None
            else [
                faults.classify(HealthState.uniform(c, friction_scale=f))
                for c, f in zip(clearance, friction)
            ],
            "design": "paper01",
            "clearance_screw": clearance,
            "clearance_nut": clearance,
            "clearance_gear": 0.0,
            "wear_spread": 0.0,
            "friction_scale": friction,
            "screw_speed": 80.0,
            "axial_load": 0.0,
            "load_amplitude": 300.0,
        }
    )


# ------------------------------------------------------------------------------------------
# training_problems: labels only, no fitting
# ------------------------------------------------------------------------------------------


def test_a_large_enough_table_has_no_problems():
    assert training_problems(labels_table(60, 20), target="both", cv=5) == []


def test_problems_name_the_minimum_and_the_fix():
    usable, guaranteed = calibration_minimums(0.1, 0.25)
    assert (usable, guaranteed) == (14, 35)
    table = labels_table(10, 3)
    problems = training_problems(table, target="both", cv=5)
    text = " | ".join(problems)
    assert f"10 training runs, a calibrated 90 % interval needs ≥ {usable}" in text
    assert "5-fold CV needs ≥ 5" in text and "add runs (sweep.repeats)" in text
    # clearance alone: only the interval minimum; a class count is not a clearance problem
    (only,) = training_problems(table, target="clearance", cv=2)
    assert only.startswith("clearance target: 10 training runs") and "add runs" in only


def test_one_short_class_names_its_count_and_the_usable_cv():
    table = labels_table(40, 10, classes=["wear"] * 20 + ["healthy"] * 17 + ["severe_wear"] * 13)
    (problem,) = training_problems(table, target="fault", cv=5)
    assert problem == (
        "fault target: class 'severe_wear' has 3 training runs, 5-fold CV needs ≥ 5 per class: "
        "add runs (sweep.repeats) or lower --cv to 3"
    )


def test_no_test_split_single_class_bad_cv_and_few_points():
    table = labels_table(40, 0, classes=["healthy"] * 40)
    problems = training_problems(table, target="fault", cv=1)
    assert any(p.startswith("--cv 1") for p in problems)
    assert any("no held-out runs" in p and "test_fraction > 0" in p for p in problems)
    assert any("every training run has class 'healthy'" in p for p in problems)
    same_point = labels_table(40, 10).assign(clearance_screw=1e-5, clearance_nut=1e-5)
    same_point["friction_scale"] = 1.0
    problems = training_problems(same_point, target="clearance", cv=3)
    assert any("1 distinct operating point(s), 3-fold CV" in p for p in problems)
    assert any("same clearance (10 µm)" in p for p in problems)


# ------------------------------------------------------------------------------------------
# train: refusals before any work
# ------------------------------------------------------------------------------------------


def test_train_refuses_a_too_small_dataset_before_fitting(tiny, tmp_path, monkeypatch):
    def no_features(*args, **kwargs):
        raise AssertionError("features extracted before the size check")

    monkeypatch.setattr(training, "dataset_features", no_features)
    with pytest.raises(PRSMHealthError) as err:
        train(tiny, tmp_path / "m.skops", cv=5, progress=False)
    message = str(err.value)
    assert "\n" not in message and message.startswith(f"{tiny}: cannot train: ")
    assert "needs ≥ 14" in message and "5-fold CV needs ≥ 5" in message
    assert not (tmp_path / "m.skops").exists()


def test_train_requires_the_skops_suffix(tmp_path):
    # checked first: the dataset directory does not even exist
    with pytest.raises(PRSMHealthError, match=r"m\.pkl: a model file must end in \.skops"):
        train(tmp_path / "no-dataset", tmp_path / "m.pkl")
    with pytest.raises(PRSMHealthError, match=r"\.skops"):
        train(tmp_path / "no-dataset", tmp_path / "m")


def test_cli_train_bad_suffix_is_one_error_line(tiny, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["train", str(tiny), "--out", "x.pkl"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and ".skops" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.pkl").exists()


def test_cli_train_too_small_is_one_error_line(tiny, tmp_path, capsys):
    assert main(["train", str(tiny), "--out", str(tmp_path / "m.skops")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "cannot train" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


# ------------------------------------------------------------------------------------------
# A useless model is reported as such
# ------------------------------------------------------------------------------------------


def test_useless_model_is_reported_not_dressed_up(tiny, tmp_path, monkeypatch):
    # The tiny dataset's manifest, a larger runs table, and indicators that are all constant:
    # the models can learn nothing, so they answer one value and one class.
    ds_dir = tmp_path / "constant"
    ds_dir.mkdir()
    shutil.copy(tiny / "manifest.json", ds_dir / "manifest.json")
    labels_table(32, 10).to_parquet(ds_dir / "runs.parquet")

    def constant_features(dataset, progress=False):
        runs = dataset.runs.reset_index(drop=True)
        return pd.concat(
            [pd.DataFrame(0.0, index=runs.index, columns=list(FEATURES)), runs], axis=1
        )

    monkeypatch.setattr(training, "dataset_features", constant_features)
    # constant indicators give trees without splits: a few iterations show the same thing
    monkeypatch.setitem(training.CLEARANCE_PARAMS, "max_iter", 5)
    monkeypatch.setitem(training.FAULT_PARAMS, "max_iter", 5)
    # earlier tests' garbage (a file another test left open) would warn when collected inside
    # the block below: collect it first, so the block sees what train() itself raises
    gc.collect()
    with warnings.catch_warnings(record=True) as leaked:
        warnings.simplefilter("always")
        metrics = train(ds_dir, tmp_path / "m.skops", cv=2, progress=False)
    # nothing leaks from scikit-learn or the estimators: it is all in metrics["warnings"]
    assert [str(w.message) for w in leaked] == []
    notes = metrics["warnings"]
    assert any(
        n.startswith("fault macro-F1") and "on held-out runs" in n and "no better than chance" in n
        for n in notes
    ), notes
    assert any(
        n.startswith("clearance MAE") and "on held-out runs" in n and "learned nothing useful" in n
        for n in notes
    ), notes
    # a held-out metric of a model that learned nothing equals the constant answer's, never 0
    assert metrics["clearance_test"]["mae"] == pytest.approx(
        metrics["clearance_test"]["baseline_mae"]
    )
    assert metrics["fault_test"]["n"] == 10 and metrics["clearance_test"]["n"] == 10
    stored = json.loads((tmp_path / "m.metrics.json").read_text())
    assert stored["warnings"] == notes
    assert Dataset(ds_dir).runs.shape[0] == 42


def test_no_metric_from_zero_runs():
    class Never:
        classes_ = np.array(["healthy", "wear"])

        def predict(self, x):
            raise AssertionError("predicted on zero runs")

        predict_interval = predict

    empty = pd.DataFrame(columns=list(FEATURES), dtype=float)
    interval = training._interval_metrics(Never(), empty, np.array([]))
    classes = training._class_metrics(Never(), empty, np.array([]))
    assert interval["n"] == 0 and classes["n"] == 0
    assert all(interval[k] is None for k in ("mae", "rmse", "interval_coverage"))
    assert classes["macro_f1_classifier"] is None and classes["accuracy"] is None
    assert training.clearance_warnings("held-out", None, [], [1e-5, 2e-5]) == [
        "held-out split has 0 runs: no held-out clearance metrics"
    ]
    assert training.fault_warnings("held-out", None, [], ["healthy", "wear"]) == [
        "held-out split has 0 runs: no held-out fault metrics"
    ]


# ------------------------------------------------------------------------------------------
# A rig's dataset: fault labels alone, empty clearance labels, sparse indicators
# ------------------------------------------------------------------------------------------


def fault_only(table):
    """A rig's runs table labelled with faults alone: no clearance, nothing swept."""
    return table[["run_id", "split", "fault_class", "design"]]


def test_fault_labels_alone_are_enough_for_the_fault_target():
    table = fault_only(labels_table(60, 20))
    assert training_problems(table, target="fault", cv=5) == []
    for target in ("clearance", "both"):
        (problem,) = training_problems(table, target=target, cv=5)
        assert problem.startswith(f"--target {target} needs clearance labels, and this dataset")
        assert "no clearance_screw, clearance_nut column(s)" in problem
        assert "use --target fault" in problem


def test_empty_clearance_labels_are_no_labels_not_a_type_error():
    # an imported rig's runs table with clearance columns left empty: object-typed None
    table = fault_only(labels_table(60, 20)).assign(clearance_screw=None, clearance_nut=None)
    assert table["clearance_screw"].dtype == object
    assert training_problems(table, target="fault", cv=5) == []
    (problem,) = training_problems(table, target="both", cv=5)
    assert "needs clearance labels" in problem and "empty clearance_screw" in problem
    partly = labels_table(60, 20)
    partly.loc[:4, "clearance_nut"] = np.nan
    (problem,) = training_problems(partly, target="clearance", cv=5)
    assert "5 of 80 runs have none" in problem


def test_runs_without_swept_columns_are_each_their_own_operating_point():
    assert len(set(operating_point(fault_only(labels_table(6, 0))))) == 6
    empty = labels_table(6, 0)[["split", "clearance_screw", "screw_speed"]].assign(
        clearance_screw=None, screw_speed=None
    )
    assert len(set(operating_point(empty))) == 6


def test_fit_minimum_is_the_runs_the_smallest_fit_could_miss():
    table = labels_table(16, 4, classes=["a", "b", "c", "d"] * 5)
    minimum = fit_minimum(table, cv=3, target="fault")
    # 16 runs, 3 folds: 10 in a fold's fit; the classifier calibrates on 2 folds of it: 5
    assert minimum == 12
    assert fit_minimum(table, cv=3, target="clearance") <= 16
    assert fit_minimum(labels_table(800, 200), cv=5, target="both") < 800


def _features_of(table, sparse, finite_rows, seed=0):
    """Indicators for a runs table: random, but ``sparse`` finite in ``finite_rows`` train runs."""
    rng = np.random.default_rng(seed)

    def features(dataset, progress=False):
        runs = dataset.runs.reset_index(drop=True)
        values = pd.DataFrame(
            rng.normal(size=(len(runs), len(FEATURES))), index=runs.index, columns=list(FEATURES)
        )
        train_rows = np.flatnonzero(runs["split"].to_numpy() == "train")
        values.loc[train_rows[finite_rows:], sparse] = np.nan
        return pd.concat([values, runs], axis=1)

    return features


def _dataset(tiny, path, table):
    path.mkdir()
    shutil.copy(tiny / "manifest.json", path / "manifest.json")
    table.to_parquet(path / "runs.parquet")
    return path


def test_fault_labels_alone_train_a_fault_model(tiny, tmp_path, monkeypatch):
    table = fault_only(labels_table(24, 8, classes=["healthy", "wear"] * 16))
    ds_dir = _dataset(tiny, tmp_path / "faults", table)
    monkeypatch.setattr(training, "dataset_features", _features_of(table, "lost_motion", 24))
    monkeypatch.setitem(training.FAULT_PARAMS, "max_iter", 3)
    metrics = train(ds_dir, tmp_path / "m.skops", target="fault", cv=2, progress=False)
    assert metrics["fault_plain_baseline_cv"]["n_splits"] == metrics["fault_cv"]["n_splits"]
    assert "clearance_cv" not in metrics and metrics["fault_test"]["n"] == 8
    # the classifier alone: every run named, so it is neither of evaluate's two macro-F1s
    assert "macro_f1_classifier" in metrics["fault_test"] and "macro_f1" not in metrics["fault_cv"]
    assert all("macro_f1_classifier" in fold for fold in metrics["fault_cv"]["folds"])
    with pytest.raises(PRSMHealthError, match="needs clearance labels"):
        train(ds_dir, tmp_path / "c.skops", target="clearance", cv=2, progress=False)


def test_a_too_sparse_indicator_is_left_out_and_said_never_a_traceback(tiny, tmp_path, monkeypatch):
    # lost_motion finite in 1 of 16 training runs (a rig whose recordings rarely reverse): a CV
    # fold that holds that run out would fit on none of its values, so it is left out, said
    table = labels_table(16, 4, classes=["healthy", "wear"] * 10)
    ds_dir = _dataset(tiny, tmp_path / "sparse", table)
    monkeypatch.setattr(training, "dataset_features", _features_of(table, "lost_motion", 1))
    monkeypatch.setitem(training.FAULT_PARAMS, "max_iter", 3)
    metrics = train(ds_dir, tmp_path / "m.skops", target="fault", cv=3, progress=False)
    fewest = fit_minimum(table, cv=3, target="fault")
    assert metrics["indicators_too_sparse"] == ["lost_motion"]
    (said,) = [n for n in metrics["warnings"] if n.startswith("indicator(s) finite in fewer")]
    assert f"the {fewest} of 16 training runs" in said and "lost_motion (1)" in said
    assert "lost_motion" not in load_model(tmp_path / "m.skops")[0]["feature_names"]


def test_the_best_cross_validated_candidate_is_shipped_and_a_winning_baseline_is_said():
    from prsm_health.training.fault_candidates import choose

    def scores(boosting, forest, plain):
        return {
            "boosting": {"macro_f1": boosting},
            "forest": {"macro_f1": forest},
            "plain_baseline": {"macro_f1": plain},
        }

    assert choose(scores(0.80, 0.90, 0.85)) == ("forest", [])
    assert choose(scores(0.90, 0.90, 0.90)) == ("boosting", [])  # a tie: the earlier
    shipped, said = choose(scores(0.70, 0.80, 0.91))
    assert shipped == "plain_baseline" and len(said) == 1
    assert "0.91" in said[0] and "0.80" in said[0] and "shipped" in said[0]
    assert choose({"plain_baseline": {"macro_f1": 0.5}})[0] == "plain_baseline"
