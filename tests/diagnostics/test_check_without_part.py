"""A health check diagnosed by a model without a check part: read window by window across its
phases, with exactly one line saying why and how to get a check part."""

from dataclasses import replace

import pytest

from prsm_health.diagnostics.diagnosis import diagnose, load_bundle


@pytest.fixture(scope="module")
def windows_only():
    return replace(load_bundle(), check=None)  # the shipped window model, its check part left off


def _no_part_lines(diagnosis) -> list[str]:
    return [w for w in diagnosis.warnings if "no health-check part" in w]


def test_a_check_without_a_check_part_says_so_in_one_line(short_check_run, windows_only):
    d = diagnose(short_check_run(), windows_only)
    (line,) = _no_part_lines(d)
    assert "window by window" in line and "out-of-distribution" in line
    assert "prsm-health train" in line and "docs/diagnostics.md" in line
    assert not d.check_phases and d.windows  # read across its phases, not phase by phase
    assert "what physics reads alone" in line


def test_without_a_check_part_physics_still_reads_the_check(short_check_run, windows_only):
    """The clearance measured from the check's reversal (the window model's own clearance
    replaced), the torque ratio and the temperature, from the check's phases."""
    d = diagnose(short_check_run(), windows_only)
    measured = d.measured_clearance
    assert measured is not None and [r.phase for r in measured.reversals] == ["swing"]
    assert measured.learnt is None and d.observability["clearance"] == 1.0
    assert d.clearance.lower < d.clearance.estimate < d.clearance.upper
    assert d.indicators["check_torque_ratio"] > 0
    assert d.indicators["check_temperature"] > 250
    assert d.indicators["check_zero_load_lost_motion"] == measured.zero_load_lost_motion


def test_a_recording_that_is_no_check_gets_no_such_line(reversing_run, windows_only):
    assert not _no_part_lines(diagnose(reversing_run(10e-6), windows_only))


def test_with_its_check_part_the_check_is_read_phase_by_phase(short_check_run):
    d = diagnose(short_check_run(), load_bundle())
    assert d.check_phases and not _no_part_lines(d)


def test_a_bundle_with_a_check_part_only_refuses_a_recording_that_is_no_check(reversing_run):
    from prsm_health.core.errors import PRSMHealthError
    from prsm_health.diagnostics.diagnosis import ModelBundle

    check_only = ModelBundle(None, None, [], {"design": "paper01", "name": "own"}, None, {})
    assert check_only.check_only
    with pytest.raises(PRSMHealthError, match="health-check part only"):
        diagnose(reversing_run(10e-6), check_only)
