"""``GET /v1/assets/{asset_id}/prognosis`` and the operating hours the history stores.

The prognostics model is fitted here on a synthetic fleet drawn from the exponential
degradation model (as tests/test_prognostics.py does) and saved to a file the service loads.
The 30-diagnosis asset is written through ``HistoryStore.add`` (a realistic growing clearance
with its interval at growing operating hours: 30 real diagnoses would take minutes); a second
asset gets real diagnoses posted as JSON, Arrow and Parquet bodies with ``operating_hours``.
The main path runs against real uvicorn servers on 127.0.0.1, stopped and restarted on the
same database file; error answers use in-process ASGI calls.
"""

import dataclasses
import json
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import time

import anyio
import httpx
import numpy as np
import pandas as pd
import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from live_server import LiveServer
from synthetic_units import Z90, fitted_model, unit

from prsm_health import prognostics
from prsm_health.apps.cli import main
from prsm_health.apps.service import HistoryStore, create_app
from prsm_health.apps.service.schemas import Prognosis as PrognosisSchema
from prsm_health.core.errors import PRSMHealthError
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.parquet import write_run_parquet
from prsm_health.prognostics import RULModel, history_of_readings, prognose, save_prognostics_model

TOKEN = "prognosis-token-81c2"

# The schema of version 1 (before operating_hours), verbatim: what existing databases hold.
V1_SCHEMA = """
CREATE TABLE IF NOT EXISTS diagnoses (
    id                  INTEGER PRIMARY KEY AUTOINCREMENT,
    asset_id            TEXT    NOT NULL,
    received_at         TEXT    NOT NULL,  -- server receive time, UTC ISO-8601 (microseconds)
    source              TEXT    NOT NULL,  -- 'json', 'arrow', 'parquet', 'mcap' or 'file'
    filename            TEXT,              -- uploaded file name (source 'file')
    window_index        INTEGER,           -- per-window rows of an upload
    window_start        REAL,              -- [s]
    window_end          REAL,              -- [s]
    speed               REAL,              -- nominal screw speed given by the client [rad/s]
    load                REAL,              -- nominal axial load given by the client [N]
    clearance_estimate  REAL,              -- [m]
    clearance_lower     REAL,              -- [m]
    clearance_upper     REAL,              -- [m]
    fault_class         TEXT,
    class_probabilities TEXT    NOT NULL,  -- JSON object
    model_name          TEXT    NOT NULL,
    model_version       TEXT    NOT NULL,
    diagnosis           TEXT    NOT NULL   -- the full Diagnosis contract JSON
);
CREATE INDEX IF NOT EXISTS diagnoses_asset_time ON diagnoses (asset_id, received_at, id);
"""


# ----------------------------------------------------------------------------- synthetic fleet
@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    model = fitted_model()
    # the physics method (progpy ageing model) of the default fleet recipe's [life], small
    from prsm_health.actuator.design import preset
    from prsm_health.physics.life_spec import LifeSpec
    from prsm_health.prognostics.ageing_model import rate_tables
    from prsm_health.prognostics.ageing_rul import AgeingRUL

    model.ageing_ = AgeingRUL(
        rate_tables(preset("paper01"), LifeSpec()),
        n_particles=80,
        n_samples=20,
        horizon=model.horizon_,
    )
    return save_prognostics_model(tmp_path_factory.mktemp("prognostics") / "model.json", model)


@pytest.fixture(scope="module")
def model(model_file):
    return prognostics.load_prognostics_model(model_file)


def _diagnosis(estimate, lower, upper, design="paper01"):
    return {
        "clearance": {"estimate": estimate, "lower": lower, "upper": upper},
        "fault_class": "wear",
        "class_probabilities": {"wear": 1.0},
        "indicators": {},
        "model": {"name": "prsm-default", "version": "1", "design": design},
    }


def _stamp(i: int) -> str:
    return f"2026-01-{1 + i // 24:02d}T{i % 24:02d}:00:00.000000+00:00"


