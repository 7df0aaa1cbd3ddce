"""FastAPI dependencies: what a route needs from the app it runs in (set by ``create_app``)."""

from typing import Annotated

from fastapi import Depends, Request

from prsm_health.diagnostics.diagnosis import ModelBundle
from prsm_health.monitoring.sqlite_store import HistoryStore
from prsm_health.prognostics import RULModel as _PrognosticsModel

from ..limits import ServiceLimits
from ..workers import WorkerPool

# async: FastAPI would run plain functions in its thread pool.


async def get_bundle(request: Request) -> ModelBundle:
    return request.app.state.bundle


async def get_store(request: Request) -> HistoryStore:
    return request.app.state.store


async def get_prognostics(request: Request) -> _PrognosticsModel | None:
    return request.app.state.prognostics


async def get_limits(request: Request) -> ServiceLimits:
    return request.app.state.limits


async def get_workers(request: Request) -> WorkerPool:
    return request.app.state.workers


#: The loaded model bundle.
Bundle = Annotated[ModelBundle, Depends(get_bundle)]
#: The history database.
Store = Annotated[HistoryStore, Depends(get_store)]
#: The prognostics model (None: none loaded).
RULModel = Annotated[_PrognosticsModel | None, Depends(get_prognostics)]
#: The service's limits.
Limits = Annotated[ServiceLimits, Depends(get_limits)]
#: The worker pool diagnoses run in (and the admission counter).
Workers = Annotated[WorkerPool, Depends(get_workers)]
