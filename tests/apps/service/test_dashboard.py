"""The data behind the dashboard, its pages and its security, over HTTP (no browser:
tests/service/test_dashboard_browser.py drives Chromium).

* the latest window's spectra: stored by ``POST /v1/diagnose`` (every body kind) and
  ``/v1/diagnose/file``, one row per asset, equal to the library's
  ``window_spectra`` of the recording's last window; nothing stored without the nut axial
  acceleration; the schema migration (version 2 → 3);
* ``GET /v1/assets`` and ``GET /v1/assets/{asset_id}`` (limit, order, prognosis in brief),
  ``GET /v1/assets/{asset_id}/spectra``, their OpenAPI documentation and a schema-driven fuzz;
* the token: pages, static files and data answer 401 without it; the login form's session
  cookie (HttpOnly, SameSite=Strict, not the token) lets a browser in; a state-changing
  request carrying only the cookie from another origin is refused; the CSP of the pages.
"""

import json
import re
import sqlite3
import subprocess
import sys
from pathlib import Path

import anyio
import httpx
import numpy as np
import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from live_server import LiveServer

from prsm_health.apps.service import HistoryStore, ServiceLimits, create_app
from prsm_health.apps.service.pages import CSP, render
from prsm_health.apps.service.security import SESSION_COOKIE, session_value
from prsm_health.core.jsonable import json_ready
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import diagnose, load_bundle, split_windows
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet
from prsm_health.signals.envelope_analysis import window_spectra

ROOT = Path(__file__).resolve().parents[3]
TOKEN = "dashboard-token-5e7d"
BINARY = {
    "arrow": "application/vnd.apache.arrow.stream",
    "parquet": "application/vnd.apache.parquet",
    "mcap": "application/vnd.mcap",
}


# ----------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def recording(bundle, reversing_run) -> Run:
    """0.8 s: a 0.5 s model window and a 0.3 s last window (a tail of more than half)."""
    run = reversing_run(20e-6, duration=0.8, seed=3).without_truth()
    diagnose(run, bundle)  # compile / load the numba kernels once
    return run


@pytest.fixture(scope="module")
def bodies(recording, tmp_path_factory) -> dict[str, bytes]:
    d = tmp_path_factory.mktemp("bodies")
    return {
        "json": json.dumps(_body(recording)).encode(),
        "arrow": write_run_arrow(recording),
        "parquet": write_run_parquet(recording, d / "run.parquet").read_bytes(),
        "mcap": write_mcap(recording, d / "run.mcap").read_bytes(),
    }


def _body(run: Run, **extra) -> dict:
    return {
        "sample_rate": run.sample_rate,
        "channels": {k: v.tolist() for k, v in run.channels.items()},
        **extra,
    }


def _app(bundle, tmp_path, token=None, limits=None):
    return create_app(None, tmp_path / "history.sqlite", token, limits, bundle=bundle, warmup=False)


def _request(app, method, url, **kwargs) -> httpx.Response:
    async def call():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.request(method, url, **kwargs)

    return anyio.run(call)


def _post(app, kind: str, body: bytes, **params) -> httpx.Response:
    if kind == "json":
        data = json.loads(body)
        data.update(params)
        return _request(app, "POST", "/v1/diagnose", json=data)
    return _request(
        app,
        "POST",
        "/v1/diagnose",
        content=body,
        headers={"content-type": BINARY[kind]},
        params={k: str(v) for k, v in params.items()},
    )


def _expected_spectra(run: Run, bundle) -> dict:
    last = split_windows(run, bundle.window)[0][-1]
    spectra = window_spectra(
        last.channels["nut_axial_accel"],
        last.sample_rate,
        bundle.design,
        float(np.mean(last.channels["screw_speed"])),
    )
    return json.loads(json.dumps(json_ready(spectra)))


