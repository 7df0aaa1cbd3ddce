"""``simulate --check FILE``: a user's health check through the front door — the phase column
read back by pyarrow, and bad checks refused in one line with exit status 2, before simulating."""

import pytest

from prsm_health.apps.cli import main

#: A two-phase check short enough for a unit test (0.1 s simulated).
TINY = """
[check]
name = "tiny"
[[check.phases]]
name = "no load"
speed = 50.0
load = 0.0
duration = 0.02
ramp_time = 0.01
[[check.phases]]
name = "loaded"
speed = -50.0
load = "{load}"
duration = 0.03
ramp_time = 0.01
"""


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_check_file_records_its_phases(tmp_path, capsys):
    import pyarrow.parquet as pq

    check = tmp_path / "tiny.toml"
    check.write_text(TINY.format(load="10 % C_a"))
    out = tmp_path / "c.parquet"
    code, text, _ = run(capsys, "simulate", "--check", check, "--out", out)
    assert code == 0 and "no load" in text and "loaded" in text
    table = pq.read_table(out)
    phases = table.column("check_phase").to_numpy()
    assert set(phases) == {-1, 0, 1}  # the ramps belong to no phase
    assert b"prsm_health.health_check" in table.schema.metadata


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ('[check]\nname = "empty"\n', "phases"),
        (TINY.format(load="10 % C_x"), "C_x"),
        (TINY.format(load="150 % C_0a"), "C_0a"),
        # 200 rad/s at the screw is 600 rad/s at the sized motor (ratio 3), above its 481.7
        (TINY.replace("speed = -50.0", "speed = -200.0").format(load="0"), "max_speed"),
    ],
)
def test_bad_checks_are_one_line_and_exit_2(tmp_path, capsys, text, needle):
    check = tmp_path / "bad.toml"
    check.write_text(text)
    out = tmp_path / "x.parquet"
    code, _, err = run(capsys, "simulate", "--check", check, "--out", out)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), err
    assert needle in lines[0]
    assert not out.exists()


def test_a_missing_check_file_is_one_line(tmp_path, capsys):
    code, _, err = run(capsys, "simulate", "--check", tmp_path / "gone.toml", "--out", "x.parquet")
    assert code == 2 and err.startswith("error: ") and len(err.strip().splitlines()) == 1
