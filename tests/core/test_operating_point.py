"""The typed parts of a Run beside its samples: the operating point and a check's phases —
validated, read leniently from the labels of older files, kept through every transformation."""

import math
from dataclasses import replace

import numpy as np
import pytest

from prsm_health.core.check_phases import CheckPhases, PhaseSpan
from prsm_health.core.errors import ParameterError
from prsm_health.core.operating_point import NO_DESIGN, OperatingPoint
from prsm_health.core.run import Run


def test_fields_validated_naming_the_field():
    point = OperatingPoint(screw_speed=np.float64(-50), axial_load=300, temperature=313.15)
    assert point.screw_speed == -50.0 and isinstance(point.screw_speed, float)
    assert point.gear_ratio == 1.0 and point.design is None
    for field, value in [
        ("gear_ratio", 0.0),
        ("gear_ratio", None),
        ("lead", -1e-3),
        ("load_amplitude", -1.0),
        ("temperature", 0.0),
        ("screw_speed", math.nan),
        ("axial_load", "300 N"),
        ("design", 3),
    ]:
        with pytest.raises(ParameterError, match=f"operating.{field} ="):
            OperatingPoint(**{field: value})


def test_known_fields_round_trip_through_their_record():
    point = OperatingPoint("paper01", "0123456789abcdef", 3.0, None, 100.0, 2000.0, 500.0, 313.15)
    record = point.as_dict()
    assert "lead" not in record  # unknown: not written
    assert OperatingPoint.from_labels(record) == point


def test_labels_of_older_files_are_read_leniently():
    labels = {
        "design": "paper02",
        "design_fingerprint": float("nan"),  # a missing cell read back from a table
        "gear_ratio": -2,  # unusable: not said
        "screw_speed": "fast",
        "axial_load": np.int64(700),
        "load_amplitude": 50.0,
        "temperature": 300.0,
        "clearance_screw": 1e-5,  # ground truth: stays in the labels
    }
    point = OperatingPoint.from_labels(labels)
    assert point == OperatingPoint(
        design="paper02", axial_load=700.0, load_amplitude=50.0, temperature=300.0
    )
    # an imported rig says design = None (NaN in a table): not a PRSM; no key: not said
    assert OperatingPoint.from_labels({"design": None}).design == NO_DESIGN
    assert OperatingPoint.from_labels({"design": float("nan")}).design == NO_DESIGN
    assert OperatingPoint.from_labels({}).design is None


def test_check_record_round_trip_and_older_records():
    check = CheckPhases(
        "c", (PhaseSpan(0, "a", 0.1, 0.2, "constant", 50.0, 0.0), PhaseSpan(1, "b", 0.3, 0.5))
    )
    assert CheckPhases.from_record(check.as_record()) == check
    assert check.names() == {0: "a", 1: "b"}
    phase = check.of_samples(np.arange(0.0, 0.6, 0.05))
    assert phase.dtype == np.int16
    assert phase.tolist() == [-1, -1, 0, 0, -1, -1, 1, 1, 1, 1, -1, -1]
    assert CheckPhases.from_record({}) is None and CheckPhases.from_record(None) is None
    with pytest.raises(KeyError):
        CheckPhases.from_record({"name": "c", "phases": [{"index": 0, "name": "a"}]})


def test_kept_through_every_transformation_of_a_run():
    point = OperatingPoint(design="paper01", gear_ratio=2.0)
    check = CheckPhases("c", (PhaseSpan(0, "a", 0.0, 0.5),))
    time = np.arange(2000) / 1000.0
    run = Run(
        time,
        {"nut_axial_accel": np.zeros(2000)},
        1000.0,
        {"clearance_screw": 1e-5},
        truth={"friction_torque": np.ones(2000)},
        check_phase=check.of_samples(time),
        check=check,
        operating=point,
    )
    parts = [
        run.without_truth(),
        run.slice(10, 900),
        *run.windows(0.5)[0],
        *run.phases().values(),
        replace(run, channels={}),
    ]
    for part in parts:
        assert part.operating is point and part.check is check
        assert part.labels == {"clearance_screw": 1e-5}
    assert run.without_truth().truth == {} and run.slice(0, 300).energy == {}
