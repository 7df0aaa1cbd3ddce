"""Units checked against physics (:mod:`prsm_health.signals.unit_checks`): a recording in SI
passes every check; a channel scaled by a unit slip is named, with the slip's factor."""

import dataclasses
import math

import numpy as np
import pytest

from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.io.column_map import unit_slips
from prsm_health.signals.unit_checks import unit_mismatches, unit_warnings

G = 9.80665
#: What the reader passes for a recording in the contract's SI units.
SI_SLIPS = {
    "nut_position": unit_slips("m"),
    "screw_angle": unit_slips("rad"),
    "nut_axial_accel": unit_slips("m/s^2"),
    "drive_torque": unit_slips("N*m"),
}


def _scaled(run: Run, **factors) -> Run:
    return dataclasses.replace(
        run, channels={k: v * factors.get(k, 1.0) for k, v in run.channels.items()}
    )


def test_recordings_in_si_raise_nothing(reversing_run, short_check_run):
    # constant speed under a reversing load (ideal sensors, load cell) and a health check
    # (flight-ema: resolver, LVDT, MEMS accelerometer; speed steps and reversals)
    assert unit_warnings(reversing_run(20e-6)) == []
    assert unit_mismatches(short_check_run(), slips=SI_SLIPS) == []


@pytest.mark.parametrize(
    "channel, factor, named",
    [
        ("nut_position", 1e3, 1e3),  # mm declared m
        ("nut_position", 1e-3, 1e-3),  # m declared mm
        ("nut_axial_accel", 1 / G, 1 / G),  # g declared m/s²
        ("nut_axial_accel", 1e3, 1e3),  # mm/s² declared m/s²
        ("screw_angle", 180 / math.pi, 180 / math.pi),  # degrees declared rad
    ],
)
def test_a_slip_names_the_channel_and_its_factor(short_check_run, channel, factor, named):
    found = unit_mismatches(_scaled(short_check_run(), **{channel: factor}), slips=SI_SLIPS)
    assert [(m.channel, m.factor) for m in found] == [(channel, named)]
    assert abs(math.log10(found[0].ratio / factor)) < 0.05  # measured, not only snapped


def test_without_the_units_table_powers_of_ten_are_named(short_check_run):
    # g is 10 within 2 %: without the reader's units it is named as a power of ten
    (found,) = unit_mismatches(_scaled(short_check_run(), nut_axial_accel=1 / G))
    assert found.factor == 0.1
    assert found.sentence().endswith("the values look 10× too small")


def test_a_torque_1000_times_the_load_s_is_named(reversing_run):
    (found,) = unit_mismatches(_scaled(reversing_run(20e-6), drive_torque=1e3))
    assert (found.channel, found.check, found.factor) == ("drive_torque", "torque", 1e3)
    assert "axial_load ÷1000" in found.sentence()


def test_a_rig_without_a_design_is_checked_against_its_lead():
    # a ball screw of 5 mm lead at 25 Hz, reversing every second: position logged in mm
    t = np.arange(500) / 25.0
    angle = 2 * np.pi * 3.0 * np.sin(2 * np.pi * 0.5 * t)
    position = 0.005 * angle / (2 * np.pi) - 2e-5 * np.sign(np.gradient(angle))
    run = Run(
        t,
        {"screw_angle": angle, "nut_position": position},
        25.0,
        operating=OperatingPoint(lead=0.005),
    )
    assert unit_mismatches(run) == []
    (found,) = unit_mismatches(_scaled(run, nut_position=1e3))
    assert found.channel == "nut_position" and found.factor == 1e3
    assert "implied lead 5000 mm/rev against the given lead 5 mm/rev" in found.sentence()


def test_what_the_reader_would_refuse_is_skipped(short_check_run):
    run = short_check_run()
    broken = dict(run.channels, nut_position=np.full(len(run), np.nan))
    assert unit_mismatches(dataclasses.replace(run, channels=broken)) == []
