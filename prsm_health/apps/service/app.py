"""The ASGI application: :func:`create_app` loads the model and the prognostics model, opens
the history store and assembles the routers (:mod:`.routes`), error handlers, OpenAPI document and the guard."""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
from functools import partial
from pathlib import Path

from fastapi import FastAPI
from fastapi.openapi.utils import get_openapi

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.version import __version__
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.monitoring.sqlite_store import HistoryStore, default_db_path

from .diagnosing import warm_up
from .handlers import install_error_handlers
from .limits import ServiceLimits
from .model_info import model_info
from .routes import ROUTERS
from .schemas import ERROR_RESPONSES, document_limits
from .security import GuardMiddleware, check_token
from .workers import WorkerPool

log = logging.getLogger("prsm_health.apps.service")

#: How long a stop waits for a warm-up still running [s] (it takes seconds; a cold numba cache
#: tens of them).
WARMUP_JOIN_TIMEOUT = 120.0
TITLE = "prsm-health diagnostics service"
DESCRIPTION = (
    "Health diagnosis of planetary roller screw mechanisms: clearance estimate with "
    "interval, fault class, condition indicators, and per-asset history. SI units."
)


def create_app(
    model_path: str | os.PathLike | None = None,
    db_path: str | os.PathLike | None = None,
    token: str | None = None,
    limits: ServiceLimits | None = None,
    *,
    bundle=None,
    warmup: bool = True,
    prognostics_model_path: str | os.PathLike | None = None,
    prognostics_model=None,
) -> FastAPI:
    """The ASGI application.

    Parameters
    ----------
    model_path : path or None
        Model bundle (default: the shipped model). Loaded once, here.
    db_path : path or None
        History database (default :func:`default_db_path`, its directory created).
    token : str or None
        Bearer token required on every endpoint; None: no authentication (this function does
        not read ``PRSM_HEALTH_TOKEN``; :func:`serve` does).
    limits : ServiceLimits or None
    bundle : ModelBundle or None
        An already loaded bundle (overrides ``model_path``).
    warmup : bool
        Diagnose a blank recording in the background at start-up, so the first request does
        not pay for one-time compilation and caches.
    prognostics_model_path : path or None
        Prognostics model (:func:`prsm_health.prognostics.save_prognostics_model`) for
        ``GET /v1/assets/{asset_id}/prognosis``, loaded once, here. None: the shipped
        ``models/prognostics.json`` if it exists, else none (that endpoint answers 503).
    prognostics_model : RULModel or None
        An already loaded model (overrides ``prognostics_model_path``).

    Raises
    ------
    PRSMHealthError
        Unreadable model, prognostics model or database, empty token.
    """
    limits = limits or ServiceLimits()
    check_token(token)
    bundle, model_file = _load_model(model_path, bundle)
    prognostics_model = _load_prognostics_model(prognostics_model_path, prognostics_model)
    if prognostics_model is not None and prognostics_model.design != bundle.design_name:
        log.warning(
            "the prognostics model is for design %r, the diagnosis model for %r: every "
            "prognosis will be refused (422)",
            prognostics_model.design,
            bundle.design_name,
        )
    store = _open_store(db_path)
    app = FastAPI(
        title=TITLE,
        version=__version__,
        description=DESCRIPTION,
        docs_url=None,
        redoc_url=None,
        lifespan=partial(_lifespan, warmup=warmup),
        responses={401: ERROR_RESPONSES[401]},
    )
    app.state.bundle = bundle
    app.state.prognostics = prognostics_model
    app.state.store = store
    app.state.limits = limits
    app.state.token = token  # the dashboard's login form compares against it
    app.state.workers = WorkerPool(limits, bundle)
    app.state.model_info = model_info(bundle, model_file)
    app.state.started = time.monotonic()
    app.state.warm = not warmup
    for router in ROUTERS:
        app.include_router(router)
    install_error_handlers(app)
    app.openapi = partial(_openapi, app, limits, token)
    app.add_middleware(GuardMiddleware, token=token, limits=limits)
    return app


def _load_model(model_path, bundle):
    """The bundle, and the file it came from when known (its metrics may lie beside it)."""
    if model_path is not None:
        model_file = Path(model_path)
    elif bundle is None:
        from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL

        model_file = DEFAULT_MODEL
    else:
        model_file = None  # a bundle handed in without its path: no metrics file to look up
    if bundle is None:
        bundle = load_bundle(model_path)
    return bundle, model_file


def _load_prognostics_model(path, model):
    """The prognostics model: ``model`` if given, else the file at ``path``, else the shipped
    one if it exists, else None (logged)."""
    from prsm_health import prognostics

    if model is None:
        if path is None:
            path = prognostics.DEFAULT_PROGNOSTICS_MODEL
            if not Path(path).is_file():
                log.warning(
                    "no prognostics model (%s not found): GET /v1/assets/{asset_id}/prognosis "
                    "answers 503; give one with --prognostics-model",
                    path,
                )
                return None
        model = prognostics.load_prognostics_model(path)
        what = str(path)
    else:
        what = "the prognostics model given"
    if not isinstance(model, prognostics.RULModel) or not hasattr(model, "form_"):
        raise PRSMHealthError(f"{what}: not a fitted prognostics model")
    return model


def _open_store(db_path) -> HistoryStore:
    if db_path is None:
        db_path = default_db_path()
        if str(db_path) != ":memory:":
            Path(db_path).parent.mkdir(parents=True, exist_ok=True)
    return HistoryStore(db_path)


@contextlib.asynccontextmanager
async def _lifespan(app: FastAPI, *, warmup: bool):
    warming = threading.Thread(target=_warm, args=(app,), name="prsm-health-warmup", daemon=True)
    if warmup:
        warming.start()
    try:
        yield
    finally:
        # A stop during the warm-up waits for it: it may still be starting the diagnosis
        # processes that close() stops, and a daemon thread inside numba's compiler or holding
        # stderr at interpreter exit aborts the process (a -6 exit seen under load).
        if warming.is_alive():
            warming.join(timeout=WARMUP_JOIN_TIMEOUT)
        app.state.workers.close()
        app.state.store.close()


def _warm(app: FastAPI) -> None:
    try:
        warm_up(app.state.bundle)
        app.state.workers.start()  # diagnosis processes, if any, load and warm their model
    except Exception:  # warm-up is an optimisation; a failure shows on the first request
        log.warning("warm-up diagnosis failed", exc_info=True)
    finally:
        app.state.warm = True


def _openapi(app: FastAPI, limits: ServiceLimits, token: str | None) -> dict:
    # FastAPI documents the routes; the JSON request body (validated in a worker thread, not
    # by FastAPI on the event loop) and the bounds set by the limits are added.
    if app.openapi_schema:
        return app.openapi_schema
    schema = get_openapi(
        title=app.title, version=app.version, description=app.description, routes=app.routes
    )
    document_limits(schema, limits)
    if token is not None:
        schema["components"]["securitySchemes"] = {
            "bearerAuth": {"type": "http", "scheme": "bearer"}
        }
        schema["security"] = [{"bearerAuth": []}]
    app.openapi_schema = schema
    return schema
