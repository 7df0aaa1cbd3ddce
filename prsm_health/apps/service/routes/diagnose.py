"""``POST /v1/diagnose`` (a JSON body, or a recording as an Arrow IPC, Parquet or MCAP body)
and ``POST /v1/diagnose/file`` (multipart upload): admit the request, run the diagnosis in the
worker pool, store it in the asset's history. Bodies are decoded where the diagnosis runs."""

import math

import anyio
from fastapi import APIRouter, Request

from prsm_health.actuator.design import PRESETS
from prsm_health.monitoring import asset_reference
from prsm_health.monitoring.sqlite_store import utc_now

from ..diagnosing import (
    BaselineFor,
    BodyParams,
    check_asset_fields,
    diagnose_body,
    diagnose_upload,
    peek_asset_id,
    record_and_encode,
)
from ..limits import MAX_OPERATING_HOURS
from ..responses import HTTPError, json_response
from ..schemas import (
    ASSET_ID_PATTERN,
    ERROR_RESPONSES,
    HEALTHY_DESCRIPTION,
    OPERATING_HOURS_DESCRIPTION,
    RECORDING_ID_DESCRIPTION,
    RECORDING_ID_PATTERN,
    Diagnosis,
    Error,
    FileDiagnosis,
    parse_query_params,
)
from ..uploads import multipart_boundary, receive_upload, upload_directory
from .deps import Bundle, Limits, Store, Workers

router = APIRouter()

#: Content types of ``POST /v1/diagnose`` → body format.
BODY_TYPES = {
    "application/json": "json",
    "application/vnd.apache.arrow.stream": "arrow",
    "application/vnd.apache.parquet": "parquet",
    "application/x-parquet": "parquet",
    "application/vnd.mcap": "mcap",
    "application/x-mcap": "mcap",
}
_BINARY_DESCRIPTIONS = {
    "arrow": "Arrow IPC stream: a `time` column [s] and contract channel columns (numbers), "
    "as the single-run Parquet file; sample rate from the `prsm_health.sample_rate` schema "
    "metadata, else 1/(median time step)",
    "parquet": "single-run Parquet file (docs/formats.md)",
    "mcap": "MCAP recording (docs/formats.md)",
}
_JSON_BODY = {
    "parameters": [
        {
            "name": "asset_id",
            "in": "query",
            "required": False,
            "description": "binary bodies only (a JSON body has the field): store the diagnosis "
            "in this asset's history",
            "schema": {"type": "string", "pattern": ASSET_ID_PATTERN},
        },
        {
            "name": "speed",
            "in": "query",
            "required": False,
            "description": "binary bodies only: nominal screw speed [rad/s] (stored)",
            "schema": {"type": "number"},
        },
        {
            "name": "load",
            "in": "query",
            "required": False,
            "description": "binary bodies only: nominal axial load [N] (stored)",
            "schema": {"type": "number"},
        },
        {
            "name": "design",
            "in": "query",
            "required": False,
            "description": "binary bodies only: design preset (must be the model's)",
            "schema": {"type": "string", "enum": sorted(PRESETS)},
        },
        {
            "name": "operating_hours",
            "in": "query",
            "required": False,
            "description": f"binary bodies only: {OPERATING_HOURS_DESCRIPTION}",
            "schema": {"type": "number", "minimum": 0, "maximum": MAX_OPERATING_HOURS},
        },
        {
            "name": "healthy",
            "in": "query",
            "required": False,
            "description": f"binary bodies only: {HEALTHY_DESCRIPTION}",
            "schema": {"type": "boolean"},
        },
        {
            "name": "recording_id",
            "in": "query",
            "required": False,
            "description": f"binary bodies only: {RECORDING_ID_DESCRIPTION}; a binary body's "
            "default: the hash of its bytes",
            "schema": {"type": "string", "pattern": RECORDING_ID_PATTERN},
        },
    ],
    "requestBody": {
        "required": True,
        "content": {
            "application/json": {"schema": {"$ref": "#/components/schemas/DiagnoseRequest"}},
            **{
                ctype: {
                    "schema": {
                        "type": "string",
                        "format": "binary",
                        "description": _BINARY_DESCRIPTIONS[fmt],
                    }
                }
                for ctype, fmt in BODY_TYPES.items()
                if fmt != "json"
            },
        },
    },
}
_MULTIPART_BODY = {
    "requestBody": {
        "required": True,
        "content": {
            "multipart/form-data": {
                "schema": {
                    "type": "object",
                    "required": ["file"],
                    "properties": {
                        "file": {
                            "type": "string",
                            "format": "binary",
                            "description": "recording (.mcap, .parquet or .csv, by file name)",
                        },
                        "map": {
                            "type": "string",
                            "format": "binary",
                            "description": "column map of a CSV or Parquet recording (TOML, "
                            "docs/import.md)",
                        },
                        "asset_id": {
                            "type": "string",
                            "pattern": ASSET_ID_PATTERN,
                            "description": "store every window in this asset's history "
                            "and record the recording in the asset's baseline and evidence",
                        },
                        "healthy": {
                            "type": "string",
                            "enum": ["true", "false"],
                            "description": HEALTHY_DESCRIPTION,
                        },
                        "recording_id": {
                            "type": "string",
                            "pattern": RECORDING_ID_PATTERN,
                            "description": f"{RECORDING_ID_DESCRIPTION}; an upload's default: "
                            "the hash of the file (and of its column map)",
                        },
                        "operating_hours": {
                            "type": "string",
                            "description": "the asset's operating hours at the recording [h] "
                            "(a number ≥ 0): what its prognosis reads",
                        },
                    },
                }
            }
        },
    }
}


