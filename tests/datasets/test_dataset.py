"""Recipes, deterministic parallel generation, resume after a kill, Dask, independent readers."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from prsm_health.core.channels import CHANNEL_NAMES, STANDARD_TRUTH_NAMES, UNITS, truth_column
from prsm_health.datasets import Dataset, Recipe, RecipeError, generate, load_recipe
from prsm_health.simulation.scenario import simulate

TINY = textwrap.dedent(
    """
    name = "tiny"
    design = "paper01"
    duration = 0.02
    sample_rate = 20000
    instrumentation = "ideal"
    seed = 11
    batch_size = 2
    test_fraction = 0.34
    [sweep]
    clearance = [5e-6, 25e-6, 40e-6]
    speed = [80.0]
    load = [100.0, 200.0]
    repeats = 1
    """
)


@pytest.fixture
def recipe_path(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def _signals(out):
    frames = [pd.read_parquet(p) for p in sorted((out / "signals").glob("part-*.parquet"))]
    return pd.concat(frames).sort_values(["run_id", "time"]).reset_index(drop=True)


def test_minimal_recipe_and_run_enumeration(recipe_path):
    r = load_recipe(recipe_path)
    specs = r.runs()
    assert len(specs) == 6 and [s.run_id for s in specs] == list(range(6))
    assert sum(s.split == "test" for s in specs) == 2  # round(6 × 0.34)
    assert specs == load_recipe(recipe_path).runs()  # deterministic
    assert len({s.seed for s in specs}) == 6
    assert [len(b) for b in r.batches()] == [2, 2, 2]


def test_latin_hypercube_and_bad_recipes():
    base = dict(name="x", design="paper01", duration=0.01, sample_rate=20000, seed=1)
    lhs = Recipe.from_dict(
        dict(
            base,
            sweep={"mode": "lhs", "samples": 10, "clearance": [0.0, 4e-5], "speed": [50.0, 100.0]},
        )
    )
    points = np.array([[s.point["clearance"], s.point["speed"]] for s in lhs.runs()])
    # Latin hypercube: each of the 10 strata of each axis holds exactly one sample.
    assert sorted(np.floor(points[:, 0] / 4e-6).astype(int)) == list(range(10))
    for bad, key in [
        (dict(base, sweep={"clearance": 1e-5}), "sweep.clearance"),
        (dict(base, sweep={"speed": [1.0]}, colour="red"), "colour"),
        (dict(base, sweep={"clearance": [-1e-6]}), "health.clearance_screw"),
        (dict(base, design="paper99", sweep={}), "design"),
        ({k: v for k, v in base.items() if k != "seed"} | {"sweep": {}}, "seed"),
        (dict(base, sweep={"mode": "lhs", "clearance": [0, 1e-5]}), "sweep.samples"),
    ]:
        with pytest.raises(RecipeError, match=key):
            Recipe.from_dict(bad)


def test_domain_randomised_group_fields():
    """Fields of profile, options, drive_train and instrumentation drawn per run: reach the
    scenario, land in the labels under their dotted names, and leave the recipe untouched."""
    base = dict(name="x", design="paper01", duration=0.01, sample_rate=20000, seed=1)
    sweep = {
        "mode": "random",
        "samples": 4,
        "profile": {"accel_time": [0.001, 0.01]},
        "options": {"contact_restitution": [0.4, 0.8], "variation": {"pitch_error": [1e-6, 3e-6]}},
        "drive_train": {"coupling_stiffness": [1e3, 2e3]},
        "instrumentation": {"nut_axial_accel": {"noise_density_ug": [20.0, 60.0]}},
    }
    recipe = Recipe.from_dict(dict(base, sweep=sweep))
    seen = set()
    for spec in recipe.runs():
        sc, labels = spec.scenario(), spec.labels()
        p = spec.point
        assert sc.profile.accel_time == p["profile.accel_time"] == labels["profile.accel_time"]
        assert sc.options.contact_restitution == p["options.contact_restitution"]
        assert sc.options.variation.pitch_error == p["options.variation.pitch_error"]
        assert sc.drive_train.coupling_stiffness == p["drive_train.coupling_stiffness"]
        ug = p["instrumentation.nut_axial_accel.noise_density_ug"]
        assert sc.instrumentation.nut_axial_accel.noise_density == pytest.approx(ug * 9.80665e-6)
        assert 1e3 <= p["drive_train.coupling_stiffness"] <= 2e3
        seen.add(round(p["drive_train.coupling_stiffness"]))
    assert len(seen) == 4  # a fresh draw per run
    assert recipe.instrumentation == "flight-ema" and recipe.options == {}
    # the flat (dotted) form is the same recipe
    assert Recipe.from_dict(recipe.source).runs() == recipe.runs()
    for bad, needle in [
        ({"drive_train": {"coupling_stiff": [1e3, 2e3]}}, "coupling_stiff"),
        ({"drive_train": {"coupling_stiffness": [-1e3, 2e3]}}, "coupling_stiffness"),
        ({"colour": {"red": [0, 1]}}, r"unknown table \[colour\] in \[sweep\]"),
    ]:
        with pytest.raises(RecipeError, match=needle):
            Recipe.from_dict(dict(base, sweep={"mode": "random", "samples": 3, **bad}))


def test_recipe_instrumentation(tmp_path):
    from prsm_health.simulation.instrumentation import load_instrumentation

    base = dict(name="x", design="paper01", duration=0.01, sample_rate=10000, seed=1, sweep={})
    # a built-in by name, at the recipe's sample rate
    named = Recipe.from_dict(dict(base, instrumentation="lab-rig")).runs()[0].scenario()
    lab = load_instrumentation("lab-rig")
    assert named.instrumentation.fitted == lab.fitted
    assert named.instrumentation.sample_rate == 10000
    # no instrumentation: the default, flight-ema
    default = Recipe.from_dict(base).runs()[0].scenario()
    assert default.instrumentation.name == "flight-ema"
    # a table: a profile (here a file next to the recipe) plus overrides, stored complete so a
    # worker rebuilds the same scenarios from the recipe's source alone
    (tmp_path / "quiet.toml").write_text('profile = "flight-ema"\n[drive_torque]\nnoise = 0.0\n')
    table = {"profile": "quiet.toml", "nut_axial_accel": {"noise_density_ug": 40.0}}
    recipe = Recipe.from_dict(dict(base, instrumentation=table), base=tmp_path)
    inst = recipe.runs()[0].scenario().instrumentation
    assert inst.drive_torque.noise == 0.0 and inst.sample_rate == 10000
    assert inst.nut_axial_accel.noise_density == pytest.approx(40e-6 * 9.80665)
    rebuilt = Recipe.from_dict(recipe.source)
    assert rebuilt.runs()[0].scenario() == recipe.runs()[0].scenario()
    assert rebuilt.fingerprint == recipe.fingerprint
    for bad, needle in [
        (dict(base, sensors={"accel_noise": 0.05}), "replaced by instrumentation"),
        (dict(base, instrumentation={"profile": "ideal", "sample_rate": 5e3}), "top-level"),
        (dict(base, instrumentation="flight-emma"), "built-in profiles: flight-ema"),
        (
            dict(base, instrumentation={"profile": "ideal", "axial_load": {"x": 1}}),
            r"unknown key 'x' in \[instrumentation.axial_load\]",
        ),
    ]:
        with pytest.raises(RecipeError, match=needle):
            Recipe.from_dict(bad)


def test_workers_1_and_2_identical_and_readers(recipe_path, tmp_path):
    a = generate(recipe_path, tmp_path / "a", workers=1, progress=False)
    b = generate(recipe_path, tmp_path / "b", workers=2, progress=False)
    assert a.generated_runs == b.generated_runs == 6
    sa, sb = _signals(tmp_path / "a"), _signals(tmp_path / "b")
    pd.testing.assert_frame_equal(sa, sb)
    ra = pd.read_parquet(tmp_path / "a" / "runs.parquet")
    assert list(ra["run_id"]) == list(range(6))
    manifest = json.loads((tmp_path / "a" / "manifest.json").read_text())
    assert manifest["counts"]["runs"] == 6 and manifest["channels"]["nut_axial_accel"] == "m/s^2"
    # units and sample rate in the Parquet schema metadata too
    meta = pq.read_schema(next((tmp_path / "a" / "signals").glob("*.parquet"))).metadata
    assert float(meta[b"prsm_health.sample_rate"]) == 20000.0
    # independent readers, no custom code: polars and duckdb
    import duckdb
    import polars as pl

    runs_pl = pl.read_parquet(tmp_path / "a" / "runs.parquet")
    assert runs_pl.height == 6
    signals_pl = pl.read_parquet(str(tmp_path / "a" / "signals" / "*.parquet"))
    truth_columns = [truth_column(n) for n in STANDARD_TRUTH_NAMES]
    assert signals_pl.columns == ["run_id", "time", *CHANNEL_NAMES, *truth_columns]
    assert manifest["truth"] == {c: UNITS[c] for c in truth_columns}
    assert "carrier_speed" not in manifest["channels"]
    shard = pq.read_table(next((tmp_path / "a" / "signals").glob("*.parquet")))
    assert shard.schema.field("truth_friction_torque").type == "float"  # recipe dtype float32
    assert json.loads(meta[b"prsm_health.units"])["truth_load_force"] == "N"
    # the units where every reader sees them, as in a single-run file: each field's and pandas'
    assert shard.schema.field("nut_axial_accel").metadata[b"unit"] == b"m/s^2"
    assert shard.schema.field("run_id").metadata is None
    attrs = pd.read_parquet(next((tmp_path / "a" / "signals").glob("*.parquet"))).attrs
    assert attrs["units"]["time"] == "s" and attrs["sample_rate"] == 20000.0
    counts = duckdb.sql(
        f"select run_id, count(*) n from read_parquet('{tmp_path / 'a' / 'signals' / '*.parquet'}') group by run_id order by run_id"
    ).fetchall()
    assert [c[1] for c in counts] == list(ra["n_samples"])


def test_dataset_run_equals_simulation(recipe_path, tmp_path):
    generate(recipe_path, tmp_path / "d", workers=1, progress=False)
    ds = Dataset(tmp_path / "d")
    spec = load_recipe(recipe_path).runs()[4]
    scenario = spec.scenario()
    direct = simulate(
        scenario.design,
        scenario.health,
        scenario.profile,
        scenario.instrumentation,
        spec.seed,
        options=scenario.options,
    )
    stored = ds.run(4)
    assert np.array_equal(stored.time, direct.time)
    for name in CHANNEL_NAMES:  # float32 storage: equal to float32 precision
        assert np.array_equal(stored[name], direct[name].astype(np.float32).astype(float)), name
    assert list(stored.truth) == list(STANDARD_TRUTH_NAMES)
    for name in STANDARD_TRUTH_NAMES:
        expected = direct.truth[name].astype(np.float32).astype(float)
        assert np.array_equal(stored.truth[name], expected), name
    assert stored.labels["clearance_screw"] == scenario.health.clearance_screw
    # the operating point from its columns in runs.parquet, as the simulation made it
    assert stored.operating == direct.operating
    assert ds.run(4, truth=False).truth == {}
    assert ds.channels == CHANNEL_NAMES


def test_runs_with_some_channels_are_stored_as_they_are(recipe_path, tmp_path, monkeypatch):
    # An instrumentation without the load cell and the radial accelerometers: the shards hold
    # the fitted channels only, the manifest and the loader say so.
    from prsm_health.simulation.scenario import Scenario

    simulate_all = Scenario.simulate
    dropped = ("axial_load", "nut_radial_x_accel", "nut_radial_y_accel")

    def fitted(self, *args, **kwargs):
        run = simulate_all(self, *args, **kwargs)
        run.channels = {k: v for k, v in run.channels.items() if k not in dropped}
        return run

    monkeypatch.setattr(Scenario, "simulate", fitted)
    generate(recipe_path, tmp_path / "d", workers=1, progress=False)
    ds = Dataset(tmp_path / "d")
    kept = tuple(c for c in CHANNEL_NAMES if c not in dropped)
    assert ds.channels == kept and tuple(ds.manifest["channels"]) == ("time", *kept)
    run = ds.run(1)
    assert tuple(run.channels) == kept and list(run.truth) == list(STANDARD_TRUTH_NAMES)
    assert "axial_load" in run.truth  # the truth is whole whatever the sensors


def test_interrupt_and_resume_in_process(recipe_path, tmp_path):
    def stop(batch):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        generate(recipe_path, tmp_path / "r", workers=1, progress=False, on_batch=stop)
    assert len(list((tmp_path / "r" / "signals").glob("part-*.parquet"))) == 1
    report = generate(recipe_path, tmp_path / "r", workers=1, progress=False)
    assert report.resumed_runs == 2 and report.generated_runs == 4
    runs = pd.read_parquet(tmp_path / "r" / "runs.parquet")
    assert sorted(runs["run_id"]) == list(range(6))


@pytest.mark.slow
def test_killed_process_resumes_without_duplicates_or_holes(recipe_path, tmp_path):
    out = tmp_path / "k"
    code = f"from prsm_health.datasets import generate; generate({str(recipe_path)!r}, {str(out)!r}, workers=1, progress=False)"
    proc = subprocess.Popen([sys.executable, "-c", code])
    deadline = time.time() + 300
    while time.time() < deadline and not list((out / "signals").glob("part-*.parquet")):
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done_before = len(list((out / "signals").glob("part-*.parquet")))
    assert 1 <= done_before
    # nothing half-written under a final name: only complete shards or hidden partials
    for path in (out / "signals").iterdir():
        assert path.name.startswith("part-") and (
            path.suffix == ".parquet" or ".partial-" in path.name
        )
    generate(recipe_path, out, workers=2, progress=False)
    runs = pd.read_parquet(out / "runs.parquet")
    assert sorted(runs["run_id"]) == list(range(6))
    signals = _signals(out)
    assert signals.groupby("run_id").size().tolist() == list(
        runs.sort_values("run_id")["n_samples"]
    )
    assert not list((out / "signals").glob("*.partial-*"))
    reference = tmp_path / "ref"
    generate(recipe_path, reference, workers=1, progress=False)
    pd.testing.assert_frame_equal(signals, _signals(reference))


@pytest.mark.slow
def test_ctrl_c_stops_the_workers(tmp_path):
    # Ctrl-C reaches the whole process group; the workers ignore it and the parent stops them,
    # so no shard is written after the command has returned (it used to finish the running and
    # queued batches: 4 more shards). Behaviour only: the time to stop is measured in the docs.
    recipe = tmp_path / "slow.toml"
    recipe.write_text(
        TINY.replace("duration = 0.02", "duration = 0.3").replace(
            "batch_size = 2", "batch_size = 1"
        )
    )
    out = tmp_path / "c"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "prsm_health.apps.cli",
            "generate",
            str(recipe),
            "--out",
            str(out),
            "--workers",
            "2",
        ],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.time() + 300
    while time.time() < deadline and not list((out / "signals").glob("part-*.parquet")):
        time.sleep(0.05)
    at_signal = len(list((out / "signals").glob("part-*.parquet")))
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "run the same command to resume" in err
    time.sleep(2.0)  # a surviving worker would finish a 0.3 s run and write its shard by now
    written_after = len(list((out / "signals").glob("part-*.parquet"))) - at_signal
    # ≤ 1: a shard being renamed at the instant of the signal is complete and kept; the old
    # behaviour wrote one per worker plus the queued batches (3–4 here).
    assert written_after <= 1, written_after


def test_dask_local_cluster_same_dataset(recipe_path, tmp_path):
    from distributed import Client, LocalCluster

    generate(recipe_path, tmp_path / "local", workers=1, progress=False)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        generate(recipe_path, tmp_path / "dask", scheduler=client, progress=False)
    pd.testing.assert_frame_equal(_signals(tmp_path / "local"), _signals(tmp_path / "dask"))


def test_other_recipe_in_same_directory_refused(recipe_path, tmp_path):
    generate(recipe_path, tmp_path / "x", workers=1, progress=False)
    from prsm_health.core.errors import PRSMHealthError

    # Another recipe, or the same recipe edited: the message names what differs.
    for old, new, change in (
        ('name = "tiny"', 'name = "other"', "name: 'tiny' → 'other'"),
        ("speed = [80.0]", "speed = [90.0]", "sweep.speed: [80.0] → [90.0]"),
    ):
        edited = tmp_path / "edited.toml"
        edited.write_text(TINY.replace(old, new))
        with pytest.raises(PRSMHealthError) as err:
            generate(edited, tmp_path / "x", workers=1, progress=False)
        assert change in str(err.value) and "new --out directory" in str(err.value)


def test_shipped_recipes_parse():
    root = os.path.join(os.path.dirname(__file__), "..", "..", "datasets")
    for name in ("demo.toml", "clearance-study.toml"):
        r = load_recipe(os.path.join(root, name))
        assert len(r.runs()) > 20


def test_generate_both_formats(recipe_path, tmp_path):
    from prsm_health.io.mcap import read_mcap

    generate(recipe_path, tmp_path / "m", workers=1, formats="both", progress=False)
    files = sorted((tmp_path / "m" / "mcap").glob("run-*.mcap"))
    assert len(files) == 6
    run = read_mcap(files[2])
    assert run.labels["run_id"] == 2
    stored = Dataset(tmp_path / "m").run(2)
    assert np.allclose(run["nut_axial_accel"], stored["nut_axial_accel"], rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize(
    "change, needle",
    [
        (
            {"sweep": {"clearence": [1e-6]}},
            "unknown key 'clearence' in [sweep] (did you mean 'clearance'?)",
        ),
        (
            {"units": {"count": 2, "sead": 1}},
            "unknown key 'sead' in [units] (did you mean 'seed'?)",
        ),
        ({"faults": {"spal": 1e-4}}, "unknown key 'spal' in [faults] (did you mean 'spall'?)"),
        (
            {"units": {"count": 2, "seed": 1, "build": {"preloa": [0, 1e-6]}}},
            "did you mean 'preload'?",
        ),
    ],
)
def test_a_mistyped_recipe_key_names_the_nearest_one(change, needle):
    # as a design file's: difflib's nearest allowed key (core.errors.nearest_key)
    base = dict(name="x", design="paper01", duration=0.01, sample_rate=10000, seed=1, sweep={})
    with pytest.raises(RecipeError) as caught:
        Recipe.from_dict({**base, **change})
    assert needle in str(caught.value)
