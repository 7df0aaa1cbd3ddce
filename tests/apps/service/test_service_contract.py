"""Real answers against the published schema: the service's OpenAPI document is generated from
the library's Diagnosis declaration (prsm_health.diagnostics.contract), and every answer the
service gives to real recordings — one window, several, a subset of channels, no reversal, a
binary body, an upload, the stored history — and the CLI's ``diagnose --json`` validate against
it. In-process ASGI calls (threads), no server."""

import json

import anyio
import httpx
import jsonschema
import numpy as np
import pytest

from prsm_health.apps.cli import main
from prsm_health.apps.service import ServiceLimits, create_app
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.parquet import write_run_parquet

#: The Diagnosis contract's fields (docs/formats.md, DESIGN.md): each always present.
CONTRACT_FIELDS = {
    "clearance",
    "fault_class",
    "class_probabilities",
    "class_set",
    "observability",
    "ood_score",
    "indicators",
    "indicator_groups",
    "model",
    "warnings",
}


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def app(bundle):
    return create_app(None, ":memory:", None, ServiceLimits(), bundle=bundle, warmup=False)


@pytest.fixture(scope="module")
def recording(reversing_run):
    return reversing_run(20e-6, seed=3).without_truth()  # 0.4 s at 20 kHz: one window


def _call(app, method: str, url: str, **kwargs) -> httpx.Response:
    async def run():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.request(method, url, **kwargs)

    return anyio.run(run)


@pytest.fixture(scope="module")
def doc(app) -> dict:
    r = _call(app, "GET", "/openapi.json")
    assert r.status_code == 200
    return r.json()


def _validator(doc: dict, schema: dict) -> jsonschema.Draft202012Validator:
    # the document is the root: its "#/components/schemas/…" references resolve inside it
    root = {**schema, "components": doc["components"]}
    jsonschema.Draft202012Validator.check_schema(root)
    return jsonschema.Draft202012Validator(root)


def _answer_schema(doc: dict, path: str, method: str = "post") -> jsonschema.Draft202012Validator:
    """The published schema of a path's 200 answer."""
    content = doc["paths"][path][method]["responses"]["200"]["content"]
    return _validator(doc, content["application/json"]["schema"])


def _diagnosis_schema(doc: dict) -> jsonschema.Draft202012Validator:
    return _validator(doc, {"$ref": "#/components/schemas/Diagnosis"})


def _body(run: Run, **extra) -> dict:
    return {
        "sample_rate": run.sample_rate,
        "channels": {k: v.tolist() for k, v in run.channels.items()},
        **extra,
    }


def _check(validator: jsonschema.Draft202012Validator, answer: dict) -> None:
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(answer)]
    assert not errors, errors[:5]


def test_published_schema_is_the_contract(doc):
    schemas = doc["components"]["schemas"]
    diagnosis = schemas["Diagnosis"]
    assert set(diagnosis["required"]) == CONTRACT_FIELDS
    optional = {"window", "windows", "undecided", "check_phases", "asset", "measured_clearance"}
    assert set(diagnosis["properties"]) == CONTRACT_FIELDS | optional
    assert diagnosis["additionalProperties"] is False
    assert set(schemas["ClearanceInterval"]["required"]) == {"estimate", "lower", "upper"}
    assert set(schemas["ModelReference"]["required"]) == {
        "name",
        "version",
        "design",
        "instrumentation",
    }
    assert set(schemas["Observability"]["required"]) == {"clearance", "fault"}
    # each field says what it means
    assert all(p.get("description") for p in diagnosis["properties"].values())


def test_schema_rejects_what_breaks_the_contract(doc, app, recording):
    validator = _diagnosis_schema(doc)
    answer = _call(app, "POST", "/v1/diagnose", json=_body(recording)).json()
    _check(validator, answer)
    for broken in (
        {k: v for k, v in answer.items() if k != "clearance"},
        {**answer, "unexpected": 1},
        {**answer, "clearance": {"estimate": "wide"}},
        {**answer, "observability": {"clearance": "yes", "fault": True}},
        {**answer, "model": {"name": "m", "version": "1", "design": "paper01"}},
    ):
        assert not validator.is_valid(broken), broken


