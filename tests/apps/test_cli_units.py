"""Units checked against physics at the front doors: `prsm-health import` and
`prsm-health diagnose FILE --map` say, in one warning line, which column's declared unit the
actuator's physics doubts and by which factor; a recording declared right says nothing."""

import pandas as pd
import pytest
from rig_log import COLUMNS, write_rig_csv

from prsm_health.apps.cli import main

# the rig's map with one column declared wrong
MAPS = {
    "right": COLUMNS,
    "mm as m": COLUMNS.replace('pos_mm = "mm"', 'pos_mm = "m"'),
    "g as m/s²": COLUMNS.replace('acc_g = "g"', 'acc_g = "m/s^2"'),
}


@pytest.fixture(scope="module")
def rig(tmp_path_factory, short_check_run):
    # the short health check (1 s, flight-ema): speed steps for the rigid-body acceleration
    root = tmp_path_factory.mktemp("units")
    write_rig_csv(root / "rig.csv", short_check_run())
    pd.DataFrame({"recording": ["rig.csv"], "fault_class": ["healthy"]}).to_csv(
        root / "labels.csv", index=False
    )
    for k, columns in enumerate(MAPS.values()):
        (root / f"map{k}.toml").write_text('design = "paper01"\n' + columns)
    return root


def _map(rig, name):
    return str(rig / f"map{list(MAPS).index(name)}.toml")


def _import_warnings(rig, name, capsys) -> list[str]:
    out = rig / f"ds-{list(MAPS).index(name)}"
    args = ["--labels", str(rig / "labels.csv"), "--map", _map(rig, name), "--out", str(out)]
    assert main(["import", str(rig / "rig.csv"), *args, "--overwrite"]) == 0
    return [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning:")]


def test_a_recording_declared_right_imports_without_a_unit_warning(rig, capsys):
    assert _import_warnings(rig, "right", capsys) == []


def test_a_position_in_mm_declared_m_is_one_warning_naming_column_and_factor(rig, capsys):
    (line,) = _import_warnings(rig, "mm as m", capsys)
    assert "column 'pos_mm' (nut_position)" in line
    assert "declared m, the values look like mm (×1000)" in line


def test_an_acceleration_in_g_declared_m_s2_is_one_warning(rig, capsys):
    (line,) = _import_warnings(rig, "g as m/s²", capsys)
    assert "column 'acc_g' (nut_axial_accel)" in line
    assert "declared m/s^2, the values look like g (÷9.81)" in line


def test_diagnose_prints_the_line_and_still_diagnoses(rig, capsys):
    csv = str(rig / "rig.csv")
    assert main(["diagnose", csv, "--map", _map(rig, "mm as m"), "--json"]) == 0
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.startswith("warning:")]
    assert len(lines) == 1 and "'pos_mm'" in lines[0] and "(×1000)" in lines[0]
    assert '"fault_class"' in captured.out
    assert main(["diagnose", csv, "--map", _map(rig, "right"), "--json"]) == 0
    assert "warning:" not in capsys.readouterr().err