def _store_unit(store, asset, n_points=30, seed=7, design="paper01"):
    """A unit's diagnoses at growing operating hours, stored as the service would: the first
    60 % of its life (30 diagnoses), one a day."""
    ages, estimate, sd, life = unit(np.random.default_rng(seed), round(n_points / 0.6))
    ages, estimate, sd = ages[:n_points], estimate[:n_points], sd[:n_points]
    for i, (t, c, s) in enumerate(zip(ages, estimate, sd)):
        store.add(
            asset,
            [_diagnosis(float(c), float(c - Z90 * s), float(c + Z90 * s), design)],
            received_at=_stamp(i),
            operating_hours=float(t),
        )
    table = pd.DataFrame(
        {
            "age_hours": ages,
            "clearance": estimate,
            "clearance_lower": estimate - Z90 * sd,
            "clearance_upper": estimate + Z90 * sd,
            "design": design,
        }
    )
    return table, life


# ----------------------------------------------------------------------------- servers
@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def recording(reversing_run):
    return reversing_run(20e-6, seed=3).without_truth()


def _request(app, method, url, **kwargs) -> httpx.Response:
    async def call():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.request(method, url, **kwargs)

    return anyio.run(call)


@pytest.fixture(scope="module")
def app(bundle, model_file, tmp_path_factory):
    db = tmp_path_factory.mktemp("asgi") / "history.sqlite"
    return create_app(None, db, bundle=bundle, warmup=False, prognostics_model_path=model_file)


# ----------------------------------------------------------------------------- the store
def test_a_version_1_database_gets_the_column_on_open(tmp_path):
    path = tmp_path / "v1.sqlite"
    old = sqlite3.connect(path)
    old.executescript(V1_SCHEMA)
    d = _diagnosis(12e-6, 10e-6, 14e-6)
    old.execute(
        "INSERT INTO diagnoses (asset_id, received_at, source, clearance_estimate,"
        " clearance_lower, clearance_upper, fault_class, class_probabilities, model_name,"
        " model_version, diagnosis) VALUES (?, ?, 'json', ?, ?, ?, 'wear', '{}', 'm', '1', ?)",
        ("press-1", _stamp(0), 12e-6, 10e-6, 14e-6, json.dumps(d)),
    )
    old.execute("PRAGMA user_version = 1")
    old.commit()
    old.close()

    store = HistoryStore(path)
    columns = {r[1]: r[2] for r in store._conn.execute("PRAGMA table_info(diagnoses)")}
    assert columns["operating_hours"] == "REAL"
    assert store._conn.execute("PRAGMA user_version").fetchone()[0] == 4
    store.add("press-1", [d], received_at=_stamp(1), operating_hours=250.0)
    entries = store.history("press-1")["diagnoses"]
    assert [e["operating_hours"] for e in entries] == [None, 250.0]
    assert entries[0]["diagnosis"] == d  # the old row is untouched
    assert store.operating_history("press-1") == [(250.0, 12e-6, 10e-6, 14e-6, "wear", "paper01")]
    store.close()
    again = HistoryStore(path)  # opening a migrated file again changes nothing
    assert again.history("press-1")["count"] == 2
    again.close()


def test_prognosis_history_orders_by_hours_and_keeps_the_latest_of_equal_hours(tmp_path):
    store = HistoryStore(tmp_path / "h.sqlite")
    readings = [  # (received, operating hours, clearance): out of order, 200 h twice
        (0, 300.0, 14e-6),
        (1, 100.0, 10e-6),
        (2, 200.0, 11e-6),
        (3, 200.0, 12e-6),
    ]
    for i, hours, c in readings:
        store.add(
            "a", [_diagnosis(c, c - 1e-6, c + 1e-6)], received_at=_stamp(i), operating_hours=hours
        )
    store.add("a", [_diagnosis(99e-6, 98e-6, 100e-6)], received_at=_stamp(4))  # no hours: unused
    store.add("a", [_diagnosis(None, None, None)], received_at=_stamp(5), operating_hours=400.0)
    table, notes = history_of_readings(store.operating_history("a"))
    assert table["age_hours"].tolist() == [100.0, 200.0, 300.0]
    assert table["clearance"].tolist() == [10e-6, 12e-6, 14e-6]  # the later 200 h reading
    assert set(table["design"]) == {"paper01"} and set(table["fault_class"]) == {"wear"}
    assert len(notes) == 1 and "1 stored diagnosis(es)" in notes[0]
    table, notes = history_of_readings([])
    assert table.empty and notes == []
    store.close()


