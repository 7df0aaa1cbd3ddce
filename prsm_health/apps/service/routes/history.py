"""``GET /v1/assets/{asset_id}/history``."""

from dataclasses import dataclass
from typing import Annotated

import anyio
from fastapi import APIRouter, Depends, Query, Request
from fastapi import Path as PathParam
from fastapi.exceptions import RequestValidationError

from prsm_health.monitoring.sqlite_store import parse_time

from ..responses import HTTPError, encode, json_response
from ..schemas import ASSET_ID_PATTERN, ERROR_RESPONSES, Error, History
from .deps import Limits, Store

router = APIRouter()


@dataclass(frozen=True)
class HistoryQuery:
    limit: int
    since: str | None


async def history_query(
    request: Request,
    limits: Limits,
    limit: Annotated[int, Query(ge=1, description="most recent N")] = 100,
    since: Annotated[
        str | None,
        Query(
            max_length=64,
            description="ISO-8601 time, inclusive; without zone: UTC",
            json_schema_extra={"format": "date-time"},
        ),
    ] = None,
) -> HistoryQuery:
    """The query, parsed before the store is touched (:func:`bounded_limit`)."""
    limit = bounded_limit(request, limits, limit)
    if since is not None:
        parse_time(since)
    return HistoryQuery(limit, since)


def bounded_limit(request: Request, limits, limit: int) -> int:
    """A ``limit`` query parameter given above the service's ``max_history`` gets the answer a
    ``Query(le=max_history)`` bound would give (the OpenAPI document shows that bound); the
    default is at most ``max_history``."""
    if "limit" not in request.query_params:
        return min(limit, limits.max_history)
    if limit > limits.max_history:
        raise RequestValidationError(
            [
                {
                    "type": "less_than_equal",
                    "loc": ("query", "limit"),
                    "msg": f"Input should be less than or equal to {limits.max_history}",
                    "input": limit,
                    "ctx": {"le": limits.max_history},
                }
            ]
        )
    return limit


@router.get(
    "/v1/assets/{asset_id}/history",
    summary="Stored diagnoses of an asset, oldest first",
    response_model=None,
    responses={
        200: {"model": History},
        404: {"model": Error, "description": "no diagnosis stored for this asset"},
        422: ERROR_RESPONSES[422],
    },
)
async def get_history(
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    query: Annotated[HistoryQuery, Depends(history_query)],
    store: Store,
):
    """The most recent `limit` diagnoses at or after `since`, returned oldest first."""

    def read():
        if not store.has_asset(asset_id):
            raise HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
        return encode(store.history(asset_id, since=query.since, limit=query.limit))

    return json_response(await anyio.to_thread.run_sync(read))
