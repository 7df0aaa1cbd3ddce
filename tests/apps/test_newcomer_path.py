"""A new user's own actuator, end to end through the front doors: a design file → generate →
train → evaluate → import a rig's CSV recordings (the map naming the design file) → diagnose a
CSV with ``--map`` → POST the CSV and its map to the service → fit a prognostics model for a
fleet of the design → prognose. Each step works, and each bad input gives one line
``error: …`` with exit status 2 (the service: a 4xx with one ``error`` line).

The design is paper01 renamed, with a nut twice as heavy: another mechanism, so nothing can
pass by falling back on a preset. Runs are short (0.5 s, the window the indicators need at these speeds) and few; the assertions are about the
path — what each step accepts, refuses and carries — never about a run's exact values.
"""

import json

import httpx
import pandas as pd
import pytest
from rig_log import COLUMNS, write_rig_csv

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.actuator.design import preset
from prsm_health.actuator.design_files import design_fingerprint, design_toml_tables, load_design
from prsm_health.apps.cli import main
from prsm_health.apps.service.app import create_app
from prsm_health.apps.service.server import serve_in_thread
from prsm_health.datasets import Dataset
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL

pytestmark = pytest.mark.slow  # ≈ 1 min: a dataset, a model, a fleet

RECIPE = """
name = "acme-study"
design = "mine.toml"
instrumentation = "flight-ema"
duration = 0.5
sample_rate = 20000
seed = 11
test_fraction = 0.25
batch_size = 3  # 8 batches: both workers busy to the end (3 batches of 8 leave one idle)
[profile]
load = 2000.0
load_profile = "reversing"
load_amplitude = 1500.0
load_frequency = 10.0
[options]
max_step = "auto"
[sweep]
mode = "random"
samples = 24
clearance = [3e-6, 40e-6]
speed = [100.0, 130.0]
"""

FLEET = """
name = "acme-fleet"
design = "mine.toml"
instrumentation = "flight-ema"
duration = 0.5
sample_rate = 20000
seed = 5
test_fraction = 0.25
batch_size = 3
[profile]
load_profile = "reversing"
[options]
max_step = "auto"
[sweep]
mode = "random"
speed = [100.0, 130.0]
load_amplitude = [1000.0, 2000.0]
[life]
units = 4
snapshots = 3
"""


def cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(result) -> bool:
    code, _, err = result
    lines = err.strip().splitlines()
    return code == 2 and len(lines) == 1 and lines[0].startswith("error: ")


def rig_csv(path, design, clearance, seed):
    run = simulate(
        design,
        HealthState.uniform(clearance),
        OperatingProfile(
            duration=0.6,
            speed=100.0,
            load=2000.0,
            load_profile="reversing",
            load_amplitude=1500.0,
            load_frequency=10.0,
        ),
        "flight-ema",
        seed=seed,
        options=SimulationOptions(max_step="auto"),
    )
    write_rig_csv(path, run)


