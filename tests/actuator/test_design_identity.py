"""Design identity: the canonical dict form, the fingerprint, same_design, and the design of a
run (design_of) from its scenario and labels."""

from dataclasses import replace

import pytest

from prsm_health.actuator.design import PRESETS, preset
from prsm_health.actuator.design_files import (
    FINGERPRINT_LENGTH,
    canonical_design,
    design_fingerprint,
    design_of,
    design_to_toml,
    load_design,
    same_design,
)
from prsm_health.core.errors import ParameterError
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run


def _mine():
    """paper01 renamed, with a heavier nut: another design."""
    base = preset("paper01")
    return base.with_(name="acme-ema-24", masses=replace(base.masses, nut_mass=0.5))


def test_fingerprints_tell_the_presets_apart():
    prints = {design_fingerprint(name) for name in PRESETS}
    assert len(prints) == len(PRESETS)
    assert all(len(p) == FINGERPRINT_LENGTH and int(p, 16) >= 0 for p in prints)


def test_the_fingerprint_survives_every_form_a_design_travels_in(tmp_path):
    mine = _mine()
    path = tmp_path / "mine.toml"
    path.write_text(design_to_toml(mine))
    expected = design_fingerprint(mine)
    for form in (mine, mine.to_dict(), path, load_design(path)):
        assert design_fingerprint(form) == expected
    assert same_design(mine, path)


def test_the_name_is_for_people_a_dimension_decides():
    base = preset("paper01")
    renamed = base.with_(name="copy", reference="a catalogue")
    assert same_design(base, renamed) and design_fingerprint(base) == design_fingerprint(renamed)
    assert renamed != base  # == compares the name too; identity does not
    mine = _mine()
    assert not same_design(base, mine) and design_fingerprint(base) != design_fingerprint(mine)
    # same name, one dimension a few ulp apart: another design (floats compare exactly)
    nudged = base.with_(nut_outer_diameter=base.nut_outer_diameter * (1 + 1e-15))
    assert nudged.name == base.name and not same_design(base, nudged)


def test_integers_for_float_fields_are_the_same_design():
    data = preset("paper01").to_dict()
    data["screw_free_length"] = 1  # an integer where a float is meant: 1.0 m
    as_float = dict(data, screw_free_length=1.0)
    assert canonical_design(data) == canonical_design(as_float)
    assert design_fingerprint(data) == design_fingerprint(as_float)
    assert "name" not in canonical_design(data) and "reference" not in canonical_design(data)


def test_design_of_a_run_scenario_first_then_a_preset_name():
    mine = _mine()
    run = Run(
        [0.0, 1.0],
        {},
        1.0,
        scenario={"design": mine.to_dict()},
        operating=OperatingPoint(design=mine.name),
    )
    assert design_of(run) == mine
    assert design_of({"design": mine.to_dict()}) == mine  # a scenario dict
    # a dataset run: the design inside the recipe
    assert design_of({"recipe": {"design": mine.to_dict()}}, mine.name) == mine
    assert design_of({"design": "paper02"}, "paper01") == preset("paper02")
    assert design_of({}, "paper03") == preset("paper03")
    # known by name only, or by nothing: the caller decides
    assert design_of({}, "acme-ema-24") is None
    assert design_of({}, None) is None
    assert design_of({}) is None


def test_a_bad_design_dict_in_a_scenario_names_the_field():
    data = preset("paper01").to_dict()
    data["pitch"] = "2 mm"
    with pytest.raises(ParameterError, match=r"design\.pitch"):
        design_of({"design": data})
