"""A health-check recording through the diagnosis: read phase by phase by the bundle's check
model, alone or against the unit's baseline; a check that lacks a phase says which condition is
missing and what to record; an ambiguous answer names the classes left; a class no check shows
is named with its reason. The estimators are stand-ins with fixed answers (the check model's
training is measured by tools/release/train_check_model.py, not here)."""

from dataclasses import replace

import numpy as np
import pytest

from prsm_health.core.run import Run
from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.contract import AMBIGUOUS, CANNOT_TELL, NOT_OBSERVABLE
from prsm_health.diagnostics.diagnosis import ModelBundle, diagnose
from prsm_health.signals.check_indicators import CHECK_INDICATORS

NAMES = list(CHECK_INDICATORS)


class Fixed:
    """A classifier or regressor stand-in with fixed answers."""

    def __init__(self, classes=(), proba=(), estimate=10e-6):
        self.classes_ = np.array(classes)
        self.set_thresholds_ = np.full(len(classes), 0.2)  # a class set: p ≥ 0.2
        self.proba = np.array([proba], float)
        self.estimate = estimate

    def predict_proba(self, x):
        return np.repeat(self.proba, len(x), axis=0)

    def predict(self, x):
        return np.full(len(x), self.estimate)

    def predict_interval(self, x):
        return np.full(len(x), 0.8 * self.estimate), np.full(len(x), 1.2 * self.estimate)


def bundle(alone=(0.8, 0.1, 0.1), against=(0.05, 0.05, 0.9)):
    classes = ("healthy", "preload_loss", "spall")
    part = {
        "feature_names": NAMES,
        "clearance": Fixed(),
        "fault": Fixed(classes, alone),
        "fault_relative": Fixed(classes, against),
        "repeatability": {n: 1.0 for n in NAMES},
        "training_prior": {c: 1 / 3 for c in classes},
        "not_observable": {"tooth_damage": "below the accelerometer's noise"},
        "clearance_range": [0.0, 40e-6],
    }
    metadata = {"design": "paper01", "name": "stand-in", "channels": None}
    return ModelBundle(None, None, ["lost_motion"], metadata, None, part)


@pytest.fixture(scope="module")
def check_run(short_check_run) -> Run:
    return short_check_run()


def without_phase(run: Run, name: str) -> Run:
    """The recording of a check that lacked the phase ``name`` (its samples outside any phase)."""
    index = next(p.index for p in run.check.phases if p.name == name)
    phase = np.where(run.check_phase == index, -1, run.check_phase).astype(np.int16)
    check = replace(run.check, phases=tuple(p for p in run.check.phases if p.index != index))
    return replace(run, check_phase=phase, check=check)


def test_a_check_is_read_phase_by_phase_and_names_a_class_alone(check_run):
    d = diagnose(check_run, bundle())
    assert set(d.check_phases) == {"no_load", "torque_pair", "reversal", "high_load"}
    assert d.check_phases["high_load"] == "heavy"
    assert d.fault_class == "healthy" and d.undecided is None
    assert d.observability["clearance"] and d.observability["fault"]
    # the clearance is measured by physics from the one reversal, the learnt one beside it
    measured = d.measured_clearance
    assert [r.phase for r in measured.reversals] == ["swing"]
    assert measured.stiffness_factor is None and not measured.commissioned
    assert measured.learnt["estimate"] == pytest.approx(10e-6)
    assert d.clearance["lower"] < d.clearance["estimate"] < d.clearance["upper"]
    assert not d.windows  # a check is not cut into windows
    assert any("tooth_damage" in w and "not observable" in w for w in d.warnings)
    assert any("read alone" in w for w in d.warnings)
    assert {"check_torque_ratio", "check_highload_snr_nut_pass"} <= set(d.indicators)


def test_against_the_baseline_the_change_model_answers(check_run):
    model = bundle()
    alone = diagnose(check_run, model)
    baseline = Baseline.fit([alone.indicators] * 3, prior_scale=model.check["repeatability"])
    d = diagnose(check_run, model, baseline=baseline)
    assert d.fault_class == "spall"
    assert not any("read alone" in w for w in d.warnings)


def test_a_class_only_the_baseline_shows_is_named_so_when_a_check_is_read_alone(check_run):
    model = bundle()
    model.check["baseline_only"] = {"preload_loss": "the lost motion of units as built spreads"}
    alone = diagnose(check_run, model)
    note = "not observable by one check alone: preload_loss"
    assert any(w.startswith(note) for w in alone.warnings)
    baseline = Baseline.fit([alone.indicators] * 3, prior_scale=model.check["repeatability"])
    against = diagnose(check_run, model, baseline=baseline)
    assert not any(w.startswith(note) for w in against.warnings)


def test_a_check_without_its_high_load_phase_cannot_show_a_spall(check_run):
    d = diagnose(without_phase(check_run, "heavy"), bundle())
    assert d.fault_class == CANNOT_TELL
    assert d.undecided.kind == NOT_OBSERVABLE
    assert d.undecided.missing == ["a constant-speed phase at ≥ 20 % of C_a"]
    assert "health check" in d.undecided.next_recording
    assert "high_load" not in d.check_phases
    assert d.to_json()["undecided"]["kind"] == NOT_OBSERVABLE


def test_a_check_without_its_reversal_hides_the_clearance(check_run):
    d = diagnose(without_phase(check_run, "swing"), bundle())
    assert not d.observability["clearance"]
    assert (d.clearance["lower"], d.clearance["upper"]) == (0.0, 40e-6)


def test_an_ambiguous_check_names_the_classes_left_and_asks_for_more_checks(check_run):
    d = diagnose(check_run, bundle(alone=(0.4, 0.35, 0.25)))
    assert d.fault_class == CANNOT_TELL
    assert d.undecided.kind == AMBIGUOUS
    assert set(d.undecided.candidates) == {"healthy", "preload_loss", "spall"}
    assert "baseline" in d.undecided.next_recording


def test_a_baseline_only_class_note_says_how_to_get_the_baseline_reading():
    # The note once ended mid-sentence ("against this unit's baseline … it is").
    from prsm_health.diagnostics.check_model import baseline_only_note

    note = baseline_only_note("preload_loss", "one check cannot tell it from the as-built play")
    assert note.startswith("not observable by one check alone: preload_loss — one check")
    assert "it is observable" in note and "--asset" in note and "asset_id" in note
