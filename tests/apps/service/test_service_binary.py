"""``POST /v1/diagnose`` with the recording as a binary body (Arrow IPC stream, Parquet, MCAP)
beside JSON: the same diagnosis, the query parameters, and every bad body a 4xx with one
message — a decompression bomb refused from what it declares, before it is decoded. In-process
ASGI calls (threads), no server."""

import json

import anyio
import httpx
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from prsm_health.apps.service import ServiceLimits, create_app
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet

ARROW = "application/vnd.apache.arrow.stream"
PARQUET = "application/vnd.apache.parquet"
MCAP = "application/vnd.mcap"


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def app(bundle):
    return create_app(None, ":memory:", None, ServiceLimits(), bundle=bundle, warmup=False)


@pytest.fixture(scope="module")
def small_app(bundle):
    """Decoded-size limit of 256 KiB, to reach it with small bodies."""
    limits = ServiceLimits(max_body_decoded_bytes=2**18)
    return create_app(None, ":memory:", None, limits, bundle=bundle, warmup=False)


@pytest.fixture(scope="module")
def recording(reversing_run):
    return reversing_run(20e-6, seed=3).without_truth()  # 0.4 s at 20 kHz: one window


def _file_bytes(run, fmt: str, tmp_path) -> bytes:
    path = tmp_path / f"run.{fmt}"
    (write_run_parquet if fmt == "parquet" else write_mcap)(run, path)
    return path.read_bytes()


