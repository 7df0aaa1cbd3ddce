"""The efficiency indicator through the reduction: drive_torque is the motor's, screw_speed the
gearbox output's, so the input power needs the run's gear ratio."""

import pytest

from prsm_health import OperatingProfile, simulate
from prsm_health.signals.features import extract_features


def test_efficiency_of_a_geared_drive_is_its_energy_book():
    # lab-rig has the load cell the indicator needs; constant speed and load, so the window's
    # power ratio is the run's output over drive energy (the kinetic energy held): 0.848 seen,
    # within 1 % (the nut speed by differences of the LVDT and the sensors' noise)
    run = simulate(
        profile=OperatingProfile(duration=0.2, load="20 % C_a"), instrumentation="lab-rig", seed=1
    )
    assert run.labels["gear_ratio"] == 3.0
    book = -run.energy["load"] / run.energy["drive"]
    assert extract_features(run)["efficiency"] == pytest.approx(book, rel=0.01)
