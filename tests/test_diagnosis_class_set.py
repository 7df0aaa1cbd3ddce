"""The fault answer of a diagnosis from the model's class set: one class only when the set
holds it alone; otherwise ``cannot_tell`` with the candidates named (fast: a synthetic model)."""

import numpy as np
import pandas as pd
import pytest

from prsm_health.diagnosis import CANNOT_TELL, ModelBundle, aggregate, diagnose_indicators
from prsm_health.estimators import FaultClassifier

CLASSES = np.array(["healthy", "lubrication", "wear"])


def _draw(n, seed):
    # healthy and lubrication share one distribution (an instrumentation that cannot tell
    # them apart); wear sits 8 standard deviations away in "lost_motion"
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 3, n)
    return 8.0 * (labels == 2) + rng.standard_normal(n), CLASSES[labels]


@pytest.fixture(scope="module")
def bundle():
    x, y = _draw(1500, seed=3)
    fault = FaultClassifier(max_iter=20).fit(pd.DataFrame({"lost_motion": x}), y)
    return ModelBundle(None, fault, ["lost_motion"], {"design": None})


def _rows(values, reversal=1.0):
    return [{"lost_motion": v, "reversal": reversal} for v in values]


def test_separable_classes_are_named_look_alikes_are_cannot_tell(bundle):
    x, y = _draw(600, seed=4)
    answers = diagnose_indicators(_rows(x), bundle)
    wear = [d for d, t in zip(answers, y) if t == "wear"]
    alike = [d for d, t in zip(answers, y) if t != "wear"]
    # wear stands 8 σ apart: named, alone in its set (seen: every one)
    assert np.mean([d.fault_class == "wear" and d.class_set == ["wear"] for d in wear]) > 0.95
    # the look-alikes: cannot_tell with both named and wear ruled out (seen 0.93: by
    # construction ~10 % of each class falls below its class's threshold and is named alone)
    told_apart = [
        d.fault_class == CANNOT_TELL and set(d.class_set) == {"healthy", "lubrication"}
        for d in alike
    ]
    assert np.mean(told_apart) > 0.6
    d = alike[int(np.argmax(told_apart))]
    (note,) = [w for w in d.warnings if w.startswith("fault class: one of")]
    assert "ruled out: wear" in note
    assert d.to_json()["class_set"] == d.class_set
    # a named class is never a confident wrong one here: the look-alikes sit near 0.5 (seen ≤ 0.65)
    named = [d for d, t in zip(alike, y[y != "wear"]) if d.fault_class not in (CANNOT_TELL, t)]
    assert all(max(d.class_probabilities.values()) <= 0.75 for d in named)


def test_hidden_fault_keeps_every_class_in_the_set(bundle):
    (d,) = diagnose_indicators(_rows([8.0], reversal=0.0), bundle)
    assert d.fault_class == CANNOT_TELL and set(d.class_set) == set(CLASSES)


def test_recording_states_the_set_once_for_its_mean_probabilities(bundle):
    x, y = _draw(300, seed=5)
    windows = diagnose_indicators(_rows(x[y != "wear"][:20]), bundle)
    whole = aggregate(windows, bundle)
    # 20 look-alike windows average to ≈ 0.5 / 0.5: both stay in the set
    assert whole.fault_class == CANNOT_TELL
    assert set(whole.class_set) == {"healthy", "lubrication"}
    assert sum(w.startswith("fault class: one of") for w in whole.warnings) == 1
    worn = aggregate(diagnose_indicators(_rows(x[y == "wear"][:5]), bundle), bundle)
    assert worn.fault_class == "wear" and worn.class_set == ["wear"]
