"""HTTP diagnostics service, tested against real uvicorn servers on 127.0.0.1.

Servers run in background threads of this process (one model load for the module) on a socket
bound to port 0, except in the restart test, which runs ``prsm-health serve`` in two successive
subprocesses on the same database file, and in the Ctrl-C test (with diagnosis processes). The
schema-driven fuzz run (schemathesis) checks that no generated request, valid or not, gets a 5xx
answer and that every answer matches the OpenAPI document.
"""

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from multiprocessing.shared_memory import SharedMemory
from pathlib import Path

import httpx
import numpy as np
import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from live_server import LiveServer

from prsm_health import PRSMHealthError
from prsm_health.apps.service import (
    ServiceLimits,
    check_bind,
    create_app,
    is_loopback,
    serve,
)
from prsm_health.apps.service.limits import DEFAULT_MAX_WINDOW_SECONDS
from prsm_health.apps.service.server import http_implementation
from prsm_health.apps.service.workers import SHARED_BODY_PREFIX
from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.run import MIN_SAMPLES, Run
from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL, diagnose, load_bundle
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet

TOKEN = "test-token-3f9a1c0e"
CONTRACT_KEYS = {"clearance", "fault_class", "class_probabilities", "indicators", "model"}
ARROW = {"content-type": "application/vnd.apache.arrow.stream"}


# ----------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def recording(bundle, reversing_run) -> Run:
    run = reversing_run(20e-6, seed=3)
    diagnose(run, bundle)  # compile / load the numba kernels once, before any server starts
    return run


def _body(run: Run, **extra) -> dict:
    # the gear ratio the files carry as a label (the efficiency indicator needs it)
    return {
        "sample_rate": run.sample_rate,
        "channels": {k: v.tolist() for k, v in run.channels.items()},
        "gear_ratio": run.operating.gear_ratio,
        **extra,
    }


@pytest.fixture(scope="module")
def server(bundle, recording, tmp_path_factory):
    db = tmp_path_factory.mktemp("service") / "history.sqlite"
    app = create_app(DEFAULT_MODEL, db, bundle=bundle)
    with LiveServer(app) as live:
        yield live


@pytest.fixture(scope="module")
def client(server):
    with server.client() as c:
        yield c


@pytest.fixture(scope="module")
def token_server(bundle, recording, tmp_path_factory):
    db = tmp_path_factory.mktemp("service-token") / "history.sqlite"
    with LiveServer(create_app(None, db, TOKEN, bundle=bundle, warmup=False)) as live:
        yield live


@pytest.fixture(scope="module")
def small_server(bundle, recording, tmp_path_factory):
    """Tight limits, to reach them with small requests."""
    db = tmp_path_factory.mktemp("service-small") / "history.sqlite"
    limits = ServiceLimits(
        max_body_bytes=200_000, max_upload_bytes=100_000, max_upload_samples=5000, max_pending=1
    )
    with LiveServer(create_app(None, db, None, limits, bundle=bundle, warmup=False)) as live:
        yield live


@pytest.fixture(scope="module")
def files(recording, tmp_path_factory):
    d = tmp_path_factory.mktemp("uploads")
    mcap = write_mcap(recording, d / "run.mcap")
    parquet = write_run_parquet(recording, d / "run.parquet")
    return {"mcap": mcap, "parquet": parquet}


def _upload_dirs() -> set[str]:
    return {p.name for p in Path(tempfile.gettempdir()).glob("prsm-health-upload-*")}


# ----------------------------------------------------------------------------- health, model
def test_health_and_model(client, bundle):
    health = client.get("/v1/health")
    assert health.status_code == 200
    body = health.json()
    assert body["status"] == "ok"
    assert body["model"] == bundle.name and body["version"] == bundle.version
    assert body["uptime_s"] >= 0

    model = client.get("/v1/model").json()
    assert model["name"] == bundle.name
    assert model["window"] == bundle.window
    assert model["design"] == bundle.design.name
    assert model["feature_names"] == bundle.feature_names
    assert model["classes"]  # the shipped model has a fault classifier