def test_own_design_through_every_front_door(tmp_path, capsys):
    # 1. the design file: a template, renamed, a heavier nut
    base = preset("paper01")
    code, template, _ = cli(capsys, "design", "template", "--from", "paper01")
    assert code == 0
    nut = f"nut_mass = {base.masses.nut_mass!r}"
    assert nut in template
    mine_text = template.replace('name = "paper01"', 'name = "acme-ema-24"').replace(
        nut, f"nut_mass = {2 * base.masses.nut_mass!r}"
    )
    (tmp_path / "mine.toml").write_text(mine_text)
    mine = load_design(tmp_path / "mine.toml")
    assert mine.name == "acme-ema-24" and design_fingerprint(mine) != design_fingerprint(base)
    assert cli(capsys, "design", "check", tmp_path / "mine.toml")[0] == 0
    (tmp_path / "typo.toml").write_text(mine_text.replace("n_rollers", "n_roller"))
    bad = cli(capsys, "design", "check", tmp_path / "typo.toml")
    assert one_line_error(bad) and "did you mean 'n_rollers'" in bad[2]

    # 2. generate a dataset of it
    (tmp_path / "recipe.toml").write_text(RECIPE)
    data = tmp_path / "data"
    generated = cli(capsys, "generate", tmp_path / "recipe.toml", "--out", data, "--workers", 2)
    assert generated[0] == 0, generated[2]
    assert design_fingerprint(Dataset(data).design) == design_fingerprint(mine)
    (tmp_path / "lost.toml").write_text(RECIPE.replace("mine.toml", "gone.toml"))
    assert one_line_error(cli(capsys, "generate", tmp_path / "lost.toml", "--out", tmp_path / "x"))

    # 3. train, 4. evaluate: the model is of that design
    model = tmp_path / "acme.skops"
    assert cli(capsys, "train", data, "--out", model, "--cv", 2)[0] == 0
    code, out, _ = cli(capsys, "evaluate", model, data, "--json")
    assert code == 0 and json.loads(out)["model"]["design"] == "acme-ema-24"
    assert one_line_error(cli(capsys, "train", tmp_path / "recipe.toml", "--out", model))
    refused = cli(capsys, "evaluate", DEFAULT_MODEL, data)  # the shipped model: paper01's
    assert one_line_error(refused) and "acme-ema-24" in refused[2]

    # 5. import the rig's recordings: its map names the design file
    (tmp_path / "map.toml").write_text('design = "mine.toml"\n' + COLUMNS)
    rig = tmp_path / "rig"
    rig.mkdir()
    names = []
    for i, clearance in enumerate((5e-6, 12e-6, 25e-6, 35e-6)):
        rig_csv(rig / f"r{i}.csv", mine, clearance, seed=40 + i)
        names.append(f"r{i}.csv")
    pd.DataFrame({"recording": names, "clearance": [5e-6, 12e-6, 25e-6, 35e-6]}).to_csv(
        tmp_path / "labels.csv", index=False
    )
    imported = tmp_path / "imported"
    args = ("import", *(rig / n for n in names), "--labels", tmp_path / "labels.csv")
    assert cli(capsys, *args, "--map", tmp_path / "map.toml", "--out", imported)[0] == 0
    assert design_fingerprint(Dataset(imported).design) == design_fingerprint(mine)
    (tmp_path / "lost-map.toml").write_text('design = "gone.toml"\n' + COLUMNS)
    assert one_line_error(
        cli(capsys, *args, "--map", tmp_path / "lost-map.toml", "--out", tmp_path / "y")
    )

    # 6. diagnose one CSV through the map, with the design's model; the shipped one refuses
    csv = rig / "r2.csv"
    code, out, _ = cli(
        capsys, "diagnose", csv, "--map", tmp_path / "map.toml", "--model", model, "--json"
    )
    answer = json.loads(out)
    assert code == 0 and answer["model"]["design"] == "acme-ema-24"
    assert not any("missing" in w for w in answer["warnings"]), answer["warnings"]
    refused = cli(capsys, "diagnose", csv, "--map", tmp_path / "map.toml")
    assert one_line_error(refused) and "acme-ema-24" in refused[2] and "paper01" in refused[2]

    # 7. the service: the CSV and its map (the design inline: an upload names no server file)
    inline = COLUMNS + "\n".join(design_toml_tables(mine, "design")) + "\n"
    app = create_app(model, db_path=tmp_path / "history.sqlite", warmup=False)
    with serve_in_thread(app) as url:
        files = {"file": ("r2.csv", csv.read_bytes()), "map": ("map.toml", inline.encode())}
        response = httpx.post(f"{url}/v1/diagnose/file", files=files, timeout=120)
        assert response.status_code == 200, response.text
        assert response.json()["diagnosis"]["model"]["design"] == "acme-ema-24"
        bad_map = {
            "file": files["file"],
            "map": ("map.toml", b'design = "mine.toml"\n' + COLUMNS.encode()),
        }
        response = httpx.post(f"{url}/v1/diagnose/file", files=bad_map, timeout=120)
        assert 400 <= response.status_code < 500 and len(response.json()["error"].splitlines()) == 1

    # 8. a prognostics model for a fleet of the design, then a prognosis from a history
    (tmp_path / "fleet.toml").write_text(FLEET)
    fleet = tmp_path / "fleet"
    assert cli(capsys, "generate", tmp_path / "fleet.toml", "--out", fleet, "--workers", 2)[0] == 0
    prognostics = tmp_path / "acme-prognostics.json"
    code, out, _ = cli(
        capsys, "train", fleet, "--target", "rul", "--model", model, "--out", prognostics, "--json"
    )
    assert code == 0 and json.loads(out)["design"] == "acme-ema-24"
    history = tmp_path / "history.csv"
    pd.DataFrame(
        {
            "age_hours": [100.0, 400.0, 800.0],
            "clearance": [8e-6, 12e-6, 17e-6],
            "clearance_lower": [5e-6, 9e-6, 14e-6],
            "clearance_upper": [11e-6, 15e-6, 20e-6],
            "design": ["acme-ema-24"] * 3,
            "design_fingerprint": [design_fingerprint(mine)] * 3,
        }
    ).to_csv(history, index=False)
    assert cli(capsys, "prognose", history, "--model", prognostics)[0] == 0
    assert one_line_error(cli(capsys, "prognose", history))  # the shipped model: paper01's
