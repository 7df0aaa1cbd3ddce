"""prsm_health.training.evaluation: the fault metrics' names, sparse features in CV folds."""

import numpy as np
import pandas as pd
import pytest
from sklearn.ensemble import HistGradientBoostingClassifier

from prsm_health.core.errors import PRSMHealthError
from prsm_health.diagnostics.diagnosis import CANNOT_TELL
from prsm_health.training.evaluation import (
    SparseFeatureError,
    cross_validated_metrics,
    fault_report,
    sparse_feature_errors,
)


def test_fault_report_names_what_cannot_tell_counts_as():
    truth = ["healthy", "healthy", "wear", "wear"]
    told = ["healthy", CANNOT_TELL, "wear", CANNOT_TELL]
    records = pd.DataFrame(
        {
            "fault_class": truth,
            "predicted_class": told,
            "top_probability": [0.9, 0.4, 0.8, 0.5],
            "class_set": [["healthy"], ["healthy", "wear"], ["wear"], ["healthy", "wear"]],
        }
    )
    report = fault_report(records)
    assert "macro_f1" not in report and "macro_f1_told" not in report
    # every run named correctly: 1; over all runs the two cannot_tell are misses (recall 1/2)
    assert report["macro_f1_named"] == pytest.approx(1.0)
    assert report["macro_f1_all"] == pytest.approx(2 / 3)
    assert report["cannot_tell_fraction"] == 0.5
    nothing_named = records.assign(predicted_class=CANNOT_TELL)
    assert fault_report(nothing_named)["macro_f1_named"] is None


def test_a_feature_no_fit_sees_is_one_line_naming_it():
    rng = np.random.default_rng(0)
    x = pd.DataFrame(rng.normal(size=(12, 2)), columns=["speed_mean", "lost_motion"])
    x.loc[1:, "lost_motion"] = np.nan  # one finite value: the fold holding it out has none
    y = np.array(["a", "b"] * 6)
    with pytest.raises(SparseFeatureError) as err:
        cross_validated_metrics(HistGradientBoostingClassifier(max_iter=3), x, y, cv=3)
    message = str(err.value)
    assert isinstance(err.value, PRSMHealthError) and "\n" not in message
    assert message.startswith("3-fold cross-validation needs a finite value of each feature")
    assert "lost_motion finite in 1 of 12 rows" in message and "speed_mean" not in message


def test_the_outer_guard_words_the_message_and_other_errors_pass():
    x = pd.DataFrame({"lost_motion": [1.0, np.nan, np.nan, np.nan]})
    with pytest.raises(SparseFeatureError, match=r"^--cv 3 needs each indicator finite in ≥ 4"):
        with sparse_feature_errors(x, "--cv 3", 4, words=("indicator", "training runs")):
            with sparse_feature_errors(x, "inner"):
                raise ValueError("window shape cannot be larger than input array shape")
    with pytest.raises(ValueError, match="something else"):
        with sparse_feature_errors(x, "--cv 3"):
            raise ValueError("something else")
