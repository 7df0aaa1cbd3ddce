"""A health check cut short (a truncated file, a logger stopped) through the shipped model: a
phase the recording does not hold whole is not read, the quantities it shows are not
observable (the clearance interval is the trained range), and one warning line names the cut
phase, how long it is against what it needs, and what to do.

Before this, a check cut 0.02 s into its slow reversal read a clearance of 4.5 [2.2, 8.2] µm
for a true 10–10.7 µm, the reversal listed as read, no warning.
"""

import numpy as np
import pytest

from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
from prsm_health.signals.check_indicators import check_indicators
from prsm_health.signals.check_roles import phase_conditions

CUTS = 20
#: The roles each target of the check model needs (diagnostics.check_model: the clearance
#: reads the reversal; the classes their role in ROLE_OF_CLASS): a check cut inside or before
#: one of these phases must name it.
NEEDED_ROLES = ("no_load", "torque_pair", "reversal", "high_load")


@pytest.fixture(scope="module")
def check(short_check_run):
    return short_check_run()


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


def _truths(run) -> list[float]:
    """The clearances an interval must hold: the check model's training target (the mean of
    the screw- and nut-side labels, training.train.clearance_target) and the clearance the
    simulated unit realised (its threads' mean over the run). Both, without tolerance: they
    differ by 0.65 µm on this run, and an interval that misses either is a miss."""
    labels = run.labels
    return [
        0.5 * (labels["clearance_screw"] + labels["clearance_nut"]),
        labels["clearance_screw_realised_mean"],
    ]


def test_a_whole_check_is_read_whole(check, bundle):
    # the premise of the cut test: the whole check reads every role and holds the truth
    d = diagnose(check, bundle)
    assert set(d.check_phases) == set(NEEDED_ROLES)
    assert not any(w.startswith("check cut short") for w in d.warnings)
    for truth in _truths(check):
        assert d.clearance["lower"] <= truth <= d.clearance["upper"]


def test_twenty_cut_checks_hold_the_truth_and_name_the_cut_phase(check, bundle):
    rate = check.sample_rate
    rng = np.random.default_rng(42)
    # from the fewest samples a recording may have (0.02 s: Run.validate's 256 samples) to the
    # end: cuts in every phase, in the ramps, and after the last phase
    cuts = np.sort(rng.uniform(0.02, check.duration, CUTS))
    model_range = tuple(bundle.check["clearance_range"])
    for cut in cuts:
        part = check.slice(0, int(cut * rate))
        d = diagnose(part, bundle)
        where = f"cut at {cut:.3f} s"
        for truth in _truths(check):
            assert d.clearance["lower"] <= truth <= d.clearance["upper"], where
        lines = [w for w in d.warnings if w.startswith("check cut short")]
        assert len(lines) <= 1, where
        # the phases not recorded whole: those the cut falls inside or before
        cut_phases = {p.name for p in check.check.phases if p.end > part.time[-1] + 1 / rate}
        read = " / ".join(d.check_phases.values())
        for name in cut_phases:
            assert f'"{name}"' in lines[0], where
            assert name not in read.split(" / "), where
        if not cut_phases:
            assert not lines, where
            assert set(d.check_phases) == set(NEEDED_ROLES), where
        assert "record the whole check" in (lines[0] if lines else "record the whole check")
        swing = next(p for p in check.check.phases if p.name == "swing")
        if swing.name in cut_phases:
            assert not d.observability["clearance"], where
            assert (d.clearance["lower"], d.clearance["upper"]) == model_range, where
            assert "the clearance" in lines[0], where


def test_the_cut_line_says_how_long_against_what_it_needs(check, bundle):
    swing = next(p for p in check.check.phases if p.name == "swing")
    part = check.slice(0, int((swing.start + 0.09) * check.sample_rate))
    d = diagnose(part, bundle)
    assert d.warnings[0].startswith("check cut short")
    assert '"swing" 0.09 s recorded of the 0.25 s it needs' in d.warnings[0]
    assert '"heavy" not recorded' in d.warnings[0]
    assert "reversal" not in d.check_phases and "high_load" not in d.check_phases
    assert d.fault_class == "cannot_tell"  # a spall cannot be shown without the heavy stroke
    # the one line replaces the "no slow reversal in this check" note: the check had one
    assert not any("no slow reversal" in w for w in d.warnings)


def test_a_whole_phase_too_short_for_its_role_is_not_read(check):
    # a reversal phase with a single reversal: recorded whole (its record says so), but the
    # lost-motion loop is not closed
    swing = next(p for p in check.check.phases if p.name == "swing")
    short_end = swing.start + 0.09  # 0.72 of a 0.125 s period: one reversal
    phases = tuple(
        p if p.name != "swing" else type(p)(**{**p.as_dict(), "end": short_end})
        for p in check.check.phases
    )
    record = type(check.check)(check.check.name, phases)
    from dataclasses import replace

    run = replace(check, check=record, check_phase=record.of_samples(check.time))
    conditions = {c.name: c for c in phase_conditions(run)}
    assert not conditions["swing"].is_cut
    reading = check_indicators(run)
    assert "reversal" not in reading.roles
    assert '"swing" 1 reversal(s) of the 2 it needs' in reading.cut["reversal"]
    assert np.isnan(reading.indicators["check_reversal_lost_motion"])
