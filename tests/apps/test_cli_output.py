"""The wording of the CLI's tables: shares say of what ("in 75 % of windows"), and each fault
macro-F1 says what it counts (evaluation: ``cannot_tell`` a miss, or only the runs given a
class; training: the classifier alone)."""

from types import SimpleNamespace

import pytest

from prsm_health.apps.cli.models import diagnosis_rows, evaluation_rows, training_rows
from prsm_health.apps.cli.output import print_table, share


@pytest.mark.parametrize(
    "value, text",
    [
        (1.0, "in 100 % of windows"),
        (0.75, "in 75 % of windows"),
        (True, "in 100 % of windows"),
        (False, "in 0 % of windows"),
        (2 / 3, "in 66.7 % of windows"),
        (None, "–"),
    ],
)
def test_share(value, text):
    assert share(value, "windows") == text


def table(rows, capsys) -> dict:
    print_table(rows)
    lines = capsys.readouterr().out.splitlines()
    return {name: line for (name, _, _), line in zip(rows, lines)}


def test_diagnose_says_of_what_the_observability_is_a_share(capsys):
    result = SimpleNamespace(
        clearance={"estimate": 24e-6, "lower": 20e-6, "upper": 30e-6},
        fault_class="wear",
        class_set=["wear"],
        class_probabilities={"wear": 0.8, "healthy": 0.2},
        observability={"clearance": 1.0, "fault": 0.5},
        ood_score=0.4,
        windows=[SimpleNamespace(ood_score=0.4)] * 4,
        model={"name": "m", "version": "1"},
        warnings=[],
    )
    lines = table(diagnosis_rows("r.mcap", result), capsys)
    assert lines["clearance observable"].endswith("clearance observable       in 100 % of windows")
    assert lines["class observable"].endswith("in 50 % of windows")


def test_a_check_says_its_phases_and_why_it_cannot_tell(capsys):
    result = SimpleNamespace(
        clearance={"estimate": 24e-6, "lower": 0.0, "upper": 40e-6},
        fault_class="cannot_tell",
        class_set=["healthy", "spall"],
        class_probabilities={"spall": 0.4, "healthy": 0.6},
        observability={"clearance": False, "fault": False},
        undecided=SimpleNamespace(
            kind="not_observable",
            missing=["a slow reversal under load"],
            candidates=[],
            next_recording="run the health check",
        ),
        check_phases={"no_load": "quiet", "high_load": "heavy"},
        model={"name": "m", "version": "1"},
        warnings=[],
    )
    rows = diagnosis_rows("c.parquet", result)
    assert ("cannot tell", "not observable", "  (a slow reversal under load)") in rows
    assert ("record next", "run the health check", "") in rows
    assert ("check phases", "high_load: heavy", "") in rows
    assert ("clearance observable", "no", "") in rows
    assert not any(r[0] in ("windows", "out-of-distribution score") for r in rows)


REPORT = {
    "model": {"name": "m", "version": "1"},
    "dataset": "d",
    "split": "test",
    "runs": 10,
    "clearance": {"mae": 2e-6, "coverage": 0.9, "mean_width": 8e-6, "observable_fraction": 0.8},
    "fault": {
        "macro_f1_all": 0.5,
        "macro_f1_named": 0.75,
        "cannot_tell_fraction": 0.3,
        "f1_by_class": {"healthy": 0.6, "wear": 0.4},
    },
    "ood": {"flagged_fraction": 0.0},
}


def test_evaluate_names_what_each_macro_f1_counts(capsys):
    lines = table(evaluation_rows(REPORT), capsys)
    f1 = {name: line for name, line in lines.items() if "macro-F1" in name}
    assert len(f1) == 2
    assert f1["fault macro-F1 (cannot_tell counted as a miss)"].endswith(" 0.5")
    assert f1["fault macro-F1 (on the runs given a class)"].endswith(" 0.75")
    assert lines["cannot_tell"].endswith("in 30 % of runs")
    assert lines["clearance observable"].endswith("in 80 % of runs")
    assert lines["out of distribution"].endswith("in 0 % of runs")


def test_train_says_its_macro_f1_is_the_classifiers_alone(capsys):
    metrics = {
        "model": {"path": "m.skops"},
        "metrics_path": "m.metrics.json",
        "fault_cv": {"macro_f1_classifier": 0.6},
        "fault_test": {"macro_f1_classifier": None},  # no held-out runs
        "clearance_test": {"mae": 2e-6, "interval_coverage": 0.85, "mean_interval_width": 8e-6},
    }
    lines = table(training_rows(metrics), capsys)
    cv = "fault CV macro-F1 (the classifier alone: no cannot_tell)"
    assert lines[cv].endswith(" 0.6")
    assert lines["fault held-out macro-F1 (the classifier alone: no cannot_tell)"].endswith("–")
    assert lines["clearance held-out 90 % interval coverage"].endswith("in 85 % of runs")


def test_the_ood_row_is_a_true_sentence(tmp_path, capsys):
    # a score below the limit must not read "> 1.5: unlike the training set"
    from prsm_health.apps.cli.models import diagnosis_rows
    from prsm_health.diagnostics.contract import Diagnosis

    d = Diagnosis(
        clearance={"estimate": 1e-5, "lower": 5e-6, "upper": 2e-5},
        fault_class="wear",
        class_probabilities={"wear": 1.0},
        indicators={},
        observability={"clearance": True, "fault": True},
        ood_score=0.663,
        warnings=[],
        model={"name": "m", "version": "1", "design": "paper01", "instrumentation": None},
    )
    row = next(r for r in diagnosis_rows("f.mcap", d) if r[0] == "out-of-distribution score")
    assert "≤ 1.5" in row[1] and "unlike" not in row[1], row