# ----------------------------------------------------------------------------- the main path
def test_prognosis_of_30_stored_diagnoses_survives_a_restart(
    bundle, model, model_file, recording, tmp_path
):
    db = tmp_path / "history.sqlite"
    store = HistoryStore(db)
    table, life = _store_unit(store, "press-30")
    store.close()
    expected = prognose(table, model).as_dict()

    def start():
        return LiveServer(
            create_app(None, db, bundle=bundle, warmup=False, prognostics_model_path=model_file)
        )

    with start() as live, live.client() as c:
        r = c.get("/v1/assets/press-30/prognosis")
        assert r.status_code == 200, r.text
        first = r.json()
        assert first == json.loads(json.dumps(expected))  # the library's answer, nothing added
        rul = first["rul_hours"]
        assert 0 < rul["lower"] < rul["estimate"] < rul["upper"]
        true_rul = life - table["age_hours"].iloc[-1]
        assert rul["lower"] < true_rul < rul["upper"]
        assert first["health_indicator"]["ages_hours"] == table["age_hours"].tolist()
        assert first["model"]["name"].startswith("degradation-")
        similarity = c.get("/v1/assets/press-30/prognosis", params={"method": "similarity"})
        assert similarity.status_code == 200 and similarity.json()["model"]["name"] == "similarity"
        physics = c.get("/v1/assets/press-30/prognosis", params={"method": "physics"})
        assert physics.status_code == 200, physics.text
        physics_first = physics.json()
        assert physics_first["model"]["name"] == "physics"
        assert physics_first == json.loads(json.dumps(prognose(table, model, "physics").as_dict()))
        # every method's answer is what the schema generated from the declaration says
        for answer in (first, similarity.json(), physics_first):
            assert PrognosisSchema.model_validate(answer).model_dump() == answer

        # real diagnoses, posted with operating hours as JSON and as binary bodies
        body = {
            "sample_rate": recording.sample_rate,
            "channels": {k: v.tolist() for k, v in recording.channels.items()},
        }
        posted = [
            c.post("/v1/diagnose", json={**body, "asset_id": "press-real", "operating_hours": 10}),
            c.post(
                "/v1/diagnose",
                content=write_run_arrow(recording),
                headers={"content-type": "application/vnd.apache.arrow.stream"},
                params={"asset_id": "press-real", "operating_hours": "1200.5"},
            ),
            c.post(
                "/v1/diagnose",
                content=write_run_parquet(recording, tmp_path / "run.parquet").read_bytes(),
                headers={"content-type": "application/vnd.apache.parquet"},
                params={"asset_id": "press-real", "operating_hours": "600"},
            ),
        ]
        assert [p.status_code for p in posted] == [200, 200, 200], [p.text for p in posted]
        h = c.get("/v1/assets/press-real/history").json()
        assert [e["operating_hours"] for e in h["diagnoses"]] == [10.0, 1200.5, 600.0]
        assert [e["source"] for e in h["diagnoses"]] == ["json", "arrow", "parquet"]
        real = c.get("/v1/assets/press-real/prognosis")
        assert real.status_code == 200, real.text
        hi = real.json()["health_indicator"]
        assert hi["ages_hours"] == [10.0, 600.0, 1200.5]  # by operating hours
        stored = h["diagnoses"]
        assert hi["values"] == [stored[i]["diagnosis"]["clearance"]["estimate"] for i in (0, 2, 1)]
        real_first = real.json()

    # a new server on the same database file: the same answers
    with start() as live, live.client() as c:
        assert c.get("/v1/assets/press-30/prognosis").json() == first
        # the physics prognosis too: the same particles from the same seed
        again = c.get("/v1/assets/press-30/prognosis", params={"method": "physics"})
        assert again.json() == physics_first
        assert c.get("/v1/assets/press-real/prognosis").json() == real_first


