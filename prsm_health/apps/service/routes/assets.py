"""``GET /v1/assets`` (the stored assets, each with its latest diagnosis in brief, baseline
and evidence), ``GET /v1/assets/{asset_id}`` (one of them), ``GET
/v1/assets/{asset_id}/evidence`` (its state after each of its recordings) and ``GET
/v1/assets/{asset_id}/spectra`` (the spectra of its latest window): what the dashboard's
pages read; ``PUT /v1/assets/{asset_id}/commissioning`` (its as-built clearance)."""

from typing import Annotated

import anyio
from fastapi import APIRouter, Query, Request
from fastapi import Path as PathParam

from prsm_health.monitoring import commission
from prsm_health.monitoring.sqlite_store import HistoryStore

from ..responses import HTTPError, encode, json_response
from ..schemas import (
    ASSET_ID_PATTERN,
    AssetList,
    AssetRecordings,
    AssetSummary,
    CommissioningBody,
    Error,
    Spectra,
)
from .deps import Limits, RULModel, Store
from .history import bounded_limit
from .prognosis import asset_prognosis

router = APIRouter()

_PROGNOSIS = Query(
    description="add each asset's prognosis in brief (RUL and interval, its headline), or why "
    "there is none (a prognosis per asset: slower for many assets)"
)


def prognosis_brief(store: HistoryStore, model, asset_id: str) -> dict:
    """The asset's prognosis in brief (default method), or the error the prognosis endpoint
    would answer, with its status."""
    try:
        p = asset_prognosis(store, model, asset_id)
    except HTTPError as exc:
        return {"error": exc.message, "status": exc.status}
    return {
        "rul_hours": p["rul_hours"],
        "headline": p["headline"],
        "method": p["model"]["name"],
        "threshold": p["health_indicator"]["threshold"],
        "current": p["health_indicator"]["current"],
        "warnings": p["warnings"],
    }


@router.get(
    "/v1/assets",
    summary="Stored assets, most recently seen first, with their latest diagnosis",
    response_model=None,
    responses={200: {"model": AssetList}, 422: {"model": Error, "description": "bad query"}},
)
async def get_assets(
    request: Request,
    store: Store,
    limits: Limits,
    model: RULModel,
    limit: Annotated[int, Query(ge=1, description="the N most recently seen assets")] = 100,
    prognosis: Annotated[bool, _PROGNOSIS] = False,
):
    """The `limit` most recently seen assets (`total` counts them all): number of diagnoses,
    first and last receive time, the latest diagnosis in brief, whether spectra are stored."""
    limit = bounded_limit(request, limits, limit)

    def read() -> bytes:
        page = store.assets(limit=limit)
        if prognosis:
            for summary in page["assets"]:
                summary["prognosis"] = prognosis_brief(store, model, summary["asset_id"])
        return encode(page)

    return json_response(await anyio.to_thread.run_sync(read))


@router.get(
    "/v1/assets/{asset_id}",
    summary="One asset with its latest diagnosis",
    response_model=None,
    responses={
        200: {"model": AssetSummary},
        404: {"model": Error, "description": "no diagnosis stored for this asset"},
        422: {"model": Error, "description": "bad asset id or query"},
    },
)
async def get_asset(
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    store: Store,
    model: RULModel,
    prognosis: Annotated[bool, _PROGNOSIS] = False,
):
    """What `GET /v1/assets` lists for this asset: its diagnoses, the latest in brief, its
    baseline (recordings in it, recordings needed, which) and its evidence after its latest
    recording (class posterior, named class, change statistic and alarm)."""

    def read() -> bytes:
        summary = store.asset_summary(asset_id)
        if summary is None:
            raise HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
        if prognosis:
            summary["prognosis"] = prognosis_brief(store, model, asset_id)
        return encode(summary)

    return json_response(await anyio.to_thread.run_sync(read))


@router.put(
    "/v1/assets/{asset_id}/commissioning",
    summary="Commission an asset: its clearance as built",
    response_model=None,
    responses={
        200: {"model": CommissioningBody},
        422: {"model": Error, "description": "bad asset id or clearance"},
    },
)
async def put_commissioning(
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    body: CommissioningBody,
    store: Store,
):
    """Give the asset its thread half-clearance as built (given again: replaced). Its
    baseline health checks then fix its own compliance chain: the clearance of each later
    check is measured against it (`measured_clearance.commissioned` true)."""
    await anyio.to_thread.run_sync(commission, store, asset_id, body.as_built_clearance)
    return json_response(encode({"as_built_clearance": body.as_built_clearance}))


@router.get(
    "/v1/assets/{asset_id}/evidence",
    summary="An asset's baseline distance and accumulated evidence after each recording",
    response_model=None,
    responses={
        200: {"model": AssetRecordings},
        404: {"model": Error, "description": "no diagnosis stored for this asset"},
        422: {"model": Error, "description": "bad asset id or query"},
    },
)
async def get_evidence(
    request: Request,
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    store: Store,
    limits: Limits,
    limit: Annotated[int, Query(ge=1, description="the N most recent recordings")] = 100,
):
    """The asset's state after each of its `limit` most recent recordings, in the order they
    were recorded: whether the recording is in the asset's baseline, its distance from the
    baseline, its own class probabilities, and the asset's accumulated class posterior, named
    class and change statistic (CUSUM of the distance) after it. Empty for an asset whose
    diagnoses were all stored before the service kept baselines."""
    limit = bounded_limit(request, limits, limit)

    def read() -> bytes:
        if not store.has_asset(asset_id):
            raise HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
        return encode(store.recordings(asset_id, limit=limit))

    return json_response(await anyio.to_thread.run_sync(read))


@router.get(
    "/v1/assets/{asset_id}/spectra",
    summary="Spectra of the latest window of an asset's latest recording",
    response_model=None,
    responses={
        200: {"model": Spectra},
        404: {
            "model": Error,
            "description": "no spectra stored for this asset (no recording with a nut axial "
            "acceleration sent with its asset id)",
        },
        422: {"model": Error, "description": "bad asset id"},
    },
)
async def get_spectra(
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    store: Store,
):
    """The nut axial acceleration's amplitude and envelope spectra of the last window of the
    asset's latest recording that had one (`POST /v1/diagnose` or `/v1/diagnose/file` with
    its asset id), with the defect frequencies at that window's mean screw speed."""

    def read() -> bytes:
        spectra = store.spectra(asset_id)
        if spectra is None:
            if store.has_asset(asset_id):
                raise HTTPError(
                    404,
                    f"no spectra stored for asset {asset_id!r}: none of its recordings "
                    "diagnosed since the service stores spectra had the nut_axial_accel channel",
                )
            raise HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
        return encode(spectra)

    return json_response(await anyio.to_thread.run_sync(read))