def test_openapi_document(client):
    doc = client.get("/openapi.json").json()
    assert doc["openapi"].startswith("3.")
    paths = doc["paths"]
    for path in (
        "/v1/diagnose",
        "/v1/diagnose/file",
        "/v1/assets/{asset_id}/history",
        "/v1/health",
        "/v1/model",
    ):
        assert path in paths
    channels = doc["components"]["schemas"]["Channels"]
    assert set(channels["properties"]) == set(CHANNEL_NAMES)
    assert channels["additionalProperties"] is False


# ----------------------------------------------------------------------------- /v1/diagnose
def test_diagnose_returns_the_contract(client, recording, bundle):
    r = client.post("/v1/diagnose", json=_body(recording))
    assert r.status_code == 200, r.text
    d = r.json()
    assert CONTRACT_KEYS <= set(d)
    assert "windows" not in d  # 0.4 s: one (short) model window
    assert d["model"] == bundle.reference()
    c = d["clearance"]
    assert c["lower"] <= c["estimate"] <= c["upper"]
    assert abs(sum(d["class_probabilities"].values()) - 1) < 1e-9
    # a class, or cannot_tell (these fixtures use the ideal instrumentation, not the model's)
    assert d["fault_class"] in {*d["class_probabilities"], "cannot_tell"}
    assert set(d["observability"]) == {"clearance", "fault"}
    # The service adds nothing to the library's answer.
    direct = diagnose(recording, bundle).to_json()
    assert d["fault_class"] == direct["fault_class"]
    assert d["clearance"]["estimate"] == pytest.approx(direct["clearance"]["estimate"], rel=1e-12)


def test_diagnose_several_windows_and_time_start(client, recording, bundle):
    tiled = {k: np.tile(v, 2).tolist() for k, v in recording.channels.items()}
    body = {"sample_rate": recording.sample_rate, "channels": tiled, "time_start": 10.0}
    d = client.post("/v1/diagnose", json=body).json()
    assert len(d["windows"]) == 2
    assert [w["window"]["index"] for w in d["windows"]] == [0, 1]
    assert d["windows"][0]["window"]["start"] == pytest.approx(10.0)
    # windows of the model's length; the 0.8 s recording's tail (≥ half a window) is the last
    assert d["windows"][1]["window"]["start"] == pytest.approx(10.0 + bundle.window)


def test_diagnose_subset_of_channels(client, recording):
    # The shipped model was trained on what flight-ema fits: a recording with only the
    # accelerometer is diagnosed with what it has, names what is missing, and gives no class
    # (not a guess): cannot_tell, clearance not observable.
    body = {
        "sample_rate": recording.sample_rate,
        "channels": {"nut_axial_accel": recording["nut_axial_accel"].tolist()},
    }
    r = client.post("/v1/diagnose", json=body)
    assert r.status_code == 200, r.text
    d = r.json()
    assert d["fault_class"] == "cannot_tell"
    assert d["observability"] == {"clearance": 0.0, "fault": 0.0}
    assert any(
        "screw_angle, screw_speed, nut_position, drive_torque, housing_temperature missing" in w
        for w in d["warnings"]
    )
    assert d["indicator_groups"]["lost_motion"] == "missing channel(s) nut_position, screw_angle"


