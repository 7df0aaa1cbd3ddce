"""``POST /v1/diagnose`` (JSON body) and ``POST /v1/diagnose/file`` (multipart upload): admit
the request, run the diagnosis in the worker pool, store it in the asset's history."""

import anyio
from fastapi import APIRouter, Request

from ..diagnosing import diagnose_body, diagnose_upload
from ..history import utc_now
from ..responses import HTTPError, json_response
from ..schemas import ASSET_ID_PATTERN, ERROR_RESPONSES, Diagnosis, Error, FileDiagnosis
from ..uploads import multipart_boundary, receive_upload, upload_directory
from .deps import Limits, Store, Workers

router = APIRouter()

_JSON_BODY = {
    "requestBody": {
        "required": True,
        "content": {
            "application/json": {"schema": {"$ref": "#/components/schemas/DiagnoseRequest"}}
        },
    }
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
                            "description": "recording (.mcap or .parquet, by file name)",
                        },
                        "asset_id": {
                            "type": "string",
                            "pattern": ASSET_ID_PATTERN,
                            "description": "store every window in this asset's history",
                        },
                    },
                }
            }
        },
    }
}


def require_json(request: Request) -> None:
    ctype = request.headers.get("content-type", "")
    if ctype.split(";")[0].strip().lower() != "application/json":
        raise HTTPError(415, f"Content-Type must be application/json, not {ctype or 'missing'!r}")


@router.post(
    "/v1/diagnose",
    summary="Diagnose a recording sent as JSON",
    response_model=None,
    responses={
        200: {"model": Diagnosis, "description": "the Diagnosis contract"},
        **ERROR_RESPONSES,
        415: {"model": Error, "description": "not JSON"},
    },
    openapi_extra=_JSON_BODY,
)
async def post_diagnose(request: Request, store: Store, limits: Limits, workers: Workers):
    """Diagnose uniformly sampled contract channels (at most `max_window_seconds`, 2 s by
    default). With `asset_id` the diagnosis is stored in the asset's history."""
    received_at = utc_now()
    require_json(request)
    with workers.admitted():
        body = await request.body()
        req, result, encoded = await workers.diagnose(diagnose_body, body, limits)
    if req.asset_id is not None:
        await anyio.to_thread.run_sync(
            lambda: store.add(
                req.asset_id,
                [result],
                received_at=received_at,
                source="json",
                speed=req.speed,
                load=req.load,
            )
        )
    return json_response(encoded)


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
async def post_diagnose_file(request: Request, store: Store, limits: Limits, workers: Workers):
    """Stream the upload into a private temporary directory (removed afterwards), read it
    with the library and diagnose every window."""
    received_at = utc_now()
    boundary = multipart_boundary(request)
    with workers.admitted():
        async with upload_directory() as directory:
            upload = await receive_upload(request, boundary, directory)
            answer, encoded = await workers.diagnose(diagnose_upload, upload.received(), limits)
    asset_id = upload.fields.get("asset_id")
    if asset_id is not None:
        await anyio.to_thread.run_sync(
            lambda: store.add(
                asset_id,
                answer["windows"],
                received_at=received_at,
                source="file",
                filename=upload.filename,
            )
        )
    return json_response(encoded)