@pytest.fixture(scope="module")
def bodies(recording, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bodies")
    return {
        "arrow": (ARROW, write_run_arrow(recording)),
        "arrow-zstd": (ARROW, write_run_arrow(recording, compression="zstd")),
        "parquet": (PARQUET, _file_bytes(recording, "parquet", tmp)),
        "x-parquet": ("application/x-parquet", _file_bytes(recording, "parquet", tmp)),
        "mcap": (MCAP, _file_bytes(recording, "mcap", tmp)),
        "x-mcap": ("application/x-mcap", _file_bytes(recording, "mcap", tmp)),
    }


def _post(app, content: bytes, ctype: str | None, params=None, url="/v1/diagnose"):
    async def main():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            headers = {"content-type": ctype} if ctype else {}
            return await client.post(url, content=content, headers=headers, params=params)

    return anyio.run(main)


def _get(app, url: str, params=None) -> httpx.Response:
    async def main():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.get(url, params=params)

    return anyio.run(main)


def _json_body(run) -> bytes:
    # the files carry the run's labels, a gear ratio among them (the efficiency indicator
    # needs it): the JSON body says it as a field
    return json.dumps(
        {
            "sample_rate": run.sample_rate,
            "channels": {k: v.tolist() for k, v in run.channels.items()},
            "gear_ratio": run.operating.gear_ratio,
        }
    ).encode()


@pytest.fixture(scope="module")
def json_answer(app, recording):
    r = _post(app, _json_body(recording), "application/json")
    assert r.status_code == 200, r.text
    return r.json()


@pytest.mark.parametrize("kind", ["arrow", "arrow-zstd", "parquet", "x-parquet", "mcap", "x-mcap"])
def test_binary_body_gives_the_json_diagnosis(app, bodies, json_answer, kind):
    ctype, content = bodies[kind]
    r = _post(app, content, f"{ctype}; charset=binary" if kind == "arrow" else ctype)
    assert r.status_code == 200, r.text
    assert r.headers["content-type"] == "application/json"
    assert r.json() == json_answer


@pytest.mark.parametrize("kind", ["arrow", "parquet", "mcap"])
def test_query_parameters_store_the_diagnosis(app, bodies, json_answer, kind):
    ctype, content = bodies[kind]
    asset = f"press-{kind}"
    params = {"asset_id": asset, "speed": "100", "load": "-300.5", "design": "paper01"}
    r = _post(app, content, ctype, params)
    assert r.status_code == 200, r.text
    answer = r.json()
    # with an asset, the asset's state too (tests/apps/service/test_service_asset_evidence.py)
    assert answer.pop("asset")["asset_id"] == asset
    assert answer == json_answer
    history = _get(app, f"/v1/assets/{asset}/history").json()
    assert history["count"] == 1
    entry = history["diagnoses"][0]
    assert (entry["source"], entry["speed"], entry["load"]) == (kind, 100.0, -300.5)
    assert entry["diagnosis"] == r.json()


def test_arrow_without_metadata_takes_the_rate_from_time(app, recording, json_answer):
    # what a client writes with plain pyarrow: time and channel columns, no prsm_health metadata
    columns = {"time": recording.time, **recording.channels}
    table = pa.table({k: np.asarray(v, dtype=float) for k, v in columns.items()})
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        for batch in table.to_batches(max_chunksize=1000):  # several record batches
            writer.write_batch(batch)
    r = _post(app, sink.getvalue().to_pybytes(), ARROW)
    assert r.status_code == 200, r.text
    answer = r.json()
    assert answer["clearance"] == pytest.approx(json_answer["clearance"], rel=1e-9)
    assert answer["fault_class"] == json_answer["fault_class"]


def _garbage_cases(bodies):
    cases = []
    for kind in ("arrow", "arrow-zstd", "parquet"):
        ctype, content = bodies[kind]
        cases += [(kind, ctype, content[: len(content) // 2]), (kind, ctype, content[:-100])]
    for kind in ("arrow", "parquet", "mcap"):
        ctype, content = bodies[kind]
        cases += [(kind, ctype, b"garbage" * 50), (kind, ctype, content[:40])]
    return cases


def test_truncated_or_garbage_bodies_are_4xx_with_one_message(app, bodies):
    for kind, ctype, content in _garbage_cases(bodies):
        r = _post(app, content, ctype)
        assert 400 <= r.status_code < 500, (kind, len(content), r.status_code, r.text)
        error = r.json()["error"]
        assert f"{kind.split('-')[0]} body" in error, error
        assert "\n" not in error and "Traceback" not in error and "/tmp" not in error


def test_truncated_mcap_is_read_up_to_the_damage(app, bodies):
    # the project's MCAP convention (uploads, replay): an interrupted recording is diagnosed
    # up to the damage, the reader's note among the warnings
    ctype, content = bodies["mcap"]
    r = _post(app, content[: int(len(content) * 0.8)], ctype)
    assert r.status_code == 200, r.text
    assert "mcap body: the file ends at byte" in r.json()["warnings"][0]


@pytest.mark.parametrize(
    "ctype",
    [None, "text/plain", "application/octet-stream", "multipart/form-data; boundary=x"],
)
def test_unknown_content_type_is_415(app, bodies, ctype):
    r = _post(app, bodies["arrow"][1], ctype)
    assert r.status_code == 415
    assert "application/vnd.apache.arrow.stream" in r.json()["error"]


def test_empty_body_is_400(app):
    r = _post(app, b"", ARROW)
    assert r.status_code == 400 and r.json() == {
        "error": "empty request body: send the recording (arrow)"
    }


@pytest.mark.parametrize(
    "params, message",
    [
        ({"asset": "x"}, "unknown query parameter 'asset'"),
        ({"asset_id": "no spaces"}, "asset_id 'no spaces' must match"),
        ({"speed": "fast"}, "speed = 'fast': a finite number expected"),
        ({"load": "inf"}, "load = 'inf': a finite number expected"),
        ({"design": "paper02"}, "design = 'paper02': model"),
        ({"design": "nope"}, "design = 'nope': model"),
    ],
)
def test_bad_query_parameters_are_422(app, bodies, params, message):
    r = _post(app, bodies["arrow"][1], ARROW, params)
    assert r.status_code == 422 and message in r.json()["error"], r.text


def test_json_body_takes_no_query_parameters(app, recording):
    r = _post(app, _json_body(recording), "application/json", {"asset_id": "x"})
    assert r.status_code == 422
    assert r.json()["error"].startswith("query parameter 'asset_id': a JSON body carries")


def test_non_numeric_channel_column_is_422(app, recording):
    n = len(recording)
    table = pa.table({"time": recording.time, "nut_axial_accel": ["x"] * n})
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    r = _post(app, sink.getvalue().to_pybytes(), ARROW)
    assert r.status_code == 422
    assert r.json()["error"] == (
        "arrow body: column 'nut_axial_accel' has type string; numbers expected"
    )


def test_bad_sample_rate_metadata_is_422(app, recording):
    data = write_run_arrow(recording)
    table = pa.ipc.open_stream(data).read_all()
    meta = {**table.schema.metadata, b"prsm_health.sample_rate": b"nan"}
    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema.with_metadata(meta)) as writer:
        writer.write_table(table)
    r = _post(app, sink.getvalue().to_pybytes(), ARROW)
    assert r.status_code == 422 and "sample_rate = nan Hz is outside" in r.json()["error"]


def test_recording_longer_than_max_window_is_413(app, reversing_run):
    # 3.1 s of the run's channels repeated (no need to simulate that long: only its length
    # is checked)
    run = reversing_run(20e-6, seed=3).without_truth()
    n = int(3.1 * run.sample_rate)
    reps = -(-n // len(run))
    channels = {k: np.tile(v, reps)[:n] for k, v in run.channels.items()}
    long = Run(np.arange(n) / run.sample_rate, channels, run.sample_rate, dict(run.labels))
    r = _post(app, write_run_arrow(long), ARROW)
    assert r.status_code == 413
    assert "at most 3 s per request" in r.json()["error"]


# ----------------------------------------------------------------------------- bombs
def _zeros_table(rows: int) -> pa.Table:
    zeros = pa.array(np.zeros(rows))
    return pa.table({"time": zeros, "nut_axial_accel": zeros})


@pytest.fixture
def no_decoding(monkeypatch):
    """A body that reaches the readers fails the test: the guard must refuse it first."""

    def refuse(*args, **kwargs):
        raise AssertionError("the body was decoded")

    monkeypatch.setattr("prsm_health.apps.service.diagnosing.read_with_warnings", refuse)


def test_compressed_arrow_bomb_is_413_before_decoding(app, no_decoding):
    sink = pa.BufferOutputStream()
    table = _zeros_table(5_000_000)  # 80 MB of zeros → ~50 kB of zstd
    options = pa.ipc.IpcWriteOptions(compression="zstd")
    with pa.ipc.new_stream(sink, table.schema, options=options) as writer:
        writer.write_table(table)
    bomb = sink.getvalue().to_pybytes()
    assert len(bomb) < 200_000
    r = _post(app, bomb, ARROW)
    assert r.status_code == 413
    assert r.json()["error"].startswith("recording too long: 5000000 samples, at most 600000")


def test_compressed_parquet_bomb_is_413_before_decoding(app, no_decoding):
    sink = pa.BufferOutputStream()
    pq.write_table(_zeros_table(5_000_000), sink, compression="zstd")
    bomb = sink.getvalue().to_pybytes()
    assert len(bomb) < 1_000_000
    r = _post(app, bomb, PARQUET)
    assert r.status_code == 413
    assert r.json()["error"].startswith("recording too long: 5000000 samples, at most 600000")


@pytest.mark.parametrize("kind", ["arrow-zstd", "parquet", "mcap"])
def test_decoded_size_limit_is_413_before_decoding(small_app, bodies, kind, no_decoding):
    # 0.4 s of 9 channels: ~0.3 MB compressed, more than 256 KiB once decompressed
    ctype, content = bodies[kind]
    r = _post(small_app, content, ctype)
    assert r.status_code == 413
    assert r.json()["error"] == (
        "recording decompresses to more than 262144 bytes (max_body_decoded_bytes)"
    )


def test_openapi_documents_the_binary_bodies(app):
    operation = _get(app, "/openapi.json").json()["paths"]["/v1/diagnose"]["post"]
    content = operation["requestBody"]["content"]
    assert set(content) == {
        "application/json",
        ARROW,
        PARQUET,
        "application/x-parquet",
        MCAP,
        "application/x-mcap",
    }
    assert {p["name"] for p in operation["parameters"]} == {
        "asset_id",
        "speed",
        "load",
        "design",
        "operating_hours",
        "healthy",
        "recording_id",
    }
    assert {"400", "413", "415", "422", "503"} <= set(operation["responses"])
