"""The fault answer of a diagnosis: a class named only when its probability reaches
NAME_PROBABILITY, and the model's class set — what the evidence cannot rule out — with the
candidates and what is ruled out in a warning (fast: a synthetic model)."""

import numpy as np
import pandas as pd
import pytest

from prsm_health.diagnostics.diagnosis import (
    CANNOT_TELL,
    NAME_PROBABILITY,
    ModelBundle,
    aggregate,
    diagnose_indicators,
)
from prsm_health.diagnostics.estimators import FaultClassifier

CLASSES = np.array(["healthy", "lubrication", "preload_loss", "wear"])
ALIKE = {"healthy", "lubrication", "preload_loss"}


def _draw(n, seed):
    # healthy, lubrication and preload loss share one distribution (an instrumentation that
    # cannot tell them apart: each ≈ 1/3 probable); wear sits 8 standard deviations away
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 4, n)
    return 8.0 * (labels == 3) + rng.standard_normal(n), CLASSES[labels]


@pytest.fixture(scope="module")
def bundle():
    x, y = _draw(2000, seed=3)
    fault = FaultClassifier(max_iter=20).fit(pd.DataFrame({"lost_motion": x}), y)
    return ModelBundle(None, fault, ["lost_motion"], {"design": None})


def _rows(values, reversal=1.0):
    return [{"lost_motion": v, "reversal": reversal} for v in values]


def test_separable_classes_are_named_look_alikes_are_cannot_tell(bundle):
    x, y = _draw(600, seed=4)
    answers = diagnose_indicators(_rows(x), bundle)
    wear = [d for d, t in zip(answers, y) if t == "wear"]
    alike = [d for d, t in zip(answers, y) if t != "wear"]
    # wear stands 8 σ apart: named, alone in its set, no warning (seen: every one)
    assert all(d.fault_class == "wear" and d.class_set == ["wear"] for d in wear)
    assert not any(d.warnings for d in wear)
    # the look-alikes: each ≈ 1/3, so mostly no class reaches 0.5 and the answer is cannot_tell
    # (seen 0.99: the boosted probabilities scatter up to 0.52); a look-alike named anyway is
    # never a confident answer
    assert np.mean([d.fault_class == CANNOT_TELL for d in alike]) > 0.95
    named = [d for d in alike if d.fault_class != CANNOT_TELL]
    assert all(NAME_PROBABILITY <= max(d.class_probabilities.values()) <= 0.6 for d in named)
    # their sets mostly hold all three with wear ruled out (seen 0.79: by construction ~10 % of
    # each class falls below its own threshold)
    assert np.mean([set(d.class_set) == ALIKE for d in alike]) > 0.6
    d = next(d for d in alike if set(d.class_set) == ALIKE)
    (note,) = [w for w in d.warnings if w.startswith("fault class: cannot tell — no class")]
    assert "not ruled out at 90 %" in note and note.endswith("ruled out: wear")
    assert d.to_json()["class_set"] == d.class_set


def test_hidden_fault_keeps_every_class_in_the_set(bundle):
    (d,) = diagnose_indicators(_rows([8.0], reversal=0.0), bundle)
    assert d.fault_class == CANNOT_TELL and set(d.class_set) == set(CLASSES)


def test_recording_states_the_set_once_for_its_mean_probabilities(bundle):
    x, y = _draw(300, seed=5)
    windows = diagnose_indicators(_rows(x[y != "wear"][:20]), bundle)
    whole = aggregate(windows, bundle)
    # 20 look-alike windows average to ≈ 1/3 each: all three stay in the set, none named
    assert whole.fault_class == CANNOT_TELL
    assert set(whole.class_set) == ALIKE
    assert sum("not ruled out at" in w for w in whole.warnings) == 1
    worn = aggregate(diagnose_indicators(_rows(x[y == "wear"][:5]), bundle), bundle)
    assert worn.fault_class == "wear" and worn.class_set == ["wear"]


def test_a_shipped_plain_baseline_reads_its_own_columns_through_the_same_diagnosis():
    # train ships the plain baseline (a forest on channel statistics) when it cross-validates
    # best: the bundle names the columns it reads, the rest of the diagnosis is unchanged
    rng = np.random.default_rng(5)
    torque = np.r_[rng.normal(0.2, 0.01, 60), rng.normal(0.4, 0.01, 60)]
    labels = np.array(["healthy"] * 60 + ["lubrication"] * 60)
    fault = FaultClassifier(learner="forest", calibration_cv=3).fit(
        pd.DataFrame({"stat_drive_torque_mean": torque}), labels
    )
    bundle = ModelBundle(
        None, fault, ["lost_motion"], {"design": None}, fault_features=["stat_drive_torque_mean"]
    )
    rows = [{"lost_motion": 1e-5, "reversal": 1.0, "stat_drive_torque_mean": t} for t in (0.2, 0.4)]
    healthy, lubrication = diagnose_indicators(rows, bundle)
    assert healthy.fault_class == "healthy" and lubrication.fault_class == "lubrication"
    assert lubrication.indicators["stat_drive_torque_mean"] == 0.4
