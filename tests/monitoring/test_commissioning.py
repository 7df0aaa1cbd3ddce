"""Commissioning an asset: its as-built clearance and its baseline checks fix the clearance
gauge's constant offset; kept in its history, read back from the store."""

import math

import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.diagnostics.clearance_gauge import GAUGE_INDICATORS
from prsm_health.monitoring import AssetEntry, AssetHistory, FileAssetStore, commission
from prsm_health.monitoring.steps import diagnose_asset
from tests.diagnostics.test_check_model import bundle as stand_in_bundle

ZERO_LOAD, FACTOR, ELASTIC = GAUGE_INDICATORS


def entry(name, lost_motion, baseline=True, factor=1.1, elastic=50e-6):
    indicators = {ZERO_LOAD: lost_motion, FACTOR: factor, ELASTIC: elastic}
    return AssetEntry(name, indicators=indicators, baseline=baseline)


def test_the_offset_is_the_baseline_s_lost_motion_less_the_as_built_play():
    history = AssetHistory(
        "unit-1",
        (entry("a", 40e-6), entry("b", 42e-6), entry("c", math.nan), entry("d", 90e-6, False)),
        as_built_clearance=5e-6,
    )
    c = history.commissioning()
    # the median of the baseline checks that read one (not d, not the NaN of c); the factors
    # equal: the zero-load lost motions themselves
    assert c.offset == pytest.approx(41e-6 - 4 * 5e-6) and c.checks == 2
    assert c.stiffness_factor == pytest.approx(1.1)
    assert AssetHistory("unit-1", history.entries).commissioning() is None
    back = AssetHistory.from_json(history.to_json())
    assert back.as_built_clearance == 5e-6 and back.commissioning() == c
    old = history.to_json()
    del old["as_built_clearance"]  # a history written before commissioning existed
    assert AssetHistory.from_json(old).as_built_clearance is None


def test_a_check_reads_against_the_commissioning_once_the_baseline_has_one(
    tmp_path, short_check_run
):
    store = FileAssetStore(tmp_path)
    model, run = stand_in_bundle(), short_check_run()
    with pytest.raises(ParameterError, match="as_built_clearance"):
        commission(store, "unit-1", 1.0)
    commission(store, "unit-1", 6e-6)
    first = diagnose_asset(run, model, store, "unit-1", "rec-1", healthy=True)
    assert not first.measured_clearance.commissioned  # no baseline check yet
    second = diagnose_asset(run, model, store, "unit-1", "rec-2", healthy=True)
    # the same recording again: its zero-load lost motion is the commissioning's
    assert second.measured_clearance.commissioned
    assert second.clearance.estimate == pytest.approx(6e-6, abs=1e-12)
    assert store.load("unit-1").history.as_built_clearance == 6e-6