@pytest.mark.slow  # three health-check recordings (≈ 3 s each) and two servers
def test_an_asset_with_check_snapshots_gets_a_rul_that_survives_a_restart(
    bundle, model_file, short_check_run, tmp_path
):
    # one unit's health checks as it wears, posted as Parquet with their operating hours: each
    # is read as a check (its phases' roles), its clearance with the check model's interval
    db = tmp_path / "history.sqlite"
    checks = {400.0: 6e-6, 800.0: 12e-6, 1200.0: 18e-6}

    def start():
        return LiveServer(
            create_app(None, db, bundle=bundle, warmup=False, prognostics_model_path=model_file)
        )

    with start() as live, live.client() as c:
        for hours, clearance in checks.items():
            body = write_run_parquet(
                short_check_run(clearance, seed=21), tmp_path / "check.parquet"
            )
            r = c.post(
                "/v1/diagnose",
                content=body.read_bytes(),
                headers={"content-type": "application/vnd.apache.parquet"},
                params={"asset_id": "ema-check", "operating_hours": str(hours)},
            )
            assert r.status_code == 200, r.text
            diagnosis = r.json()
            assert diagnosis["check_phases"], diagnosis  # read as a health check
            interval = diagnosis["clearance"]
            assert interval["lower"] < interval["estimate"] < interval["upper"]
        first = {}
        for method in ("degradation", "similarity", "physics"):
            r = c.get("/v1/assets/ema-check/prognosis", params={"method": method})
            assert r.status_code == 200, r.text
            answer = r.json()
            assert answer["health_indicator"]["ages_hours"] == list(checks)
            rul = answer["rul_hours"]
            assert rul["lower"] <= rul["estimate"] <= rul["upper"], rul
            assert answer["model"]["name"].startswith(method), answer["model"]
            first[method] = answer

    # a new server on the same database file: the same answers, every method
    with start() as live, live.client() as c:
        for method, answer in first.items():
            again = c.get("/v1/assets/ema-check/prognosis", params={"method": method})
            assert again.json() == answer


# ----------------------------------------------------------------------------- the headline
def test_the_headline_is_in_the_answer_and_in_the_brief(app, model, monkeypatch):
    # what a maintainer reads, made by the library's one rule: in the prognosis answer (in its
    # generated schema) and in the asset's brief, which the dashboard shows
    from prsm_health.apps.service.routes import prognosis as route
    from prsm_health.apps.service.schemas import AssetSummary

    store = app.state.store
    table, _ = _store_unit(store, "press-headline", n_points=12, seed=11)
    r = _request(app, "GET", "/v1/assets/press-headline/prognosis")
    assert r.status_code == 200, r.text
    answer = r.json()
    expected = prognose(table, model)
    assert answer["headline"] == expected.headline.to_json()
    assert answer["headline"]["state"] == "remaining"
    assert (
        answer["headline"]["text"].startswith("RUL ")
        and "µm threshold" in answer["headline"]["text"]
    )
    assert PrognosisSchema.model_validate(answer).model_dump() == answer
    summary = _request(app, "GET", "/v1/assets/press-headline?prognosis=true").json()
    assert summary["prognosis"]["headline"] == answer["headline"]
    assert AssetSummary.model_validate(summary).model_dump(exclude_unset=True) == summary

    # the trend has reached the threshold, the latest reading has not: never "0 h"
    at_limit = dataclasses.replace(
        expected,
        rul_hours={"estimate": 0.0, "lower": 0.0, "upper": 242.0},
        health_indicator=expected.health_indicator.to_json()
        | {"current": 31.2e-6, "threshold": 32.7e-6},
    )
    monkeypatch.setattr(route, "prognose_readings", lambda *args, **kwargs: (at_limit, None))
    monkeypatch.setattr(route, "_MADE", type(route._MADE)())  # the real one is remembered
    answer = _request(app, "GET", "/v1/assets/press-headline/prognosis").json()
    brief = _request(app, "GET", "/v1/assets?prognosis=true").json()["assets"]
    brief = next(a["prognosis"] for a in brief if a["asset_id"] == "press-headline")
    for headline in (answer["headline"], brief["headline"]):
        assert headline["state"] == "at_limit"
        assert headline["text"].startswith("at the limit by its trend: RUL < 1 h median")
        assert "31.2 µm, below the 32.7 µm threshold" in headline["text"]
        assert headline["short"] == "at the limit: < 1 h, up to 242 h"


