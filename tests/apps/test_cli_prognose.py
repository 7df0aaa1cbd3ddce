"""``prsm-health prognose``: a history file or a fleet dataset's unit → the prognosis (JSON or a
short summary); every bad input one line ``error: …`` with exit status 2.

The prognostics model is fitted here on a synthetic fleet (the exponential degradation model,
as in tests/test_prognostics.py); the fleet dataset is a tiny life recipe generated here
(3 units × 4 snapshots of 0.25 s).
"""

import copy
import json

import numpy as np
import pandas as pd
import pytest
from synthetic_units import Z90, unit  # tests/: the degradation units, shared

from prsm_health.apps.cli import main
from prsm_health.apps.cli.output import hours
from prsm_health.apps.cli.prognose_options import PROGNOSIS_METHODS
from prsm_health.datasets import Recipe, generate
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL
from prsm_health.prognostics import (
    METHODS,
    Prognosis,
    RULModel,
    fleet_histories,
    load_prognostics_model,
    prognose,
    read_history,
    save_prognostics_model,
)

TINY_FLEET = {
    "name": "tiny-fleet",
    "design": "paper01",
    "instrumentation": "flight-ema",
    "duration": 0.25,
    "sample_rate": 20000,
    "seed": 3,
    "test_fraction": 0.34,
    "sweep": {"mode": "random", "speed": [80.0, 120.0], "load_amplitude": [1000.0, 2000.0]},
    "profile": {"load_profile": "reversing"},
    "options": {"contact_law": "hertz"},
    "life": {"units": 3, "snapshots": 4},
    "batch_size": 6,  # one batch per worker
}


def _unit(uid, rng, n_points=20):
    """One synthetic unit's history table and its life [h] (tests/synthetic_units.py)."""
    ages, estimate, sd, life = unit(rng, n_points)
    table = pd.DataFrame(
        {
            "unit_id": uid,
            "age_hours": ages,
            "clearance": estimate,
            "clearance_lower": estimate - Z90 * sd,
            "clearance_upper": estimate + Z90 * sd,
        }
    )
    return table, life


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    rng = np.random.default_rng(0)
    units = [_unit(uid, rng) for uid in range(10)]
    histories = pd.concat([t for t, _ in units], ignore_index=True)
    model = RULModel(n_samples=2000).fit(histories, {i: life for i, (_, life) in enumerate(units)})
    return save_prognostics_model(tmp_path_factory.mktemp("model") / "prognostics.json", model)


@pytest.fixture(scope="module")
def history(tmp_path_factory):
    """A held-out unit's first 12 diagnoses (60 % of its life), as CSV and Parquet."""
    table, _ = _unit(100, np.random.default_rng(5))
    table = table.iloc[:12].assign(design="paper01", fault_class="wear")
    d = tmp_path_factory.mktemp("history")
    table.to_csv(d / "unit.csv", index=False)
    table.to_parquet(d / "unit.parquet", index=False)
    return {"csv": d / "unit.csv", "parquet": d / "unit.parquet", "table": table}


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    out = tmp_path_factory.mktemp("fleet") / "tiny-fleet"
    generate(Recipe.from_dict(copy.deepcopy(TINY_FLEET)), out, workers=2, progress=False)
    return out


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_methods_are_the_librarys():
    assert sorted(PROGNOSIS_METHODS) == sorted(METHODS)


@pytest.mark.parametrize("kind", ["csv", "parquet"])
def test_json_is_the_prognosis_as_dict(capsys, model_file, history, kind):
    code, out, _ = run(capsys, "prognose", history[kind], "--model", model_file, "--json")
    assert code == 0
    expected = prognose(read_history(history[kind]), load_prognostics_model(model_file))
    assert json.loads(out) == json.loads(json.dumps(expected.as_dict()))
    assert set(json.loads(out)) == {
        "rul_hours",
        "health_indicator",
        "model",
        "warnings",
        "headline",
    }


def test_method_option(capsys, model_file, history):
    code, out, _ = run(
        capsys,
        "prognose",
        history["csv"],
        "--model",
        model_file,
        "--method",
        "similarity",
        "--json",
    )
    assert code == 0 and json.loads(out)["model"]["name"] == "similarity"