def test_every_json_answer_matches_the_published_schema(doc, app, recording, reversing_run):
    validator = _answer_schema(doc, "/v1/diagnose")
    n = len(recording)
    accel = {"nut_axial_accel": recording["nut_axial_accel"].tolist()}
    steady = reversing_run(20e-6, seed=3, load=100.0, load_profile="constant").without_truth()
    bodies = {
        "one window": _body(recording),
        "windows and a tail": {
            "sample_rate": recording.sample_rate,
            "channels": {
                k: np.tile(v, 3)[: 5 * n // 2].tolist() for k, v in recording.channels.items()
            },
        },
        "accelerometer only": {"sample_rate": recording.sample_rate, "channels": accel},
        "no reversal": _body(steady, asset_id="contract-1", operating_hours=10.0),
    }
    answers = {}
    for name, body in bodies.items():
        r = _call(app, "POST", "/v1/diagnose", json=body)
        assert r.status_code == 200, (name, r.text)
        answers[name] = r.json()
        _check(validator, answers[name])
    # the cases differ where the schema allows: windows present or not, observability
    assert "windows" in answers["windows and a tail"]
    assert all(
        isinstance(w["observability"]["clearance"], bool)
        for w in answers["windows and a tail"]["windows"]
    )
    assert answers["accelerometer only"]["observability"] == {"clearance": 0.0, "fault": 0.0}
    assert answers["no reversal"]["fault_class"] == "cannot_tell"
    assert answers["one window"]["model"]["instrumentation"] == "flight-ema"


def test_binary_upload_and_history_answers_match_the_published_schema(
    doc, app, recording, tmp_path
):
    r = _call(
        app,
        "POST",
        "/v1/diagnose",
        content=write_run_arrow(recording),
        headers={"content-type": "application/vnd.apache.arrow.stream"},
        params={"asset_id": "contract-2", "operating_hours": "12.5"},
    )
    assert r.status_code == 200, r.text
    _check(_answer_schema(doc, "/v1/diagnose"), r.json())

    long = Run(
        np.arange(2 * len(recording)) / recording.sample_rate,
        {k: np.tile(v, 2) for k, v in recording.channels.items()},
        recording.sample_rate,
    )
    path = write_run_parquet(long, tmp_path / "long.parquet")
    with path.open("rb") as f:
        r = _call(
            app,
            "POST",
            "/v1/diagnose/file",
            files={"file": ("long.parquet", f, "application/octet-stream")},
            data={"asset_id": "contract-2"},
        )
    assert r.status_code == 200, r.text
    upload = r.json()
    _check(_answer_schema(doc, "/v1/diagnose/file"), upload)
    assert len(upload["windows"]) == 2

    history = _call(app, "GET", "/v1/assets/contract-2/history")
    assert history.status_code == 200
    _check(_answer_schema(doc, "/v1/assets/{asset_id}/history", "get"), history.json())
    # what the history stores is the contract, as answered
    stored = history.json()["diagnoses"]
    assert len(stored) == 3
    for entry in stored:
        _check(_diagnosis_schema(doc), entry["diagnosis"])
    assets = _call(app, "GET", "/v1/assets")
    _check(_answer_schema(doc, "/v1/assets", "get"), assets.json())


def test_cli_diagnose_json_matches_the_published_schema(doc, recording, tmp_path, capsys):
    path = write_run_parquet(recording, tmp_path / "r.parquet")
    assert main(["diagnose", str(path), "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    _check(_diagnosis_schema(doc), answer)
    assert set(answer) >= CONTRACT_FIELDS


def test_the_docs_json_example_sends_only_measured_channels(tmp_path, monkeypatch, capsys):
    # docs/service.md's JSON body from a simulated run.parquet (measured and truth columns)
    # must be a valid request: truth_* channels are 422.
    import re
    import runpy
    from pathlib import Path

    from prsm_health.apps.service.schemas import DiagnoseRequest
    from prsm_health.core.channels import CHANNEL_NAMES, TRUTH_NAMES

    text = (Path(__file__).resolve().parents[3] / "docs" / "service.md").read_text()
    script = re.search(r"python - <<'EOF' > body.json\n(.*?)\nEOF", text, re.S).group(1)
    n, rate = 300, 20_000.0
    zeros = np.zeros(n)
    run = Run(
        np.arange(n) / rate,
        dict.fromkeys(CHANNEL_NAMES, zeros),
        rate,
        truth=dict.fromkeys(TRUTH_NAMES, zeros),
    )
    write_run_parquet(run, tmp_path / "run.parquet")
    (tmp_path / "example.py").write_text(script)
    monkeypatch.chdir(tmp_path)
    runpy.run_path("example.py")
    body = json.loads(capsys.readouterr().out)
    request = DiagnoseRequest.model_validate(body)
    assert set(request.channels.model_dump(exclude_none=True)) == set(CHANNEL_NAMES)


def test_the_docs_say_whether_the_shipped_model_has_a_check_part():
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[3] / "docs" / "service.md").read_text()
    text = " ".join(text.split())
    from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL, check_part_path

    has_check = check_part_path(DEFAULT_MODEL).exists()  # load_bundle loads it when there
    assert bool(re.search(r"shipped model[^.]*has a health-check part", text)) == has_check
    assert bool(re.search(r"shipped model[^.]*has no health-check part", text)) == (not has_check)