def test_a_prognosis_is_made_once_per_readings(app, model, monkeypatch):
    # the physics method runs a particle filter: the fleet page and the asset page ask the same
    # asset's prognosis again and again; a new reading makes a new one
    from prsm_health.apps.service.routes import prognosis as route

    made = []
    real = route.prognose_readings

    def counting(*args, **kwargs):
        made.append(args[0][-1])
        return real(*args, **kwargs)

    monkeypatch.setattr(route, "prognose_readings", counting)
    monkeypatch.setattr(route, "_MADE", type(route._MADE)())
    store = app.state.store
    _store_unit(store, "press-remembered", n_points=6, seed=12)
    first = _request(app, "GET", "/v1/assets/press-remembered/prognosis").json()
    again = _request(app, "GET", "/v1/assets/press-remembered/prognosis").json()
    brief = _request(app, "GET", "/v1/assets/press-remembered?prognosis=true").json()
    assert again == first and brief["prognosis"]["rul_hours"] == first["rul_hours"]
    assert len(made) == 1
    other = _request(app, "GET", "/v1/assets/press-remembered/prognosis?method=similarity")
    assert other.status_code == 200 and len(made) == 2  # another method, another prognosis
    store.add(
        "press-remembered",
        [_diagnosis(12e-6, 11e-6, 13e-6)],
        received_at=_stamp(50),
        operating_hours=5000.0,
    )
    newer = _request(app, "GET", "/v1/assets/press-remembered/prognosis").json()
    assert len(made) == 3 and newer["health_indicator"]["ages_hours"][-1] == 5000.0


# ----------------------------------------------------------------------------- errors
def test_prognosis_errors(app, bundle):
    store = app.state.store
    store.add("one-hour", [_diagnosis(12e-6, 10e-6, 14e-6)], operating_hours=5.0)
    store.add("no-hours", [_diagnosis(12e-6, 10e-6, 14e-6)] * 3)
    for i in range(2):
        store.add("same-hours", [_diagnosis(12e-6 + i * 1e-6, 10e-6, 16e-6)], operating_hours=7.0)
    _store_unit(store, "other-design", n_points=4, design="paper02")

    cases = [
        ("/v1/assets/nobody/prognosis", 404, "no diagnoses stored for asset 'nobody'"),
        ("/v1/assets/one-hour/prognosis", 422, "'one-hour' has 1 diagnosis(es) at distinct"),
        ("/v1/assets/no-hours/prognosis", 422, "has 0 diagnosis(es)"),
        ("/v1/assets/same-hours/prognosis", 422, "has 1 diagnosis(es) at distinct operating"),
        (
            "/v1/assets/other-design/prognosis",
            422,
            "asset 'other-design': history is of design 'paper02', the prognostics model of "
            "'paper01'",
        ),
        ("/v1/assets/one-hour/prognosis?method=magic", 422, "method"),
        ("/v1/assets/bad%20id/prognosis", 422, "asset_id"),
    ]
    for url, status, message in cases:
        r = _request(app, "GET", url)
        assert r.status_code == status, (url, r.text)
        assert r.headers["content-type"] == "application/json"
        error = r.json()["error"]
        assert message in error and "\n" not in error, (url, error)