def test_human_summary(capsys, model_file, history):
    code, out, err = run(capsys, "prognose", history["csv"], "--model", model_file)
    assert code == 0 and err == ""
    p = prognose(history["table"], load_prognostics_model(model_file))
    rul, hi = p.rul_hours, p.health_indicator
    lines = {line.split("  ")[0]: line for line in out.splitlines()}
    first = out.splitlines()[0]  # what a maintainer reads
    assert first.startswith("prognosis ") and first.endswith(f"  {p.headline.text}")
    assert p.headline.state == "remaining" and f"{rul['estimate']:.0f} h [" in lines["RUL"]
    assert lines["RUL"].endswith(f"{p.headline.short} (median, 90 % interval)")
    assert (
        f"{1e6 * hi['current']:.1f} [" in lines["clearance now"] and "µm" in lines["clearance now"]
    )
    assert "30.0" in lines["failure threshold"] and "µm" in lines["failure threshold"]
    assert p.model["name"] in lines["method"]
    assert "12 from 0 to" in lines["diagnoses"]
    assert "true RUL" not in out  # only a fleet dataset has the truth


def test_at_the_limit_by_its_trend_never_reads_0_h(capsys, model_file, history, monkeypatch):
    # the fitted trend has reached the threshold (median RUL 0) while the latest clearance is
    # still below it: the table and the JSON say so with the interval, the reading and the
    # threshold, never "0 h"
    from prsm_health.apps.cli import prognose as command

    table = history["table"]
    indicator = {
        "name": "clearance",
        "unit": "m",
        "threshold": 32.7e-6,
        "ages_hours": table["age_hours"].tolist(),
        "values": table["clearance"].tolist(),
        "lower": table["clearance_lower"].tolist(),
        "upper": table["clearance_upper"].tolist(),
        "current": 31.2e-6,
    }
    at_limit = Prognosis(
        {"estimate": 0.0, "lower": 0.0, "upper": 242.0},
        indicator,
        {"name": "degradation-linear", "design": "paper01", "units_trained": 10, "version": "1"},
    )
    monkeypatch.setattr(command, "prognose_history", lambda *args: at_limit)
    code, out, err = run(capsys, "prognose", history["csv"], "--model", model_file)
    assert code == 0 and err == ""
    lines = {line.split("  ")[0]: line for line in out.splitlines()}
    headline = lines["prognosis"]
    assert "at the limit by its trend" in headline and "< 1 h" in headline
    assert "up to 242 h" in headline and "31.2 µm" in headline and "32.7 µm" in headline
    assert "< 1 h, up to 242 h" in lines["RUL"]
    assert " 0 h" not in out and "0.000" not in out and "nan" not in out
    code, out, _ = run(capsys, "prognose", history["csv"], "--model", model_file, "--json")
    assert json.loads(out)["headline"] == at_limit.headline.to_json()
    assert json.loads(out)["headline"]["state"] == "at_limit"


def _write(path, table):
    if path.suffix == ".csv":
        table.to_csv(path, index=False)
    else:
        table.to_parquet(path, index=False)
    return path


