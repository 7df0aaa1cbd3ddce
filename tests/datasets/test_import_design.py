"""A rig of one's own design imported: the map's design (a design file relative to the map, or an
inline table) travels with the recordings as a generated dataset's design does — manifest, run
labels, run scenario — and the design-dependent indicators are computed for it.

The recordings are short simulations (0.1 s) of paper01 with a nut twice as heavy, written as a
rig's CSV files (its own column names and units). Nothing checked depends on the trajectory of
a run: the design-dependent indicator compared is the healthy axial baseline frequency, a
function of the design and the measured mean load only.
"""

import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from prsm_health import simulate
from prsm_health.actuator.design import preset
from prsm_health.actuator.design_files import (
    design_fingerprint,
    design_of,
    design_to_toml,
    design_toml_tables,
    same_design,
)
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.apps.cli import main
from prsm_health.core.errors import PRSMHealthError
from prsm_health.datasets import Dataset
from prsm_health.datasets.importer import import_recordings
from prsm_health.io import load_column_map, read_recording
from prsm_health.io.column_map import column_map_from_text
from prsm_health.signals.features import dataset_features, extract_features

BASE = preset("paper01")
#: paper01 renamed, with a nut twice as heavy: its axial baseline frequency is 1/√2 of paper01's.
MINE = BASE.with_(name="rig-7", masses=replace(BASE.masses, nut_mass=2 * BASE.masses.nut_mass))
RATE = 20000.0
#: The rig's column names and units → contract channels.
COLUMNS = {
    "screw_angle": ("enc_deg", "deg", 180 / math.pi),
    "screw_speed": ("speed_rpm", "rpm", 60 / (2 * math.pi)),
    "drive_torque": ("torque_Nmm", "N*mm", 1e3),
    "nut_position": ("lvdt_mm", "mm", 1e3),
    "axial_load": ("load_kN", "kN", 1e-3),
    "nut_axial_accel": ("acc_ax_g", "g", 1 / 9.80665),
    "nut_tangential_accel": ("acc_t_g", "g", 1 / 9.80665),
    "nut_radial_x_accel": ("acc_x_g", "g", 1 / 9.80665),
    "nut_radial_y_accel": ("acc_y_g", "g", 1 / 9.80665),
}
MAP_BODY = f"sample_rate = {RATE}\n[columns]\n" + "".join(
    f'{channel} = "{column}"\n' for channel, (column, _, _) in COLUMNS.items()
)
MAP_BODY += "[units]\n" + "".join(f'{column} = "{unit}"\n' for column, unit, _ in COLUMNS.values())
#: (clearance [m], seed) of each recording.
CASES = [(5e-6, 1), (20e-6, 2), (5e-6, 3), (20e-6, 4)]


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    """The rig's folder: four CSV recordings, a labels table, the design file, the map."""
    root = tmp_path_factory.mktemp("rig")
    names = []
    for k, (clearance, seed) in enumerate(CASES):
        run = simulate(
            MINE,
            HealthState(clearance_screw=clearance, clearance_nut=clearance),
            OperatingProfile(
                speed=100.0, duration=0.1, load_profile="reversing", load_amplitude=300.0
            ),
            "ideal",
            seed=seed,
        )
        frame = pd.DataFrame(
            {column: run.channels[c] * scale for c, (column, _, scale) in COLUMNS.items()}
        )
        names.append(f"rec{k}.csv")
        frame.to_csv(root / names[-1], index=False)
    pd.DataFrame(
        {
            "recording": names,
            "clearance": [c for c, _ in CASES],
            "fault_class": ["healthy", "wear"] * 2,
        }
    ).to_csv(root / "labels.csv", index=False)
    (root / "mine.toml").write_text(design_to_toml(MINE))
    (root / "map.toml").write_text('design = "mine.toml"\n' + MAP_BODY)
    return root, [root / n for n in names]


@pytest.fixture(scope="module")
def imported(rig):
    root, files = rig
    import_recordings(files, root / "labels.csv", root / "map.toml", root / "ds")
    return Dataset(root / "ds")