def _close(a, b, path="") -> None:
    """Equal JSON values, numbers to 1e-9 (an MCAP body's samples are decoded from JSON)."""
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            _close(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        np.testing.assert_allclose(
            np.array(a, float), np.array(b, float), rtol=1e-9, atol=1e-12, err_msg=path
        )
    elif isinstance(a, float):
        assert a == pytest.approx(b, rel=1e-9), path
    else:
        assert a == b, path


# ----------------------------------------------------------------------------- spectra
@pytest.mark.parametrize("kind", ["json", "arrow", "parquet", "mcap"])
def test_every_body_kind_stores_the_last_window_spectra(kind, bundle, recording, bodies, tmp_path):
    app = _app(bundle, tmp_path)
    r = _post(app, kind, bodies[kind], asset_id="press-1", operating_hours=120.5)
    assert r.status_code == 200, r.text
    assert len(r.json()["windows"]) == 2  # the spectra are of the last, 0.3 s window
    s = _request(app, "GET", "/v1/assets/press-1/spectra")
    assert s.status_code == 200, s.text
    got = s.json()
    assert got["source"] == kind and got["filename"] is None
    assert got["window"] == {"index": 1, "start": pytest.approx(0.5), "end": pytest.approx(0.79995)}
    assert got["operating_hours"] == 120.5 and got["channel"] == "nut_axial_accel"
    assert got["samples"] == 6000  # 0.3 s at 20 kHz
    assert len(got["spectrum"]["frequency"]) <= 2048
    assert got["envelope"] is not None and got["frequencies"]["gear_mesh"] > 0
    expected = _expected_spectra(recording, bundle)  # the library's, nothing changed on the way
    _close({k: got[k] for k in expected}, expected)
    summary = _request(app, "GET", "/v1/assets/press-1").json()
    assert summary["spectra_received_at"] == got["received_at"] == summary["last_received_at"]


def test_spectra_replaced_per_asset_kept_without_the_channel(bundle, recording, bodies, tmp_path):
    app = _app(bundle, tmp_path)
    assert _post(app, "arrow", bodies["arrow"], asset_id="a").status_code == 200
    first = _request(app, "GET", "/v1/assets/a/spectra").json()
    assert _post(app, "parquet", bodies["parquet"], asset_id="a").status_code == 200
    second = _request(app, "GET", "/v1/assets/a/spectra").json()
    assert second["received_at"] > first["received_at"] and second["source"] == "parquet"
    db = sqlite3.connect(tmp_path / "history.sqlite")
    assert db.execute("SELECT COUNT(*) FROM spectra WHERE asset_id = 'a'").fetchone()[0] == 1

    # a recording without the nut axial acceleration: diagnosed, stored, no spectra
    channels = {k: v for k, v in recording.channels.items() if k != "nut_axial_accel"}
    no_accel = _body(Run(recording.time, channels, recording.sample_rate))
    r = _request(app, "POST", "/v1/diagnose", json={**no_accel, "asset_id": "a"})
    assert r.status_code == 200, r.text
    assert _request(app, "GET", "/v1/assets/a/spectra").json() == second  # kept
    summary = _request(app, "GET", "/v1/assets/a").json()
    assert summary["diagnoses"] == 3 and summary["last_received_at"] > second["received_at"]
    r = _request(app, "POST", "/v1/diagnose", json={**no_accel, "asset_id": "b"})
    assert r.status_code == 200
    missing = _request(app, "GET", "/v1/assets/b/spectra")
    assert missing.status_code == 404
    assert "nut_axial_accel" in missing.json()["error"]
    assert _request(app, "GET", "/v1/assets/b").json()["spectra_received_at"] is None
    unknown = _request(app, "GET", "/v1/assets/nobody/spectra")
    assert unknown.status_code == 404 and "no diagnoses stored" in unknown.json()["error"]
    # without an asset id nothing is stored
    assert _post(app, "arrow", bodies["arrow"]).status_code == 200
    assert db.execute("SELECT COUNT(*) FROM spectra").fetchone()[0] == 1
    db.close()


def test_upload_stores_the_last_window_spectra(bundle, recording, bodies, tmp_path):
    app = _app(bundle, tmp_path)
    r = _request(
        app,
        "POST",
        "/v1/diagnose/file",
        files={"file": ("rig 7.parquet", bodies["parquet"])},
        data={"asset_id": "rig-7"},
    )
    assert r.status_code == 200, r.text
    got = _request(app, "GET", "/v1/assets/rig-7/spectra").json()
    assert got["source"] == "file" and got["filename"] == "rig 7.parquet"
    assert got["window"]["index"] == 1 and got["operating_hours"] is None
    expected = _expected_spectra(recording, bundle)
    _close({k: got[k] for k in expected}, expected)


def test_processes_store_the_same_spectra(bundle, recording, bodies, tmp_path):
    """With diagnosis processes the spectra row is built there and sent back."""
    app = _app(bundle, tmp_path, limits=ServiceLimits(processes=1))
    with LiveServer(app) as live, live.client() as c:
        r = c.post(
            "/v1/diagnose",
            content=bodies["arrow"],
            headers={"content-type": BINARY["arrow"]},
            params={"asset_id": "p"},
        )
        assert r.status_code == 200, r.text
        got = c.get("/v1/assets/p/spectra").json()
    expected = _expected_spectra(recording, bundle)
    _close({k: got[k] for k in expected}, expected)


# The schema of version 2 (before the spectra table), verbatim.
V2_SCHEMA = """
CREATE TABLE IF NOT EXISTS diagnoses (
    id                  INTEGER PRIMARY KEY AUTOINCREMENT,
    asset_id            TEXT    NOT NULL,
    received_at         TEXT    NOT NULL,
    source              TEXT    NOT NULL,
    filename            TEXT,
    window_index        INTEGER,
    window_start        REAL,
    window_end          REAL,
    speed               REAL,
    load                REAL,
    operating_hours     REAL,
    clearance_estimate  REAL,
    clearance_lower     REAL,
    clearance_upper     REAL,
    fault_class         TEXT,
    class_probabilities TEXT    NOT NULL,
    model_name          TEXT    NOT NULL,
    model_version       TEXT    NOT NULL,
    diagnosis           TEXT    NOT NULL
);
CREATE INDEX IF NOT EXISTS diagnoses_asset_time ON diagnoses (asset_id, received_at, id);
"""


def _diagnosis(estimate=12e-6, fault_class="wear"):
    return {
        "clearance": {"estimate": estimate, "lower": estimate - 2e-6, "upper": estimate + 2e-6},
        "fault_class": fault_class,
        "class_probabilities": {"wear": 0.7, "healthy": 0.3},
        "indicators": {},
        "model": {"name": "prsm-default", "version": "1", "design": "paper01"},
        "warnings": ["a note"],
    }


def test_a_version_2_database_gets_the_spectra_table_on_open(bundle, bodies, tmp_path):
    path = tmp_path / "history.sqlite"
    old = sqlite3.connect(path)
    old.executescript(V2_SCHEMA)
    d = _diagnosis()
    old.execute(
        "INSERT INTO diagnoses (asset_id, received_at, source, operating_hours,"
        " clearance_estimate, clearance_lower, clearance_upper, fault_class,"
        " class_probabilities, model_name, model_version, diagnosis)"
        " VALUES ('old', '2026-01-01T00:00:00.000000+00:00', 'json', 5.0, ?, ?, ?, 'wear',"
        " '{\"wear\": 1.0}', 'm', '1', ?)",
        (12e-6, 10e-6, 14e-6, json.dumps(d)),
    )
    old.execute("PRAGMA user_version = 2")
    old.commit()
    old.close()

    store = HistoryStore(path)
    assert store._conn.execute("PRAGMA user_version").fetchone()[0] == 4
    columns = [r[1] for r in store._conn.execute("PRAGMA table_info(spectra)")]
    assert columns[:2] == ["asset_id", "received_at"] and "spectra" in columns
    assert store.history("old")["diagnoses"][0]["diagnosis"] == d  # untouched
    assert store.spectra("old") is None
    summary = store.asset_summary("old")
    assert summary["diagnoses"] == 1 and summary["spectra_received_at"] is None
    assert summary["latest"]["warnings"] == ["a note"]
    store.close()
    app = create_app(None, path, bundle=bundle, warmup=False)  # the service opens it too
    assert _post(app, "arrow", bodies["arrow"], asset_id="old").status_code == 200
    assert _request(app, "GET", "/v1/assets/old/spectra").status_code == 200
    app.state.store.close()
    again = HistoryStore(path)  # opening a migrated file again changes nothing
    assert again.spectra("old")["source"] == "arrow"
    again.close()


# ----------------------------------------------------------------------------- assets
def test_the_latest_says_what_the_model_could_not_see(tmp_path):
    # the pages show a target the model could not see as "not observable" (common.js)
    store = HistoryStore(tmp_path / "history.sqlite")
    undecided = {"kind": "not_observable", "missing": ["a load or motion reversal"]}
    hidden = {"observability": {"clearance": 0.0, "fault": False}, "undecided": undecided}
    store.add("hidden", [{**_diagnosis(30e-6, "cannot_tell"), **hidden}])
    store.add("old", [_diagnosis()])  # stored before observability was kept
    latest = store.asset_summary("hidden")["latest"]
    assert latest["observability"] == hidden["observability"]
    assert latest["undecided"] == undecided
    old = store.asset_summary("old")["latest"]
    assert old["observability"] is None and old["undecided"] is None
    store.close()


def test_assets_list_and_summary(bundle, tmp_path):
    app = _app(bundle, tmp_path, limits=ServiceLimits(max_history=3))
    store = app.state.store
    assert _request(app, "GET", "/v1/assets").json() == {
        "count": 0,
        "total": 0,
        "truncated": False,
        "assets": [],
    }
    stamp = "2026-02-01T00:00:{:02d}.000000+00:00".format
    for i, asset in enumerate(["c", "a", "b", "a", "d"]):
        store.add(asset, [_diagnosis(10e-6 + i * 1e-6)], received_at=stamp(i), operating_hours=i)
    store.add("a", [_diagnosis(30e-6, "cannot_tell")], received_at=stamp(9))  # no hours
    page = _request(app, "GET", "/v1/assets").json()  # default limit: max_history (3)
    assert [a["asset_id"] for a in page["assets"]] == ["a", "d", "b"]  # most recently seen
    assert page["count"] == 3 and page["total"] == 4 and page["truncated"] is True
    a = page["assets"][0]
    assert a["diagnoses"] == 3 and a["with_operating_hours"] == 2 and a["operating_hours"] == 3
    assert a["first_received_at"] == stamp(1) and a["last_received_at"] == stamp(9)
    assert a["latest"]["fault_class"] == "cannot_tell"
    assert a["latest"]["clearance"]["estimate"] == pytest.approx(30e-6)
    assert a["latest"]["operating_hours"] is None and a["latest"]["source"] == "json"
    assert a["latest"]["model"]["design"] == "paper01" and "prognosis" not in a
    assert _request(app, "GET", "/v1/assets?limit=1").json()["count"] == 1
    for bad in ("0", "4", "x"):
        r = _request(app, "GET", f"/v1/assets?limit={bad}")
        assert r.status_code == 422 and "limit" in r.json()["error"], r.text
    one = _request(app, "GET", "/v1/assets/a")
    assert one.status_code == 200 and one.json() == a
    assert _request(app, "GET", "/v1/assets/zz").status_code == 404
    assert _request(app, "GET", "/v1/assets/bad%20id").status_code == 422

    # prognosis in brief: the prognosis endpoint's answer or its error
    r = _request(app, "GET", "/v1/assets?prognosis=true&limit=3").json()
    briefs = {x["asset_id"]: x["prognosis"] for x in r["assets"]}
    assert briefs["a"].keys() >= {"rul_hours", "method", "threshold", "current", "warnings"}
    full = _request(app, "GET", "/v1/assets/a/prognosis").json()
    assert briefs["a"]["rul_hours"] == full["rul_hours"]
    assert briefs["a"]["method"] == full["model"]["name"]
    assert briefs["d"]["status"] == 422 and "at least 2" in briefs["d"]["error"]
    app.state.prognostics = None
    brief = _request(app, "GET", "/v1/assets/a?prognosis=1").json()["prognosis"]
    assert brief["status"] == 503 and "no prognostics model" in brief["error"]


def test_openapi_documents_the_routes_not_the_pages(bundle, tmp_path):
    doc = _request(_app(bundle, tmp_path), "GET", "/openapi.json").json()
    paths = doc["paths"]
    assert {"/v1/assets", "/v1/assets/{asset_id}", "/v1/assets/{asset_id}/spectra"} <= set(paths)
    assert not {"/", "/login", "/logout", "/upload", "/assets/{asset_id}"} & set(paths)
    assert not any(p.startswith("/static") for p in paths)
    limit = next(p for p in paths["/v1/assets"]["get"]["parameters"] if p["name"] == "limit")
    assert limit["schema"]["maximum"] == ServiceLimits().max_history
    ref = paths["/v1/assets/{asset_id}/spectra"]["get"]["responses"]["200"]["content"]
    assert ref["application/json"]["schema"]["$ref"] == "#/components/schemas/Spectra"


@pytest.mark.parametrize("mode", ["positive", "negative"])
def test_fuzz_asset_routes_no_server_errors(bundle, bodies, tmp_path, mode):
    """Schema-driven requests: never a 5xx, every answer as documented."""
    from hypothesis import given
    from schemathesis.checks import (
        content_type_conformance,
        not_a_server_error,
        response_schema_conformance,
        status_code_conformance,
    )

    app = _app(bundle, tmp_path)
    assert _post(app, "arrow", bodies["arrow"], asset_id="a", operating_hours=1).status_code == 200
    assert _post(app, "arrow", bodies["arrow"], asset_id="a", operating_hours=9).status_code == 200
    checks = [
        not_a_server_error,
        status_code_conformance,
        content_type_conformance,
        response_schema_conformance,
    ]
    with LiveServer(app) as live:
        schema = schemathesis.openapi.from_url(f"{live.url}/openapi.json")
        for path in ("/v1/assets", "/v1/assets/{asset_id}", "/v1/assets/{asset_id}/spectra"):
            strategy = schema[path]["GET"].as_strategy(
                generation_mode=schemathesis.GenerationMode(mode)
            )

            @given(case=strategy)
            @settings(
                max_examples=15,
                deadline=None,
                suppress_health_check=list(HealthCheck),
                derandomize=True,
                database=None,
            )
            def fuzz(case):
                case.validate_response(case.call(timeout=60), checks=checks)

            fuzz()
        with live.client() as c:  # the stored asset, for good measure
            for url in ("/v1/assets?prognosis=true", "/v1/assets/a", "/v1/assets/a/spectra"):
                assert c.get(url).status_code == 200


# ----------------------------------------------------------------------------- pages
def test_pages_static_files_and_headers(bundle, tmp_path):
    app = _app(bundle, tmp_path)
    for url, script in [
        ("/", "fleet.js"),
        ("/assets/press-1", "asset.js"),
        ("/upload", "upload.js"),
    ]:
        r = _request(app, "GET", url)
        assert r.status_code == 200 and r.headers["content-type"].startswith("text/html")
        assert r.headers["content-security-policy"] == CSP
        assert r.headers["x-content-type-options"] == "nosniff"
        assert f'src="/static/dashboard/{script}"' in r.text
        assert "<script>" not in r.text and "style=" not in r.text  # nothing inline
        for src in re.findall(r'(?:src|href)="(/static/[^"]+)"', r.text):
            assert _request(app, "GET", src).status_code == 200, src
    assert "script-src 'self'" in CSP and "unsafe" not in CSP
    assert 'data-asset-id="press-1"' in _request(app, "GET", "/assets/press-1").text
    # an id the pattern refuses is not a page (and could not be stored)
    assert _request(app, "GET", "/assets/%3Cscript%3E").status_code == 422
    # the templates escape every value
    html = render("asset.html", asset_id='<script>alert(1)</script>"')
    assert "<script>" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;&quot;" in html

    js = _request(app, "GET", "/static/dashboard/asset.js")
    assert js.headers["content-type"].startswith("text/javascript")
    assert js.headers["x-content-type-options"] == "nosniff"
    again = _request(
        app, "GET", "/static/dashboard/asset.js", headers={"if-none-match": js.headers["etag"]}
    )
    assert again.status_code == 304 and not again.content
    for missing in ("/static/nope.js", "/static/../app.py", "/static/%2e%2e/app.py", "/static/"):
        assert _request(app, "GET", missing).status_code == 404, missing
    assert _request(app, "GET", "/static/vendor/uplot/LICENSE").text.startswith("The MIT License")
    # the data files never contain markup built by the scripts: no innerHTML anywhere
    for name in ("common.js", "fleet.js", "asset.js", "upload.js"):
        assert "innerHTML" not in _request(app, "GET", f"/static/dashboard/{name}").text
    # without a token there is nothing to log in to
    r = _request(app, "GET", "/login?next=/upload")
    assert r.status_code == 303 and r.headers["location"] == "/upload"


def test_vendored_uplot_matches_its_record():
    record = json.loads(
        (ROOT / "prsm_health/apps/service/static/vendor/uplot/VENDORED.json").read_text()
    )
    assert record["name"] == "uplot" and record["license"] == "MIT"
    assert record["integrity"].startswith("sha512-")
    done = subprocess.run(
        [sys.executable, str(ROOT / "tools/release/vendor_js.py"), "--check"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


# ----------------------------------------------------------------------------- token
def _login(app, token=TOKEN, next_path="/") -> httpx.Response:
    return _request(
        app,
        "POST",
        "/login",
        content=f"token={token}&next={next_path}",
        headers={"content-type": "application/x-www-form-urlencoded"},
    )


def test_token_pages_static_and_data_need_it(bundle, bodies, tmp_path):
    app = _app(bundle, tmp_path, token=TOKEN)
    bearer = {"Authorization": f"Bearer {TOKEN}"}
    for hours in (1, 2):  # a prognosis needs two
        assert _post_with(app, bodies, bearer, hours).status_code == 200
    pages = ["/", "/assets/press-1", "/upload"]
    data = [
        "/v1/assets",
        "/v1/assets/press-1",
        "/v1/assets/press-1/spectra",
        "/v1/assets/press-1/history",
        "/v1/assets/press-1/prognosis",
    ]
    static = [
        "/static/dashboard/common.js",
        "/static/dashboard/dashboard.css",
        "/static/vendor/uplot/uPlot.iife.min.js",
        "/static/vendor/uplot/LICENSE",
    ]
    for url in pages:  # the login form, with status 401
        r = _request(app, "GET", url)
        assert r.status_code == 401 and r.headers["content-type"].startswith("text/html"), url
        assert 'action="/login"' in r.text and f'name="next" value="{url}"' in r.text
        assert r.headers["content-security-policy"] == CSP
        assert r.headers["www-authenticate"].startswith("Bearer")
        assert "<script" not in r.text and "stylesheet" not in r.text
    for url in data + static:
        for headers in ({}, {"Authorization": "Bearer wrong"}, {"Cookie": f"{SESSION_COOKIE}=x"}):
            r = _request(app, "GET", url, headers=headers)
            assert r.status_code == 401, (url, headers)
            assert "bearer token" in r.json()["error"]
    # the form: wrong token, then the right one
    assert _request(app, "GET", "/login").status_code == 200
    wrong = _login(app, "nope")
    assert wrong.status_code == 401 and "Wrong token" in wrong.text
    assert "set-cookie" not in wrong.headers
    ok = _login(app, TOKEN, "/assets/press-1")
    assert ok.status_code == 303 and ok.headers["location"] == "/assets/press-1"
    cookie = ok.headers["set-cookie"]
    assert cookie.startswith(f"{SESSION_COOKIE}={session_value(TOKEN)};")
    assert TOKEN not in cookie
    attributes = {part.strip().lower() for part in cookie.split(";")[1:]}
    assert {"httponly", "samesite=strict", "path=/"} <= attributes
    assert "secure" not in attributes  # plain http; set behind https
    jar = {"Cookie": f"{SESSION_COOKIE}={session_value(TOKEN)}"}
    for url in pages + data + static:
        assert _request(app, "GET", url, headers=jar).status_code == 200, url
    # another token's cookie is not this one's
    other = {"Cookie": f"{SESSION_COOKIE}={session_value(TOKEN + 'x')}"}
    assert _request(app, "GET", "/v1/assets", headers=other).status_code == 401
    # state-changing requests with the cookie only: from the service's own pages only
    assert _post_with(app, bodies, {**jar, "Origin": "http://test"}).status_code == 200
    for foreign in (
        {"Origin": "http://127.0.0.1:9999"},
        {"Origin": "null"},
        {"Sec-Fetch-Site": "same-site"},
    ):
        r = _post_with(app, bodies, {**jar, **foreign})
        assert r.status_code == 403 and "cross-origin" in r.json()["error"], foreign
    # a bearer header needs no origin
    assert _post_with(app, bodies, {**bearer, "Origin": "http://elsewhere"}).status_code == 200
    # never a redirect elsewhere
    for target in ("//evil.example/", "https://evil.example/", "/v1/assets", "javascript:x"):
        assert _login(app, TOKEN, target).headers["location"] == "/", target
    out = _request(app, "POST", "/logout", headers=jar)
    assert out.status_code == 303 and out.headers["location"] == "/login"
    assert out.headers["set-cookie"].startswith(f'{SESSION_COOKIE}="";')
    assert "max-age=0" in out.headers["set-cookie"].lower()


def _post_with(app, bodies, headers, hours=5) -> httpx.Response:
    return _request(
        app,
        "POST",
        "/v1/diagnose",
        content=bodies["arrow"],
        headers={"content-type": BINARY["arrow"], **headers},
        params={"asset_id": "press-1", "operating_hours": str(hours)},
    )
