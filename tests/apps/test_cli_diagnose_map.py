"""`prsm-health diagnose FILE --map MAP.toml`: a rig's CSV read through its column map, the
screw speed derived from the angle as import derives it, diagnosed like any recording."""

import json

import pytest
from rig_log import COLUMNS, write_rig_csv

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.apps.cli import main

MAP = 'design = "paper01"\n' + COLUMNS


@pytest.fixture(scope="module")
def rig_csv(tmp_path_factory):
    # A flight-EMA recording written as a rig would log it: its own column names, degrees and
    # g, and no speed column (the drive's speed estimate is not logged).
    run = simulate(
        "paper01",
        HealthState.uniform(18e-6),
        OperatingProfile(
            duration=0.6,
            speed=100.0,
            load=2000.0,
            load_profile="reversing",
            load_amplitude=1500.0,
            load_frequency=10.0,
        ),
        "flight-ema",
        seed=5,
    )
    root = tmp_path_factory.mktemp("rig")
    write_rig_csv(root / "rig.csv", run)
    (root / "map.toml").write_text(MAP)
    return root


def test_diagnose_reads_a_rig_csv_through_its_map(rig_csv, capsys):
    assert main(["diagnose", str(rig_csv / "rig.csv"), "--map", str(rig_csv / "map.toml")]) == 0
    capsys.readouterr()
    code = main(
        ["diagnose", str(rig_csv / "rig.csv"), "--map", str(rig_csv / "map.toml"), "--json"]
    )
    answer = json.loads(capsys.readouterr().out)
    assert code == 0
    # every channel the model was trained with is there, the speed derived from the angle
    assert not any("missing" in w for w in answer["warnings"]), answer["warnings"]
    assert answer["fault_class"]


def test_without_its_map_the_rig_csv_is_one_line_error(rig_csv, capsys):
    assert main(["diagnose", str(rig_csv / "rig.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ")


def test_a_bad_map_is_one_line_error(rig_csv, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(MAP.replace('acc_g = "g"', 'acc_g = "furlongs"'))
    assert main(["diagnose", str(rig_csv / "rig.csv"), "--map", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "furlongs" in err[0]
