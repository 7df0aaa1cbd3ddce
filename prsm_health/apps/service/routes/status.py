"""``GET /v1/health`` and ``GET /v1/model``: answered on the event loop, without touching the
model or the database."""

import time

from fastapi import APIRouter, Request

from ..responses import json_response
from ..schemas import Health, ModelInfo
from .deps import Bundle, Workers

router = APIRouter()


@router.get(
    "/v1/health",
    summary="Liveness and model identity",
    response_model=None,
    responses={200: {"model": Health}},
)
async def get_health(request: Request, bundle: Bundle, workers: Workers):
    state = request.app.state
    return json_response(
        {
            "status": "ok",
            "model": bundle.name,
            "version": bundle.version,
            "uptime_s": round(time.monotonic() - state.started, 3),
            "warm": state.warm,
            "active_diagnoses": workers.active,
        }
    )


@router.get(
    "/v1/model",
    summary="Model metadata",
    response_model=None,
    responses={200: {"model": ModelInfo}},
)
async def get_model(request: Request):
    return json_response(request.app.state.model_info)