def _mutate(run, kind):
    body = _body(run)
    ch = body["channels"]
    if kind == "unknown channel":
        ch["nut_temperature"] = ch["nut_axial_accel"]
    elif kind == "truth column":
        ch["truth_friction_torque"] = ch["drive_torque"]
    elif kind == "truth-only signal":
        ch["carrier_speed"] = ch["screw_speed"]
    elif kind == "lengths differ":
        ch["screw_speed"] = ch["screw_speed"][:-1]
    elif kind == "string sample":
        ch["nut_axial_accel"][5] = "1.0"
    elif kind == "bool sample":
        ch["nut_axial_accel"][5] = True
    elif kind == "nested sample":
        ch["nut_axial_accel"][5] = [1.0]
    elif kind == "channel not a list":
        ch["nut_axial_accel"] = 3.0
    elif kind == "channels not an object":
        body["channels"] = [1, 2, 3]
    elif kind == "sample_rate string":
        body["sample_rate"] = "20000"
    elif kind == "sample_rate zero":
        body["sample_rate"] = 0
    elif kind == "sample_rate too high":
        body["sample_rate"] = 1e9
    elif kind == "missing sample_rate":
        del body["sample_rate"]
    elif kind == "no channels":
        body["channels"] = {}
    elif kind == "too short":
        body["channels"] = {"nut_axial_accel": [0.0] * (MIN_SAMPLES - 1)}
    elif kind == "huge values":
        ch["nut_axial_accel"][0] = 1e300
    elif kind == "unknown field":
        body["temperature"] = 20.0
    elif kind == "bad asset id":
        body["asset_id"] = "../../etc/passwd"
    elif kind == "other design":
        body["design"] = "paper02"
    elif kind == "unknown design":
        body["design"] = "paper99"
    elif kind == "time_start out of range":
        body["time_start"] = 1e300
    return body


INVALID = [
    ("unknown channel", 422, "unknown channel(s) 'nut_temperature'"),
    ("truth column", 422, "'truth_friction_torque'; contract channels: screw_angle"),
    ("truth-only signal", 422, "(carrier_speed: simulator truth, not a measurement"),
    ("lengths differ", 422, "equal lengths"),
    ("string sample", 422, "channels.nut_axial_accel.5"),
    ("bool sample", 422, "channels.nut_axial_accel.5"),
    ("nested sample", 422, "channels.nut_axial_accel.5"),
    ("channel not a list", 422, "channels.nut_axial_accel"),
    ("channels not an object", 422, "channels"),
    ("sample_rate string", 422, "sample_rate"),
    ("sample_rate zero", 422, "sample_rate"),
    ("sample_rate too high", 422, "sample_rate"),
    ("missing sample_rate", 422, "sample_rate: Field required"),
    ("no channels", 422, "at least one contract channel"),
    ("too short", 422, "too short"),
    ("huge values", 422, "beyond"),
    ("unknown field", 422, "unknown field 'temperature'"),
    ("bad asset id", 422, "asset_id"),
    ("other design", 422, "trained on design 'paper01'"),
    ("unknown design", 422, "design"),
    ("time_start out of range", 422, "time_start"),
]


@pytest.mark.parametrize("kind, status, message", INVALID, ids=[k for k, _, _ in INVALID])
def test_diagnose_rejects_invalid_requests(client, recording, kind, status, message):
    r = client.post("/v1/diagnose", json=_mutate(recording, kind))
    assert r.status_code == status, r.text
    assert r.headers["content-type"] == "application/json"
    assert message in r.json()["error"]


