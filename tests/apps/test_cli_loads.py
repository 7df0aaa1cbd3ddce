"""``prsm-health simulate --load/--load-amplitude`` in every written form, the default share of
C_a, and the one-line errors (exit 2) of a bad unit, a bad rating and a load above C_0a."""

import json

import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.states import DEFAULT_LOAD_SHARE
from prsm_health.apps.cli import main
from prsm_health.physics.load_rating import load_ratings

P01 = load_ratings(preset("paper01"))


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--load", "4.4 lbf"], "argument --load: '4.4 lbf': unknown unit or rating 'lbf'"),
        (["--load", "20 % C_b"], "unknown unit or rating 'C_b'"),
        (["--load", "20 %"], "a percentage needs its rating"),
        (["--load-amplitude", "heavy"], "argument --load-amplitude"),
        (["--load-amplitude", "-5 % C_a"], "a swing must be ≥ 0"),
        (["--load", "190 % C_a"], f"C_0a = {P01.static:.4g} N"),
        (
            ["--load", "15kN", "--load-amplitude", "5 kN", "--load-profile", "reversing"],
            "profile.load = '15000 N' is invalid: the peak axial load",
        ),
    ],
)
def test_bad_loads_are_one_line_and_exit_2(tmp_path, capsys, monkeypatch, extra, needle):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "simulate", "--out", "x.parquet", "--duration", "0.001", *extra)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0]
    assert not (tmp_path / "x.parquet").exists()  # refused before simulating


def _labels(capsys, tmp_path, *extra):
    code, out, _ = run(
        capsys,
        "simulate",
        "--duration",
        "0.005",
        "--out",
        str(tmp_path / "r.parquet"),
        "--json",
        *extra,
    )
    assert code == 0
    return json.loads(out)["labels"]


def test_the_default_load_is_the_default_share_of_c_a(capsys, tmp_path):
    labels = _labels(capsys, tmp_path)
    assert labels["axial_load"] == pytest.approx(DEFAULT_LOAD_SHARE * P01.dynamic, rel=1e-9)
    assert labels["load_share"] == pytest.approx(DEFAULT_LOAD_SHARE, rel=1e-9)


def test_loads_in_shares_and_units(capsys, tmp_path):
    labels = _labels(
        capsys,
        tmp_path,
        "--load",
        "4.4kN",
        "--load-amplitude",
        "5 % C_a",
        "--load-profile",
        "reversing",
        "--load-frequency",
        "100",
    )
    assert labels["axial_load"] == pytest.approx(4400.0)
    assert labels["load_amplitude"] == pytest.approx(0.05 * P01.dynamic, rel=1e-9)
    assert labels["load_share"] == pytest.approx(4400.0 / P01.dynamic + 0.05, rel=1e-9)
    light = _labels(capsys, tmp_path, "--load", "2 % C_a")
    assert light["load_share"] == pytest.approx(0.02, rel=1e-9)
