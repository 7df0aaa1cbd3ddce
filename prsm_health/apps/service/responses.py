"""JSON answers: the service's one error type (:class:`HTTPError`) and encoding."""

from __future__ import annotations

from fastapi.responses import Response

from prsm_health.core.jsonable import dumps


class HTTPError(Exception):
    """A 4xx/5xx answer ``{"error": message}`` with ``status``, raised from any layer (route,
    worker thread, multipart callback, ASGI guard)."""

    def __init__(self, status: int, message: str, headers: dict | None = None):
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers

    def __reduce__(self):
        # raised in a diagnosis process, it crosses back to the server by pickling
        return (HTTPError, (self.status, self.message, self.headers))


class BodyTooLarge(HTTPError):
    def __init__(self, limit: int):
        super().__init__(413, f"request body larger than {limit} bytes (limit of this endpoint)")


def encode(value) -> bytes:
    """Compact, strict JSON bytes (numpy values made plain, non-finite floats null)."""
    return dumps(value, compact=True).encode()


def json_response(payload, status: int = 200, headers=None) -> Response:
    """``payload`` (a value, or bytes already encoded) as an ``application/json`` response."""
    body = payload if isinstance(payload, bytes) else encode(payload)
    return Response(body, status_code=status, media_type="application/json", headers=headers)