def test_operating_hours_are_checked_where_they_come_in(app, recording):
    body = {"sample_rate": recording.sample_rate, "channels": {"nut_axial_accel": [0.0] * 300}}
    arrow = write_run_arrow(recording)
    binary = {"content-type": "application/vnd.apache.arrow.stream"}
    for value, words in (
        (-1.0, "greater than or equal to 0"),
        (2e7, "less than or equal"),
        ("12", "operating_hours"),
    ):
        r = _request(app, "POST", "/v1/diagnose", json={**body, "operating_hours": value})
        assert r.status_code == 422 and words in r.json()["error"], r.text
    for value in ("-1", "1e8", "nan", "inf", "soon"):
        r = _request(
            app,
            "POST",
            "/v1/diagnose",
            content=arrow,
            headers=binary,
            params={"operating_hours": value},
        )
        assert r.status_code == 422 and "operating_hours" in r.json()["error"], r.text
    r = _request(
        app, "POST", "/v1/diagnose", json=body, params={"operating_hours": "3"}
    )  # a JSON body carries it as a field
    assert r.status_code == 422 and "operating_hours as fields" in r.json()["error"]


def test_no_prognostics_model_is_503(bundle, monkeypatch, tmp_path):
    monkeypatch.setattr(prognostics, "DEFAULT_PROGNOSTICS_MODEL", tmp_path / "missing.json")
    app = create_app(None, ":memory:", bundle=bundle, warmup=False)
    assert app.state.prognostics is None
    app.state.store.add("a", [_diagnosis(12e-6, 10e-6, 14e-6)], operating_hours=1.0)
    r = _request(app, "GET", "/v1/assets/a/prognosis")
    assert r.status_code == 503
    assert r.json()["error"].startswith("no prognostics model loaded: start the service with")
    # with the path given, the model is loaded, and a bad one stops the start
    (tmp_path / "bad.json").write_text("{}")
    with pytest.raises(PRSMHealthError, match="bad.json: not a prsm_health prognostics model"):
        create_app(
            None,
            ":memory:",
            bundle=bundle,
            warmup=False,
            prognostics_model_path=tmp_path / "bad.json",
        )
    unfitted = RULModel()
    with pytest.raises(PRSMHealthError, match="not a fitted prognostics model"):
        create_app(None, ":memory:", bundle=bundle, warmup=False, prognostics_model=unfitted)


def test_token_is_required(bundle, model):
    app = create_app(None, ":memory:", TOKEN, bundle=bundle, warmup=False, prognostics_model=model)
    for headers in ({}, {"Authorization": "Bearer wrong"}):
        r = _request(app, "GET", "/v1/assets/a/prognosis", headers=headers)
        assert r.status_code == 401 and "bearer token" in r.json()["error"]
    r = _request(app, "GET", "/v1/assets/a/prognosis", headers={"Authorization": f"Bearer {TOKEN}"})
    assert r.status_code == 404


def test_openapi_documents_the_route(app):
    doc = _request(app, "GET", "/openapi.json").json()
    op = doc["paths"]["/v1/assets/{asset_id}/prognosis"]["get"]
    assert set(op["responses"]) >= {"200", "404", "422", "503"}
    ref = op["responses"]["200"]["content"]["application/json"]["schema"]["$ref"]
    assert ref == "#/components/schemas/Prognosis"
    schemas = doc["components"]["schemas"]
    # generated from the library's declaration: its fields, with their meanings
    declared = {f.name: f for f in dataclasses.fields(prognostics.Prognosis)}
    properties = schemas["Prognosis"]["properties"]
    assert set(properties) == set(declared)
    assert set(declared) == {"rul_hours", "health_indicator", "model", "warnings", "headline"}
    for name, f in declared.items():
        assert properties[name]["description"] == f.metadata["description"]
    headline = {f.name: f for f in dataclasses.fields(prognostics.prognosis.Headline)}
    assert set(schemas["Headline"]["properties"]) == set(headline) == {"state", "text", "short"}
    assert schemas["Headline"]["required"] == ["state", "text", "short"]
    assert "operating_hours" in schemas["DiagnoseRequest"]["properties"]
    assert "operating_hours" in schemas["HistoryEntry"]["properties"]
    diagnose = doc["paths"]["/v1/diagnose"]["post"]
    assert "operating_hours" in {p["name"] for p in diagnose["parameters"]}


