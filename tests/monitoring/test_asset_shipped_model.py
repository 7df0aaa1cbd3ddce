"""A real case: the shipped model without its check part reads a healthy unit's short health
checks window by window (the windows cut across the check's phases). Recorded through the
monitoring steps with the model's priors, three baseline checks and four more neither raise the
change alarm nor name a fault. Before the spread of the model's training windows was the
baseline's prior scale, the three baseline checks agreed closely enough to give near-zero
scales and this unit alarmed at its 6th check (issue 42)."""

import dataclasses

import pytest

from prsm_health.diagnostics.contract import CANNOT_TELL
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.monitoring import HEALTHY, FileAssetStore, bundle_priors, diagnose_asset


@pytest.mark.slow  # seven 1 s checks simulated and diagnosed: 10–20 s
def test_a_model_without_a_check_part_keeps_a_healthy_unit_quiet(short_check_run, tmp_path):
    bundle = dataclasses.replace(load_bundle(), check=None)
    assert bundle_priors(bundle)[0]  # a prior scale all the same: the training spread
    store = FileAssetStore(tmp_path)
    for seed in range(1, 8):  # the default health state: healthy
        d = diagnose_asset(short_check_run(None, seed), bundle, store, "unit-1", f"check-{seed}")
        assert not d.check_phases  # read window by window
        assert not d.asset.evidence.change_alarm, d.asset
        assert d.asset.evidence.fault_class in (CANNOT_TELL, HEALTHY), d.asset.evidence
    history = store.load("unit-1").history
    assert [e.baseline for e in history.entries] == [True] * 3 + [False] * 4
    assert history.evidence.recordings == 4  # its windows showed the class: evidence was added
