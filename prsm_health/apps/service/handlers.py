"""Every error becomes a JSON answer ``{"error": "…"}``: 4xx for what the client sent, 500 (and
a logged traceback) for a bug."""

from __future__ import annotations

import json
import logging

from fastapi import FastAPI
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.requests import ClientDisconnect

from prsm_health.core.errors import PRSMHealthError, RecordingTooLongError

from .responses import HTTPError, json_response
from .schemas import format_errors

log = logging.getLogger("prsm_health.apps.service")


async def _on_http_error(request, exc: HTTPError):
    return json_response({"error": exc.message}, exc.status, exc.headers)


async def _on_library_error(request, exc: PRSMHealthError):
    return json_response({"error": str(exc)}, 422)


async def _on_too_long(request, exc: RecordingTooLongError):
    return json_response({"error": str(exc)}, 413)


async def _on_validation(request, exc: RequestValidationError):
    return json_response({"error": format_errors(list(exc.errors()))}, 422)


async def _on_starlette(request, exc: StarletteHTTPException):
    message = exc.detail if isinstance(exc.detail, str) else json.dumps(exc.detail)
    if exc.status_code == 404 and message == "Not Found":
        message = f"no such endpoint: {request.url.path}"
    elif exc.status_code == 405:
        message = f"method {request.method} not allowed on {request.url.path}"
    return json_response({"error": message}, exc.status_code, getattr(exc, "headers", None))


async def _on_disconnect(request, exc: ClientDisconnect):
    return json_response({"error": "client disconnected"}, 400)


async def _on_bug(request, exc: Exception):
    log.error("internal error on %s %s", request.method, request.url.path, exc_info=exc)
    return json_response({"error": "internal server error (logged on the server)"}, 500)


def install_error_handlers(app: FastAPI) -> None:
    """Register the handlers (Starlette picks the most specific class of an exception)."""
    app.add_exception_handler(HTTPError, _on_http_error)
    app.add_exception_handler(PRSMHealthError, _on_library_error)
    app.add_exception_handler(RecordingTooLongError, _on_too_long)
    app.add_exception_handler(RequestValidationError, _on_validation)
    app.add_exception_handler(StarletteHTTPException, _on_starlette)
    app.add_exception_handler(ClientDisconnect, _on_disconnect)
    app.add_exception_handler(Exception, _on_bug)