def test_serve_passes_the_prognostics_model_option(monkeypatch):
    import prsm_health.apps.service as service

    seen = {}
    monkeypatch.setattr(service, "serve", lambda *a, **kw: seen.update(kw))
    assert main(["serve", "--prognostics-model", "fleet-model.json"]) == 0
    assert seen["prognostics_model_path"] == "fleet-model.json"
    assert main(["serve"]) == 0
    assert seen["prognostics_model_path"] is None


@pytest.mark.parametrize("mode", ["positive", "negative"])
def test_fuzz_prognosis_no_server_errors(app, model, bundle, mode):
    """Schema-driven requests: never a 5xx, every answer as documented."""
    from hypothesis import given
    from schemathesis.checks import (
        content_type_conformance,
        not_a_server_error,
        response_schema_conformance,
        status_code_conformance,
    )

    fuzz_app = create_app(None, ":memory:", bundle=bundle, warmup=False, prognostics_model=model)
    _store_unit(fuzz_app.state.store, "a", n_points=5)
    with LiveServer(fuzz_app) as live:
        schema = schemathesis.openapi.from_url(f"{live.url}/openapi.json")
        operation = schema["/v1/assets/{asset_id}/prognosis"]["GET"]
        strategy = operation.as_strategy(generation_mode=schemathesis.GenerationMode(mode))
        checks = [
            not_a_server_error,
            status_code_conformance,
            content_type_conformance,
            response_schema_conformance,
        ]

        @given(case=strategy)
        @settings(
            max_examples=30,
            deadline=None,
            suppress_health_check=list(HealthCheck),
            derandomize=True,
            database=None,
        )
        def fuzz(case):
            case.validate_response(case.call(timeout=60), checks=checks)

        fuzz()
        with live.client() as c:  # the stored asset, for good measure
            assert c.get("/v1/assets/a/prognosis").status_code == 200


# ----------------------------------------------------------------------------- command line
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow  # two command-line services in subprocesses (each loads the model)
def test_command_line_service_prognosis_survives_a_restart(model_file, tmp_path):
    db = tmp_path / "history.sqlite"
    store = HistoryStore(db)
    _store_unit(store, "press-30")
    store.close()
    answers = []
    while len(answers) < 2:
        port = _free_port()
        cmd = [
            sys.executable,
            "-m",
            "prsm_health.apps.cli",
            "serve",
            "--port",
            str(port),
            "--db",
            str(db),
            "--prognostics-model",
            str(model_file),
            "--log-level",
            "warning",
        ]
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        r = None
        try:
            deadline = time.monotonic() + 120
            while proc.poll() is None:
                try:
                    r = httpx.get(f"http://127.0.0.1:{port}/v1/assets/press-30/prognosis")
                    break
                except httpx.TransportError:
                    assert time.monotonic() < deadline, "the service did not start in 120 s"
                    time.sleep(0.2)
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(timeout=60)
        stderr = proc.stderr.read()
        proc.stderr.close()  # the pipe, not left to the garbage collector
        if r is None and b"address already in use" in stderr.lower():
            continue  # another process took the free port between probe and bind: retry
        assert r is not None, stderr.decode(errors="replace")
        assert r.status_code == 200, r.text
        assert proc.returncode == 0, stderr.decode(errors="replace")
        assert b"Traceback" not in stderr
        answers.append(r.json())
    assert answers[0] == answers[1]
    assert os.path.exists(db)