def test_the_imported_dataset_carries_the_map_design(rig, imported):
    root, _ = rig
    fingerprint = design_fingerprint(root / "mine.toml")
    assert fingerprint != design_fingerprint("paper01")
    assert imported.design == MINE and design_fingerprint(imported.design) == fingerprint
    # as a generated dataset writes it: the design's dict form under the recipe, name and
    # fingerprint at a glance, every run labelled with both
    assert imported.manifest["recipe"]["design"] == MINE.to_dict()
    assert imported.manifest["design"] == {"name": "rig-7", "fingerprint": fingerprint}
    assert set(imported.runs["design"]) == {"rig-7"}
    assert set(imported.runs["design_fingerprint"]) == {fingerprint}
    assert same_design(design_of(imported.run(0, truth=False)), MINE)


def test_indicators_of_an_imported_dataset_use_the_design(imported):
    table = dataset_features(imported)
    assert len(table) == len(CASES)
    for name in ("axial_baseline_frequency", "mesh_frequency"):
        assert np.isfinite(table[name]).all(), name
    # the design itself was used, not paper01 (same threads, nut twice as heavy: f0 / √2)
    run = imported.run(int(table["run_id"].iloc[0]), truth=False)
    assert extract_features(run)["axial_baseline_frequency"] == pytest.approx(
        table["axial_baseline_frequency"].iloc[0], rel=1e-12
    )
    paper01 = extract_features(run, "paper01")["axial_baseline_frequency"]
    assert table["axial_baseline_frequency"].iloc[0] == pytest.approx(
        paper01 / math.sqrt(2), rel=1e-9
    )


def test_an_inline_design_table_is_the_same_design(rig, tmp_path):
    root, files = rig
    text = MAP_BODY + "\n" + "\n".join(design_toml_tables(MINE, "design")) + "\n"
    (tmp_path / "inline.toml").write_text(text)
    spec = load_column_map(tmp_path / "inline.toml")
    assert spec.design == MINE.to_dict()
    # a single recording read through the map (what `diagnose FILE --map` and the service
    # read) carries the design too: its operating point names it, the scenario holds it
    run = read_recording(files[0], column_map=tmp_path / "inline.toml")
    assert run.operating.design == "rig-7"
    assert run.operating.design_fingerprint == design_fingerprint(MINE)
    assert same_design(design_of(run), MINE)
    # an uploaded map (text: no folder) takes the inline table, and the preset, as they are
    assert column_map_from_text(text, "up.toml").design == MINE.to_dict()
    preset_map = column_map_from_text('design = "paper01"\n' + MAP_BODY)
    assert preset_map.design == "paper01"
    assert preset_map.operating().design_fingerprint == design_fingerprint("paper01")
    # an inline table that does not name itself is named after the map
    unnamed = text.replace('name = "rig-7"\n', "")
    (tmp_path / "bench.toml").write_text(unnamed)
    assert load_column_map(tmp_path / "bench.toml").prsm_design.name == "bench"


def test_the_design_file_is_read_relative_to_the_map(rig, tmp_path, monkeypatch):
    root, _ = rig
    monkeypatch.chdir(tmp_path)  # not the map's folder
    assert load_column_map(root / "map.toml").operating().design == "rig-7"


@pytest.mark.parametrize(
    "design, needle",
    [
        ('"missing.toml"', r"map\.toml: design: .*missing\.toml: no such design file$"),
        ('"acme-9"', r"map\.toml: design = 'acme-9' must be a preset \(paper01"),
        ("3", r"map\.toml: design = 3 must be a preset"),
        ('"bad.toml"', r"map\.toml: design: design\.n_rollers = -\d+ is invalid"),
    ],
)
def test_a_bad_design_is_one_line_naming_the_map_and_the_field(
    rig, tmp_path, capsys, design, needle
):
    root, files = rig
    (tmp_path / "bad.toml").write_text(
        design_to_toml(MINE).replace("n_rollers = ", "n_rollers = -")
    )
    (tmp_path / "map.toml").write_text(f"design = {design}\n" + MAP_BODY)
    with pytest.raises(PRSMHealthError, match=needle) as info:
        load_column_map(tmp_path / "map.toml")
    assert "\n" not in str(info.value)
    argv = ["import", *map(str, files), "--labels", str(root / "labels.csv")]
    argv += ["--map", str(tmp_path / "map.toml"), "--out", str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and "map.toml" in err
    assert not (tmp_path / "out").exists()


def test_an_uploaded_map_cannot_name_a_file():
    with pytest.raises(PRSMHealthError, match="up.toml: design = 'mine.toml' names a file"):
        column_map_from_text('design = "mine.toml"\n' + MAP_BODY, "up.toml")