def _bad_inputs(history, tmp_path, model_file):
    table = history["table"]
    swapped = table.copy()
    swapped.loc[5, "age_hours"] = swapped.loc[3, "age_hours"]
    parquet = history["parquet"].read_bytes()
    (tmp_path / "truncated.parquet").write_bytes(parquet[: len(parquet) // 2])
    (tmp_path / "garbage.csv").write_bytes(b"\x00\xff\xfe garbage \x81" * 50)
    (tmp_path / "model.json").write_text('{"format": "something else"}')
    (tmp_path / "not-a-dataset").mkdir()
    m = ["--model", model_file]
    return {
        "one row": ([_write(tmp_path / "one.csv", table.iloc[:1]), *m], "at least 2 diagnoses"),
        "non-increasing hours": (
            [_write(tmp_path / "swapped.csv", swapped), *m],
            "age_hours must be strictly increasing; row 5",
        ),
        "other design": (
            [_write(tmp_path / "paper02.parquet", table.assign(design="paper02")), *m],
            "history is of design 'paper02', the prognostics model of 'paper01'",
        ),
        "missing columns": (
            [_write(tmp_path / "cols.csv", table.drop(columns=["clearance_upper"])), *m],
            "lacks column(s) clearance_upper",
        ),
        "truncated parquet": ([tmp_path / "truncated.parquet", *m], "cannot read history"),
        "unreadable csv": ([tmp_path / "garbage.csv", *m], "garbage.csv"),
        "missing file": ([tmp_path / "nope.csv", *m], "no such file"),
        "unknown suffix": ([tmp_path / "unit.txt", *m], "unknown suffix '.txt'"),
        "bad model": ([history["csv"], "--model", tmp_path / "model.json"], "model.json: not a"),
        "unit with a file": ([history["csv"], "--unit", "1", *m], "--unit applies to a fleet"),
        "until-age with a file": (
            [history["csv"], "--until-age", "5", *m],
            "--until-age applies to a fleet dataset",
        ),
        "not a dataset": ([tmp_path / "not-a-dataset", "--unit", "0", *m], "no manifest.json"),
        "unknown method": ([history["csv"], "--method", "astrology", *m], "--method"),
    }


BAD = [
    "one row",
    "non-increasing hours",
    "other design",
    "missing columns",
    "truncated parquet",
    "unreadable csv",
    "missing file",
    "unknown suffix",
    "bad model",
    "unit with a file",
    "until-age with a file",
    "not a dataset",
    "unknown method",
]


@pytest.mark.parametrize("case", BAD)
def test_bad_history_inputs_are_one_line_exit_2(capsys, history, tmp_path, model_file, case):
    argv, words = _bad_inputs(history, tmp_path, model_file)[case]
    code, out, err = run(capsys, "prognose", *argv)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert words in err and "Traceback" not in err


# ----------------------------------------------------------------------------- fleet dataset
def test_fleet_unit_json_and_summary_with_the_true_rul(capsys, fleet, model_file):
    code, out, _ = run(capsys, "prognose", fleet, "--unit", 1, "--model", model_file, "--json")
    assert code == 0
    history = fleet_histories(fleet, units=[1])
    expected = prognose(history, load_prognostics_model(model_file)).as_dict()
    assert json.loads(out) == json.loads(json.dumps(expected))

    code, out, err = run(
        capsys,
        "prognose",
        fleet,
        "--unit",
        1,
        "--until-age",
        history["age_hours"].iloc[2],
        "--model",
        model_file,
        "--diagnosis-model",
        DEFAULT_MODEL,
    )
    assert code == 0, err
    lines = {line.split("  ")[0]: line for line in out.splitlines()}
    truth = history["rul_hours"].iloc[2]  # the label of the last snapshot used
    assert f"  {hours(truth)} h" in lines["true RUL"]
    assert "simulator's truth" in lines["true RUL"]
    assert "unit 1" in lines["history"] and "3 from 0 to" in lines["diagnoses"]
    assert "RUL" in lines


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--unit", "7"], "no unit 7 (units 0–2)"),
        (["--unit", "1", "--until-age", "-1"], "no snapshot at or before -1 h"),
        (["--unit", "1", "--until-age", "0"], "at least 2 diagnoses"),
        ([], "choose the unit to prognose with --unit ID"),
        (["--unit", "one"], "--unit"),
        (["--unit", "1", "--until-age", "nan"], "--until-age"),
    ],
)
def test_bad_fleet_inputs_are_one_line_exit_2(capsys, fleet, model_file, extra, words):
    code, out, err = run(capsys, "prognose", fleet, *extra, "--model", model_file)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert words in err


def _asset_store(directory, table, design="paper01", asset="unit-1"):
    """A file store whose asset ``asset`` holds ``table``'s diagnoses as recorded entries."""
    from dataclasses import replace

    from prsm_health.monitoring import AssetEntry, FileAssetStore

    store = FileAssetStore(directory)
    entries = tuple(
        AssetEntry(
            f"rec-{i}",
            operating_hours=float(row.age_hours),
            fault_class="wear",
            clearance={
                "estimate": float(row.clearance),
                "lower": float(row.clearance_lower),
                "upper": float(row.clearance_upper),
            },
            design=design,
        )
        for i, row in enumerate(table.itertuples())
    )
    store.update(asset, lambda h: (replace(h, entries=entries), None))
    return directory


def test_an_asset_s_stored_diagnoses_are_its_history(capsys, tmp_path, model_file, history):
    store = _asset_store(tmp_path / "assets", history["table"])
    code, out, _ = run(
        capsys, "prognose", "--asset", "unit-1", "--store", store, "--model", model_file, "--json"
    )
    assert code == 0
    expected = prognose(history["table"], load_prognostics_model(model_file)).as_dict()
    assert json.loads(out)["rul_hours"] == pytest.approx(expected["rul_hours"])
    code, out, _ = run(
        capsys, "prognose", "--asset", "unit-1", "--store", store, "--model", model_file
    )
    assert code == 0 and "asset unit-1" in out and "RUL" in out


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--asset", "nobody"], "no asset 'nobody'"),
        ([], "a history table, a fleet dataset with --unit, or --asset ID"),
        (["--asset", "unit-1", "--unit", "1"], "--unit applies to a fleet dataset"),
        (["--asset", "unit-1", "somefile.csv"], "give no history or dataset"),
        (["--asset", "old-1"], "do not record the design"),
    ],
)
def test_bad_asset_inputs_are_one_line_exit_2(capsys, tmp_path, model_file, history, extra, words):
    store = _asset_store(tmp_path / "assets", history["table"])
    # an asset recorded before the design was kept
    _asset_store(store, history["table"], design=None, asset="old-1")
    code, out, err = run(capsys, "prognose", *extra, "--store", store, "--model", model_file)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert words in err
