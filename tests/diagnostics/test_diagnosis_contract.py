"""The Diagnosis contract's declaration (typed parts, JSON made from the fields) and the honesty
of its words: observability that says no where the interval is the whole trained range, an
out-of-distribution warning whose numbers are true for the recording it is given for (fast: a
synthetic model)."""

import json

import numpy as np
import pytest

from prsm_health.diagnostics.contract import (
    ClearanceInterval,
    Diagnosis,
    ModelReference,
    Observability,
    WindowSpan,
)
from prsm_health.diagnostics.diagnosis import (
    OOD_LIMIT,
    WHOLE_RANGE_SHARE,
    ModelBundle,
    _above_limit,
    aggregate,
    diagnose_indicators,
    ood_verdict,
)

SPAN = [0.0, 40e-6]


def _window(**overrides) -> Diagnosis:
    fields = dict(
        clearance=ClearanceInterval(20e-6, 15e-6, 25e-6),
        fault_class="wear",
        class_probabilities={"wear": 0.8, "healthy": 0.2},
        class_set=["wear"],
        observability=Observability(True, True),
        ood_score=0.7,
        indicators={"lost_motion": 1e-4, "tan_rms": None},
        indicator_groups={"lost_motion": "computed"},
        model=ModelReference("m", "1", "paper01", "flight-ema"),
        window=WindowSpan(0, 0.0, 0.4),
    )
    return Diagnosis(**{**fields, **overrides})


def test_json_follows_the_declaration():
    d = _window()
    out = d.to_json()
    assert list(out) == [
        "clearance",
        "fault_class",
        "class_probabilities",
        "class_set",
        "observability",
        "ood_score",
        "indicators",
        "indicator_groups",
        "model",
        "warnings",
        "window",
    ]
    assert out["clearance"] == {"estimate": 20e-6, "lower": 15e-6, "upper": 25e-6}
    assert out["model"] == {
        "name": "m",
        "version": "1",
        "design": "paper01",
        "instrumentation": "flight-ema",
    }
    assert out["window"] == {"index": 0, "start": 0.0, "end": 0.4}
    json.dumps(out, allow_nan=False)
    # a recording: windows, no window
    whole = _window(window=None, windows=[d])
    assert "window" not in whole.to_json() and whole.to_json()["windows"] == [out]


def test_parts_read_as_the_mappings_they_were():
    d = _window()
    assert d.clearance["estimate"] == d.clearance.estimate == 20e-6
    assert d.observability.get("clearance") is True
    assert d.observability == {"clearance": True, "fault": True}
    assert dict(d.model) == d.model.to_json()
    assert d.window["start"] == 0.0
    with pytest.raises(KeyError):
        d.clearance["median"]
    with pytest.raises(AttributeError):
        d.clearance.estimate = 1.0  # frozen
    # mappings are accepted where a part is expected
    legacy = _window(clearance={"estimate": 1e-6, "lower": 0.0, "upper": 2e-6}, window=None)
    assert isinstance(legacy.clearance, ClearanceInterval) and legacy.clearance.upper == 2e-6


class _Clearance:
    """A clearance model whose interval is given: (lower, upper) per row."""

    def __init__(self, intervals):
        self.intervals = np.asarray(intervals, float)

    def predict(self, x):
        return self.intervals.mean(axis=1)

    def predict_interval(self, x):
        return self.intervals[:, 0], self.intervals[:, 1]


class _Guard:
    def __init__(self, scores):
        self.scores = np.asarray(scores, float)

    def score(self, x):
        return self.scores


def _bundle(intervals, scores=None) -> ModelBundle:
    guard = None if scores is None else _Guard(scores)
    metadata = {"design": None, "name": "m", "clearance_range": SPAN}
    return ModelBundle(_Clearance(intervals), None, ["lost_motion"], metadata, guard)


def _rows(n):
    return [{"lost_motion": 1e-4, "reversal": 1.0} for _ in range(n)]


def test_an_interval_as_wide_as_the_trained_range_is_not_observability():
    wide = (0.02 * SPAN[1], 0.98 * SPAN[1])  # 96 % of the range
    narrow = (15e-6, 25e-6)
    # as wide, but reaching past the upper end: 60 % of the range, the clearance lies high
    past = (16e-6, 56e-6)
    shown, hidden, high = diagnose_indicators(_rows(3), _bundle([narrow, wide, past]))
    assert high.observability.clearance is True and not high.warnings
    assert shown.observability.clearance is True and not shown.warnings
    assert [shown.clearance.lower, shown.clearance.upper] == pytest.approx(narrow)
    assert hidden.observability.clearance is False
    (note,) = hidden.warnings
    assert f"covers {100 * WHOLE_RANGE_SHARE:.0f} % or more of the trained range" in note
    assert "clearance is not observable in this window" in note
    assert [hidden.clearance.lower, hidden.clearance.upper] == SPAN
    # the recording: the clearance of the window that showed it, the share that did
    whole = aggregate([shown, hidden], _bundle([narrow, wide]))
    assert whole.observability.clearance == 0.5
    assert [whole.clearance.lower, whole.clearance.upper] == pytest.approx(narrow)
    assert any(w.endswith("(in 1 of 2 windows)") for w in whole.warnings)


def test_out_of_distribution_windows_hide_the_clearance():
    narrow = (15e-6, 25e-6)
    (d,) = diagnose_indicators(_rows(1), _bundle([narrow], scores=[9.4]))
    assert d.observability == {"clearance": False, "fault": False}
    assert [d.clearance.lower, d.clearance.upper] == SPAN
    assert any("out-of-distribution score 9.4 > 1.5" in w for w in d.warnings)


def test_out_of_distribution_words_are_true_for_the_recording():
    # one window of three unlike the training set: the recording's (median) score is below
    # the limit, its warning names the window's score and how many windows it concerns
    bundle = _bundle([(15e-6, 25e-6)] * 3, scores=[0.55, 0.61, 2.345])
    windows = diagnose_indicators(_rows(3), bundle)
    whole = aggregate(windows, bundle)
    assert whole.ood_score == pytest.approx(0.61) and whole.ood_score < OOD_LIMIT
    (note,) = [w for w in whole.warnings if "out-of-distribution" in w]
    assert "(out-of-distribution score 2.3 > 1.5)" in note
    assert note.endswith("(in 1 of 3 windows)")
    assert (
        ood_verdict(whole) == "0.61 ≤ 1.5: like the training set (median of 3 windows; 1 above 1.5)"
    )
    assert ood_verdict(windows[2]) == "2.3 > 1.5: unlike the training set"
    # several windows above: one warning with the range of their scores
    bundle = _bundle([(15e-6, 25e-6)] * 3, scores=[1.7, 9.4, 0.5])
    whole = aggregate(diagnose_indicators(_rows(3), bundle), bundle)
    (note,) = [w for w in whole.warnings if "out-of-distribution" in w]
    assert "score 1.7 … 9.4 > 1.5" in note and note.endswith("(in 2 of 3 windows)")
    assert ood_verdict(whole).startswith("1.7 > 1.5: unlike the training set")


@pytest.mark.parametrize(
    "score, text", [(9.396, "9.4"), (2.345, "2.3"), (1.52, "1.52"), (1.5004, "1.5004")]
)
def test_rounded_scores_still_read_above_the_limit(score, text):
    assert _above_limit(score) == text