@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_diagnose_rejects_non_finite_numbers(client, token):
    samples = ", ".join(["0.0"] * 300 + [token])
    raw = f'{{"sample_rate": 20000, "channels": {{"nut_axial_accel": [{samples}]}}}}'
    r = client.post("/v1/diagnose", content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422
    assert "finite" in r.json()["error"]


@pytest.mark.parametrize(
    "content, ctype, status",
    [
        (b"{not json", "application/json", 422),
        (b"", "application/json", 422),
        (b"[1, 2]", "application/json", 422),
        (b'{"sample_rate": 1}', "text/plain", 415),
        (b'{"sample_rate": 1}', None, 415),
    ],
)
def test_diagnose_rejects_bad_bodies(client, content, ctype, status):
    headers = {"content-type": ctype} if ctype else {}
    r = client.post("/v1/diagnose", content=content, headers=headers)
    assert r.status_code == status, r.text
    assert r.json()["error"]


def test_diagnose_rejects_too_long_recordings(client):
    # default limit: the longest built-in health check (2.62 s) rounded up to 3 s
    assert DEFAULT_MAX_WINDOW_SECONDS == 3.0
    body = {"sample_rate": 1000.0, "channels": {"nut_axial_accel": [0.0] * 3001}}
    r = client.post("/v1/diagnose", json=body)
    assert r.status_code == 413
    assert "at most 3 s" in r.json()["error"]


def test_the_longest_built_in_check_fits_one_request():
    from prsm_health.actuator.health_check import BUILT_IN

    rate = 20_000.0  # the flight-ema logger's rate
    samples = max(int(round(c.duration * rate)) + 1 for c in BUILT_IN.values())
    assert samples <= ServiceLimits().max_json_samples(rate)


def test_body_size_limit_declared_and_streamed(small_server):
    with small_server.client() as c:
        big = b"[" + b"0.0," * 60_000 + b"0.0]"
        r = c.post("/v1/diagnose", content=big, headers={"content-type": "application/json"})
        assert r.status_code == 413
        assert "200000 bytes" in r.json()["error"]

        def chunks():  # no Content-Length: counted while it streams
            for _ in range(30):
                yield b" " * 10_000

        r = c.post("/v1/diagnose", content=chunks(), headers={"content-type": "application/json"})
        assert r.status_code == 413
        # the server is still fine afterwards
        assert c.get("/v1/health").status_code == 200


def test_busy_answers_503(small_server):
    gate = threading.Event()
    answers = {}

    def slow_body():
        yield b'{"sample_rate": 20000, '
        gate.wait(20)
        yield b'"channels": {}}'

    def first():
        with small_server.client() as c:
            answers["first"] = c.post(
                "/v1/diagnose", content=slow_body(), headers={"content-type": "application/json"}
            )

    sender = threading.Thread(target=first)
    sender.start()
    try:
        with small_server.client() as c:
            for _ in range(500):
                if c.get("/v1/health").json()["active_diagnoses"] >= 1:
                    break
                time.sleep(0.01)
            r = c.post("/v1/diagnose", json={"sample_rate": 1.0, "channels": {}})
            assert r.status_code == 503
            assert r.headers["retry-after"] == "2"
            assert "busy" in r.json()["error"]
    finally:
        gate.set()
        sender.join()
    assert answers["first"].status_code == 422  # admitted, then judged on its content


# ----------------------------------------------------------------------------- uploads
@pytest.mark.parametrize("kind", ["mcap", "parquet"])
def test_file_upload(client, files, kind, bundle):
    before = _upload_dirs()
    path = files[kind]
    with open(path, "rb") as f:
        r = client.post("/v1/diagnose/file", files={"file": (path.name, f)})
    assert r.status_code == 200, r.text
    body = r.json()
    assert CONTRACT_KEYS <= set(body["diagnosis"])
    assert len(body["windows"]) == 1
    assert body["windows"][0]["window"]["index"] == 0
    assert body["recording"]["samples"] == 8000
    assert body["recording"]["channels"] == list(CHANNEL_NAMES)  # the file's truth is not used
    assert body["recording"]["filename"] == path.name
    assert body["warnings"] == []
    assert _upload_dirs() <= before  # the temporary directory is gone


def test_file_upload_rejections(client, small_server, files):
    before = _upload_dirs()
    cases = [
        ({"file": ("notes.txt", b"hello")}, None, 415, "unsupported recording type"),
        ({"file": ("run.csv", b"time\n0\n")}, None, 422, "run.csv: "),  # CSV read, refused
        ({"file": ("broken.mcap", b"not an mcap at all")}, None, 422, "broken.mcap: not an MCAP"),
        ({"file": ("broken.parquet", b"PAR1 garbage")}, None, 422, "broken.parquet"),
        ({"other": ("x.mcap", b"")}, None, 422, "unknown form field 'other'"),
        ({"asset_id": (None, "a")}, None, 422, "no recording"),
        ({"file": (None, "a")}, None, 422, "with a file name"),
        (None, {"asset_id": "a"}, 415, "multipart/form-data"),
    ]
    for upload, data, status, message in cases:
        r = client.post("/v1/diagnose/file", files=upload, data=data)
        assert r.status_code == status, (upload, r.text)
        assert message in r.json()["error"]
        assert str(tempfile.gettempdir()) not in r.json()["error"]  # no server paths leak
    with open(files["mcap"], "rb") as f:
        r = client.post("/v1/diagnose/file", files={"file": ("a.mcap", f)}, data={"asset_id": "/x"})
    assert r.status_code == 422 and "asset_id" in r.json()["error"]
    r = client.post("/v1/diagnose/file", json={"file": "x"})
    assert r.status_code == 415
    with small_server.client() as c, open(files["mcap"], "rb") as f:  # 1 MB > 100 kB
        r = c.post("/v1/diagnose/file", files={"file": ("run.mcap", f)})
        assert r.status_code == 413
    with small_server.client() as c, open(files["parquet"], "rb") as f:
        r = c.post("/v1/diagnose/file", files={"file": ("run.parquet", f.read()[:99_000])})
        assert r.status_code == 422  # truncated Parquet: the library's message
    assert _upload_dirs() <= before


def test_truncated_mcap_is_read_up_to_the_damage(client, files):
    data = files["mcap"].read_bytes()
    r = client.post("/v1/diagnose/file", files={"file": ("cut.mcap", data[: len(data) * 7 // 10])})
    assert r.status_code == 200, r.text
    body = r.json()
    assert 256 <= body["recording"]["samples"] < 8000
    assert len(body["warnings"]) == 1 and body["warnings"][0].startswith("cut.mcap: ")


def test_upload_with_non_numeric_channel(client, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / "text.parquet"
    pq.write_table(pa.table({"time": [0.0, 1.0], "nut_axial_accel": ["a", "b"]}), path)
    r = client.post("/v1/diagnose/file", files={"file": ("text.parquet", path.read_bytes())})
    assert r.status_code == 422
    # the Parquet reader checks the column types as the Arrow reader does (io.columns)
    assert r.json()["error"] == (
        "text.parquet: column 'nut_axial_accel' has type string; numbers expected"
    )


def test_upload_sample_limit(small_server, recording, tmp_path):
    # 8000 samples > max_upload_samples = 5000, announced by the Parquet metadata
    short = Run(
        recording.time[:6000],
        {"nut_axial_accel": recording["nut_axial_accel"][:6000]},
        recording.sample_rate,
    )
    path = write_run_parquet(short, tmp_path / "long.parquet")
    with small_server.client() as c:
        r = c.post("/v1/diagnose/file", files={"file": ("long.parquet", path.read_bytes())})
    assert r.status_code == 413
    assert "at most 5000" in r.json()["error"]


# ----------------------------------------------------------------------------- history
def test_history_of_an_asset(client, recording, files):
    asset = "actuator-7"
    assert client.get(f"/v1/assets/{asset}/history").status_code == 404
    first = client.post(
        "/v1/diagnose", json=_body(recording, asset_id=asset, speed=100.0, load=300.0)
    )
    assert first.status_code == 200
    with open(files["mcap"], "rb") as f:
        up = client.post(
            "/v1/diagnose/file", files={"file": ("run.mcap", f)}, data={"asset_id": asset}
        )
    assert up.status_code == 200, up.text

    h = client.get(f"/v1/assets/{asset}/history").json()
    assert h["asset_id"] == asset and h["count"] == 2 and not h["truncated"]
    a, b = h["diagnoses"]
    assert a["received_at"] <= b["received_at"]
    assert a["source"] == "json" and a["speed"] == 100.0 and a["load"] == 300.0
    assert a["diagnosis"] == first.json()
    assert b["source"] == "file" and b["filename"] == "run.mcap" and b["window"]["index"] == 0
    assert b["diagnosis"] == up.json()["windows"][0]

    latest = client.get(f"/v1/assets/{asset}/history", params={"limit": 1}).json()
    assert latest["count"] == 1 and latest["truncated"] and latest["diagnoses"][0]["id"] == b["id"]
    since = client.get(f"/v1/assets/{asset}/history", params={"since": b["received_at"]}).json()
    assert [e["id"] for e in since["diagnoses"]] == [b["id"]]
    future = client.get(f"/v1/assets/{asset}/history", params={"since": "2999-01-01T00:00:00Z"})
    assert future.json()["count"] == 0
    for params in ({"since": "yesterday"}, {"limit": 0}, {"limit": "many"}):
        r = client.get(f"/v1/assets/{asset}/history", params=params)
        assert r.status_code == 422 and r.json()["error"]
    assert client.get("/v1/assets/bad%20id/history").status_code == 422


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def _command_line_service(db: Path, log: Path, *, processes: str = "0", token: str = ""):
    """``prsm-health serve`` in a subprocess on ``db`` (``token`` through the environment
    variable), yielded warm — the model loaded and a diagnosis walked once in the server and in
    each diagnosis process — as (client, url). Leaving stops it with Ctrl-C, which must end it
    with exit status 0, no traceback and nothing leaked (the resource tracker would warn of
    leftover shared memory segments); its stderr is written to ``log``."""
    port = _free_port()
    cmd = [sys.executable, "-m", "prsm_health.apps.cli", "serve", "--port", str(port)]
    cmd += ["--db", str(db), "--processes", processes, "--log-level", "warning"]
    env = {**os.environ, "PRSM_HEALTH_TOKEN": token}  # empty: no token
    url = f"http://127.0.0.1:{port}"
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    with open(log, "wb") as err:
        proc = subprocess.Popen(cmd, env=env, stderr=err, stdout=subprocess.DEVNULL)
        try:
            deadline = time.monotonic() + 120
            while True:
                try:
                    if httpx.get(f"{url}/v1/health", headers=headers, timeout=2).json()["warm"]:
                        break
                except httpx.TransportError:
                    pass
                assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
                time.sleep(0.2)
            with httpx.Client(base_url=url, headers=headers, timeout=60) as client:
                yield client, url
        finally:
            proc.send_signal(signal.SIGINT)
            code = proc.wait(timeout=60)
    text = log.read_text()
    assert code == 0 and "Traceback" not in text and "leaked" not in text, text


@pytest.mark.slow  # the command-line service in two successive subprocesses
def test_history_survives_a_restart(recording, tmp_path):
    # and Ctrl-C stops the service without diagnosis processes cleanly, after a JSON and an
    # Arrow body were diagnosed (with processes: test_ctrl_c_stops_the_command_line_service…)
    db, token = tmp_path / "history.sqlite", "env-token-1234"
    with _command_line_service(db, tmp_path / "first.txt", token=token) as (c, url):
        assert httpx.get(f"{url}/v1/health").status_code == 401  # env token enforced
        stored = c.post("/v1/diagnose", json=_body(recording, asset_id="press-3"))
        assert stored.status_code == 200, stored.text
        arrow = write_run_arrow(recording.without_truth())
        assert c.post("/v1/diagnose", content=arrow, headers=ARROW).status_code == 200
    with _command_line_service(db, tmp_path / "second.txt", token=token) as (c, _):
        h = c.get("/v1/assets/press-3/history")
        assert h.status_code == 200
        assert h.json()["count"] == 1
        assert h.json()["diagnoses"][0]["diagnosis"] == stored.json()


# ----------------------------------------------------------------------------- token
@pytest.mark.parametrize(
    "method, path",
    [
        ("GET", "/v1/health"),
        ("GET", "/v1/model"),
        ("GET", "/openapi.json"),
        ("GET", "/v1/assets/a/history"),
        ("POST", "/v1/diagnose"),
        ("POST", "/v1/diagnose/file"),
        ("GET", "/no-such-endpoint"),
    ],
)
def test_token_required_everywhere(token_server, method, path):
    with token_server.client() as c:
        for headers in ({}, {"Authorization": "Bearer wrong"}, {"Authorization": TOKEN}):
            r = c.request(method, path, headers=headers)
            assert r.status_code == 401, (headers, r.text)
            assert "bearer token" in r.json()["error"]
            assert r.headers["www-authenticate"].startswith("Bearer")


def test_token_accepted(token_server, recording):
    with token_server.client(headers={"Authorization": f"Bearer {TOKEN}"}) as c:
        assert c.get("/v1/health").status_code == 200
        assert "bearerAuth" in c.get("/openapi.json").json()["components"]["securitySchemes"]
        assert c.post("/v1/diagnose", json=_body(recording)).status_code == 200


def test_bind_rules(monkeypatch):
    monkeypatch.delenv("PRSM_HEALTH_TOKEN", raising=False)
    with pytest.raises(PRSMHealthError, match="non-loopback address requires a bearer token"):
        serve("0.0.0.0", 0)
    with pytest.raises(PRSMHealthError, match="requires a bearer token"):
        check_bind("::", None)
    check_bind("0.0.0.0", "a-token")  # allowed with a token
    check_bind("127.0.0.1", None)
    assert is_loopback("localhost") and is_loopback("::1") and is_loopback("127.0.0.2")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.0.2.1")
    with pytest.raises(PRSMHealthError, match="token"):
        create_app(None, ":memory:", "has space", bundle=object(), warmup=False)


def test_http_parser_choice(monkeypatch):
    # httptools (C parser) when installed, else h11; asked for by name, or refused
    assert http_implementation("h11") == "h11"
    assert http_implementation("auto") == http_implementation("httptools") == "httptools"
    with pytest.raises(PRSMHealthError, match="one of"):
        http_implementation("zttp")
    monkeypatch.setitem(sys.modules, "httptools", None)  # as if not installed
    assert http_implementation("auto") == "h11"
    with pytest.raises(PRSMHealthError, match="not installed"):
        http_implementation("httptools")
    with pytest.raises(PRSMHealthError, match="not installed"):
        serve("127.0.0.1", 0, http="httptools")  # refused before the model loads


# ----------------------------------------------------------------------------- concurrency
def test_health_answers_while_diagnoses_run(client, recording):
    body = json.dumps(_body(recording)).encode()
    busy = []
    stop = threading.Event()

    def post():
        with httpx.Client(base_url=str(client.base_url), timeout=60) as c:
            while not stop.is_set():
                c.post("/v1/diagnose", content=body, headers={"content-type": "application/json"})

    workers = [threading.Thread(target=post) for _ in range(4)]
    for w in workers:
        w.start()
    try:
        for _ in range(400):
            h = client.get("/v1/health").json()
            if h["active_diagnoses"] > 0:
                busy.append(h)
                if len(busy) >= 5:
                    break
            time.sleep(0.01)
    finally:
        stop.set()
        for w in workers:
            w.join()
    assert len(busy) >= 5  # /v1/health answered while diagnoses were in progress


# ----------------------------------------------------------------------------- fuzzing
OPERATIONS = [
    ("POST", "/v1/diagnose"),
    ("POST", "/v1/diagnose/file"),
    ("GET", "/v1/assets/{asset_id}/history"),
    ("GET", "/v1/health"),
    ("GET", "/v1/model"),
]


@pytest.fixture(scope="module")
def fuzz_schema(server):
    return schemathesis.openapi.from_url(f"{server.url}/openapi.json")


FUZZ_CASES = [(m, p, "positive") for m, p in OPERATIONS] + [
    (m, p, "negative")
    for m, p in OPERATIONS[:3]  # the others take no input to violate
]


@pytest.mark.parametrize("method, path, mode", FUZZ_CASES)
def test_fuzz_openapi_no_server_errors(fuzz_schema, method, path, mode):
    """Schema-driven requests (schemathesis; valid ones, then ones that violate the schema):
    never a 5xx, and every answer has a documented status, content type and body shape."""
    from hypothesis import given
    from schemathesis.checks import (
        content_type_conformance,
        not_a_server_error,
        response_schema_conformance,
        status_code_conformance,
    )

    operation = fuzz_schema[path][method]
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
        response = case.call(timeout=60)
        case.validate_response(response, checks=checks)

    fuzz()


# ----------------------------------------------------------------------------- processes
@pytest.mark.slow  # spawns two processes that import the package and load the model
def test_diagnosis_processes_answer_as_the_threads_do(bundle, recording, files, tmp_path, client):
    # Two spawned diagnosis processes, each with its own copy of the model: the same answers as
    # the in-process workers (the same code and model), errors crossing back as HTTP answers,
    # and the processes gone when the server stops.
    limits = ServiceLimits(processes=2)
    app = create_app(None, tmp_path / "history.sqlite", None, limits, bundle=bundle)
    with LiveServer(app) as live, live.client() as c:
        deadline = time.monotonic() + 120  # spawn, imports, model, warm-up in each process
        while not c.get("/v1/health").json().get("warm"):
            assert time.monotonic() < deadline, "diagnosis processes did not start"
            time.sleep(0.2)
        body = _body(recording, asset_id="pump-7")
        answer = c.post("/v1/diagnose", json=body)
        assert answer.status_code == 200, answer.text
        first = answer.json()  # with the asset's state, recorded in the server
        assert first.pop("asset")["baseline"]["recordings"] == 1
        assert first == client.post("/v1/diagnose", json=_body(recording)).json()
        with open(files["parquet"], "rb") as f:
            upload = c.post("/v1/diagnose/file", files={"file": ("run.parquet", f)})
        assert upload.status_code == 200, upload.text
        bad = c.post("/v1/diagnose", json={**body, "sample_rate": 0.5})
        assert bad.status_code == 422 and "sample_rate" in bad.json()["error"]
        # a binary body crosses to the process as bytes and is decoded there
        binary = c.post(
            "/v1/diagnose",
            content=write_run_arrow(recording.without_truth()),
            headers=ARROW,
            params={"asset_id": "pump-7"},
        )
        assert binary.status_code == 200
        second = binary.json()  # the asset's second recording (its id: the body's hash)
        assert second.pop("asset")["baseline"]["recordings"] == 2
        assert second == first
        # the bodies crossed through shared memory segments, kept for the next requests
        segments = set(app.state.workers._bodies.names)
        assert segments and all(n.startswith(SHARED_BODY_PREFIX) for n in segments)
        garbage = c.post("/v1/diagnose", content=b"garbage" * 20, headers=ARROW)
        assert garbage.status_code == 422 and garbage.json()["error"].startswith("arrow body: ")
        assert c.get("/v1/assets/pump-7/history").json()["count"] == 2
        pids = [p.pid for p in app.state.workers._processes._processes.values()]
        # a diagnosis process killed (out of memory, say): 503 with Retry-After while a new
        # pool starts, then answers again (seen [503, 200]; a request that beats the pool's
        # notice of the death may be answered 200 at once)
        os.kill(pids[0], signal.SIGKILL)
        statuses = []
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and statuses[-1:] != [200]:
            r = c.post("/v1/diagnose", json=_body(recording))
            statuses.append(r.status_code)
            if r.status_code == 503:
                assert r.headers["retry-after"] == "2"
        assert statuses[-1] == 200 and set(statuses) <= {200, 503}, statuses
        pids += [p.pid for p in app.state.workers._processes._processes.values()]
        segments |= set(app.state.workers._bodies.names)
    assert len(pids) >= 2
    # no segment left behind by the killed process or the stopped server
    for name in segments:
        with pytest.raises(FileNotFoundError):
            SharedMemory(name).close()
    for pid in pids:  # shut down with the server (the killed one long gone)
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


@pytest.mark.slow  # the command-line service and its two diagnosis processes
def test_ctrl_c_stops_the_command_line_service_without_a_traceback(tmp_path, recording):
    # with diagnosis processes (without them: the two stops of test_history_survives_a_restart)
    service = _command_line_service(tmp_path / "h.sqlite", tmp_path / "err.txt", processes="2")
    with service as (c, _):
        # a body large enough to cross to a diagnosis process through shared memory
        arrow = write_run_arrow(recording.without_truth())
        r = c.post("/v1/diagnose", content=arrow, headers=ARROW)
        assert r.status_code == 200, r.text