def body_format(request: Request) -> str:
    """The format of a ``POST /v1/diagnose`` body from its Content-Type; 415 otherwise."""
    ctype = request.headers.get("content-type", "")
    fmt = BODY_TYPES.get(ctype.split(";")[0].strip().lower())
    if fmt is None:
        raise HTTPError(
            415,
            f"Content-Type {ctype or 'missing'!r} is not accepted: send application/json, "
            "application/vnd.apache.arrow.stream, application/vnd.apache.parquet or "
            "application/vnd.mcap (multipart uploads go to /v1/diagnose/file)",
        )
    return fmt


def body_params(request: Request, fmt: str) -> BodyParams | None:
    """A binary body's query parameters; a JSON body takes none (its fields say it all)."""
    items = request.query_params.multi_items()
    if fmt != "json":
        return BodyParams(**parse_query_params(items).model_dump())
    if items:
        raise HTTPError(
            422,
            f"query parameter {items[0][0]!r}: a JSON body carries asset_id, speed, load, "
            "design, gear_ratio, healthy, recording_id and operating_hours as fields (query "
            "parameters are for binary bodies)",
        )
    return None


@router.post(
    "/v1/diagnose",
    summary="Diagnose a recording sent as JSON, Arrow IPC, Parquet or MCAP",
    response_model=None,
    responses={
        200: {"model": Diagnosis, "description": "the Diagnosis contract"},
        **ERROR_RESPONSES,
        400: {"model": Error, "description": "empty body"},
        415: {"model": Error, "description": "Content-Type not accepted"},
    },
    openapi_extra=_JSON_BODY,
)
async def post_diagnose(
    request: Request, store: Store, limits: Limits, workers: Workers, bundle: Bundle
):
    """Diagnose uniformly sampled contract channels (at most `max_window_seconds`, 2 s by
    default), sent as JSON or as a recording (Arrow IPC stream, Parquet or MCAP: decoded by
    the library's readers; the asset and nominal operating point then come as query
    parameters). With `asset_id` the diagnosis is stored in the asset's history, with
    `operating_hours` when given (the prognosis uses those)."""
    received_at = utc_now()
    fmt = body_format(request)
    params = body_params(request, fmt)
    with workers.admitted():
        body = await request.body()
        asset_id = params.asset_id if params is not None else peek_asset_id(body)
        baseline = await load_baseline(store, bundle, asset_id)
        answer = await workers.diagnose(
            diagnose_body, body, fmt, params, limits, received_at, baseline
        )
        del body
    return json_response(await store_answer(store, bundle, answer, received_at))


async def load_baseline(store, bundle, asset_id: str | None) -> BaselineFor | None:
    """The baseline of the asset a request names (None without one), for the worker."""
    if asset_id is None:
        return None
    baseline, commissioning = await anyio.to_thread.run_sync(
        asset_reference, store, bundle, asset_id
    )
    return BaselineFor(asset_id, baseline, commissioning)


async def store_answer(store, bundle, answer, received_at: str) -> bytes:
    """The answer; with an asset, once recorded in its history with the request's rows
    (:func:`~..diagnosing.record_and_encode`)."""
    if answer.asset is None:
        return answer.encoded
    return await anyio.to_thread.run_sync(record_and_encode, store, bundle, answer, received_at)


@router.post(
    "/v1/diagnose/file",
    summary="Diagnose an uploaded MCAP or Parquet recording",
    response_model=None,
    responses={
        200: {
            "model": FileDiagnosis,
            "description": "whole-recording and per-window diagnoses",
        },
        **ERROR_RESPONSES,
        415: {
            "model": Error,
            "description": "not multipart, or not a .mcap/.parquet file",
        },
    },
    openapi_extra=_MULTIPART_BODY,
)
async def post_diagnose_file(
    request: Request, store: Store, limits: Limits, workers: Workers, bundle: Bundle
):
    """Stream the upload into a private temporary directory (removed afterwards), read it
    with the library and diagnose every window."""
    received_at = utc_now()
    boundary = multipart_boundary(request)
    with workers.admitted():
        async with upload_directory() as directory:
            upload = await receive_upload(request, boundary, directory)
            asset_id = upload.fields.get("asset_id")
            healthy = form_healthy(upload.fields.get("healthy"))
            recording_id = upload.fields.get("recording_id")
            hours = form_operating_hours(upload.fields.get("operating_hours"))
            check_asset_fields(asset_id, healthy, recording_id, hours)
            baseline = await load_baseline(store, bundle, asset_id)
            answer = await workers.diagnose(
                diagnose_upload,
                upload.received(),
                limits,
                asset_id,
                received_at,
                baseline,
                healthy,
                recording_id,
                hours,
            )
    return json_response(await store_answer(store, bundle, answer, received_at))


def form_operating_hours(text: str | None) -> float | None:
    """The ``operating_hours`` form field of an upload [h]: a finite number in
    [0, MAX_OPERATING_HOURS]."""
    if text is None:
        return None
    try:
        value = float(text.strip())
    except ValueError:
        value = math.nan
    if not 0.0 <= value <= MAX_OPERATING_HOURS:  # NaN fails too
        raise HTTPError(
            422,
            f"operating_hours = {text[:40]!r}: a number of hours in [0, {MAX_OPERATING_HOURS:g}]",
        )
    return value


def form_healthy(text: str | None) -> bool | None:
    """The ``healthy`` form field of an upload: ``true`` or ``false`` (as a query parameter)."""
    if text is None:
        return None
    value = text.strip().lower()
    if value not in ("true", "false"):
        raise HTTPError(422, f"healthy = {text[:40]!r}: true or false expected")
    return value == "true"
