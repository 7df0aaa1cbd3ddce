"""``simulate``'s health flags read by the rules of a health file (``HealthState.from_dict``):
the same state from ``--clearance X`` as from a file saying ``clearance = X``, and the flags
laid over a file replace what it says of the same parameters. Scenarios are built, not
simulated."""

import pytest

from prsm_health.apps.cli import build_parser
from prsm_health.apps.cli.simulate import scenario_from_args
from prsm_health.core.errors import PRSMHealthError


def scenario(*argv):
    return scenario_from_args(build_parser().parse_args(["simulate", *map(str, argv)]))


def health_file(tmp_path, text: str) -> str:
    path = tmp_path / "health.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    "flags, table",
    [
        (["--clearance", 25e-6], "clearance = 25e-6\n"),
        (
            ["--clearance", 25e-6, "--gear-clearance", 40e-6],
            "clearance = 25e-6\nclearance_gear = 40e-6\n",
        ),
        (["--gear-clearance", 40e-6], "clearance_gear = 40e-6\n"),
        (
            ["--wear-spread", 0.2, "--friction-scale", 1.5, "--preload", 5e-6],
            "wear_spread = 0.2\nfriction_scale = 1.5\npreload = 5e-6\n",
        ),
    ],
    ids=["clearance", "clearance and gear", "gear alone", "other flags"],
)
def test_flags_and_file_give_the_same_labels(tmp_path, flags, table):
    from_flags = scenario(*flags)
    from_file = scenario("--health", health_file(tmp_path, table))
    assert from_flags.labels() == from_file.labels()
    assert from_flags.health == from_file.health


def test_clearance_gives_the_gear_backlash_too():
    h = scenario("--clearance", 25e-6).health
    assert h.clearance_screw == h.clearance_nut == h.clearance_gear == 25e-6


def test_flags_replace_what_the_file_says(tmp_path):
    path = health_file(
        tmp_path,
        "clearance_screw = 30e-6\nclearance_nut = 35e-6\nclearance_gear = 45e-6\n"
        'wear_spread = 0.3\n[[faults]]\nkind = "spall"\nlocation = "screw"\ndepth = 20e-6\n',
    )
    base = scenario("--health", path).health
    assert (base.clearance_screw, base.clearance_gear, base.wear_spread) == (30e-6, 45e-6, 0.3)
    # --clearance replaces every clearance of the file; a flag equal to the library's default
    # (wear spread 0) still replaces the file's value; what no flag names is kept
    h = scenario("--health", path, "--clearance", 12e-6, "--wear-spread", 0).health
    assert h.clearance_screw == h.clearance_nut == h.clearance_gear == 12e-6
    assert h.wear_spread == 0 and h.faults == base.faults
    h = scenario("--health", path, "--clearance", 12e-6, "--gear-clearance", 50e-6).health
    assert (h.clearance_screw, h.clearance_nut, h.clearance_gear) == (12e-6, 12e-6, 50e-6)
    h = scenario("--health", path, "--gear-clearance", 50e-6).health
    assert (h.clearance_screw, h.clearance_nut, h.clearance_gear) == (30e-6, 35e-6, 50e-6)


def test_a_bad_flag_is_named_as_a_file_field_would_be():
    with pytest.raises(PRSMHealthError, match="health.clearance_gear"):
        scenario("--gear-clearance=-1e-6")
