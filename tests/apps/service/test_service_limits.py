"""Bounds of ``ServiceLimits`` that the fixed request models do not carry: checked where the
limits are known (validation context, a FastAPI dependency, the recording checks) and written
into the OpenAPI document. In-process ASGI calls, no server."""

import anyio
import httpx
import numpy as np
import pytest

from prsm_health.apps.service import ServiceLimits, create_app
from prsm_health.apps.service.responses import HTTPError
from prsm_health.apps.service.schemas import DiagnoseRequest, parse_diagnose_request
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet

LIMITS = ServiceLimits(
    min_sample_rate=10, max_sample_rate=1e5, max_history=50, max_upload_samples=5000
)


@pytest.fixture(scope="module")
def app():
    return create_app(None, ":memory:", None, LIMITS, bundle=load_bundle(), warmup=False)


def _call(app, method: str, url: str, **kwargs) -> httpx.Response:
    async def main():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.request(method, url, **kwargs)

    return anyio.run(main)


def _body(rate: float) -> bytes:
    return b'{"sample_rate": %r, "channels": {"nut_axial_accel": [0.0, 1.0]}}' % rate


@pytest.mark.parametrize(
    "rate, message",
    [
        (5.0, "sample_rate: Input should be greater than or equal to 10"),
        (2e5, "sample_rate: Input should be less than or equal to 100000"),
    ],
)
def test_sample_rate_bounds_from_the_limits(app, rate, message):
    with pytest.raises(HTTPError) as info:
        parse_diagnose_request(_body(rate), LIMITS)
    assert info.value.status == 422 and info.value.message == message
    r = _call(
        app,
        "POST",
        "/v1/diagnose",
        content=_body(rate),
        headers={"content-type": "application/json"},
    )
    assert r.status_code == 422 and r.json() == {"error": message}
    # Without a context the model applies the default limits.
    assert DiagnoseRequest.model_validate_json(_body(5.0)).sample_rate == 5.0


def test_history_limit_bound_from_the_limits(app):
    r = _call(app, "GET", "/v1/assets/a/history", params={"limit": 51})
    assert r.status_code == 422
    assert r.json() == {"error": "query.limit: Input should be less than or equal to 50"}
    # The default (100) is cut to max_history, not refused: nothing stored yet → 404.
    assert _call(app, "GET", "/v1/assets/a/history").status_code == 404
    assert _call(app, "GET", "/v1/assets/a/history", params={"limit": 50}).status_code == 404


def test_openapi_shows_the_limits(app):
    doc = _call(app, "GET", "/openapi.json").json()
    rate = doc["components"]["schemas"]["DiagnoseRequest"]["properties"]["sample_rate"]
    assert (rate["minimum"], rate["maximum"]) == (10, 1e5)
    parameters = doc["paths"]["/v1/assets/{asset_id}/history"]["get"]["parameters"]
    assert [p["name"] for p in parameters] == ["asset_id", "limit", "since"]
    assert parameters[1]["schema"]["maximum"] == 50
    channel = doc["components"]["schemas"]["Channels"]["properties"]["nut_axial_accel"]
    assert channel["description"] == "nut acceleration along the screw axis [m/s^2]"


def test_upload_longer_than_the_limit_is_413(app, tmp_path):
    # MCAP has no sample count to precheck: Run.validate's RecordingTooLongError answers.
    n, rate = 6000, 20000.0
    run = Run(np.arange(n) / rate, {"nut_axial_accel": np.zeros(n)}, rate)
    data = write_mcap(run, tmp_path / "long.mcap").read_bytes()
    r = _call(app, "POST", "/v1/diagnose/file", files={"file": ("long.mcap", data)})
    assert r.status_code == 413, r.text
    assert r.json()["error"].startswith("long.mcap too long: 6000 samples")
    assert "at most 5000 samples" in r.json()["error"]


def test_upload_sample_rate_outside_the_limits(app, tmp_path):
    n, rate = 600, 5.0
    run = Run(np.arange(n) / rate, {"nut_axial_accel": np.zeros(n)}, rate)
    data = write_run_parquet(run, tmp_path / "slow.parquet").read_bytes()
    r = _call(app, "POST", "/v1/diagnose/file", files={"file": ("slow.parquet", data)})
    assert r.status_code == 422
    assert r.json() == {
        "error": "slow.parquet: sample_rate = 5 Hz is outside the accepted range [10, 100000] Hz"
    }


def test_serve_takes_the_limits_default_window_unless_given(monkeypatch):
    # without --max-window the service's default (the longest built-in check fits); with it,
    # the value given
    import prsm_health.apps.service as service
    from prsm_health.apps.cli import main
    from prsm_health.apps.service.limits import DEFAULT_MAX_WINDOW_SECONDS

    seen = {}
    monkeypatch.setattr(service, "serve", lambda *a, **kw: seen.update(kw))
    assert main(["serve"]) == 0
    assert seen["limits"].max_window_seconds == DEFAULT_MAX_WINDOW_SECONDS
    assert main(["serve", "--max-window", "3"]) == 0
    assert seen["limits"].max_window_seconds == 3.0
