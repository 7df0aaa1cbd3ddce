"""The outermost ASGI layer: bearer token on every request, then request body size limits."""

from __future__ import annotations

import hmac

from ..errors import PRSMHealthError
from .limits import ServiceLimits
from .responses import BodyTooLarge, encode


def check_token(token: str | None) -> None:
    """A token must be a non-empty string without whitespace (None: no authentication)."""
    if token is not None and (
        not token or token != token.strip() or any(c.isspace() for c in token)
    ):
        raise PRSMHealthError("token must be a non-empty string without whitespace")


def body_limits(limits: ServiceLimits):
    """The largest body [bytes] each path accepts: a function of the request path."""

    def limit_for(path: str) -> int:
        if path == "/v1/diagnose":
            return limits.max_body_bytes
        if path == "/v1/diagnose/file":
            return limits.max_upload_bytes
        return limits.max_small_body_bytes

    return limit_for


class Guard:
    """Outermost ASGI layer: bearer token on every request, then body size limits.

    The token is compared in constant time. The body limit is checked on ``Content-Length``
    before anything is read, and again on the bytes actually received (chunked bodies).
    """

    def __init__(self, app, token: str | None, limit_for):
        self.app = app
        self.token = token.encode() if token else None
        self.limit_for = limit_for

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            if scope["type"] == "websocket" and self.token is not None:
                await send({"type": "websocket.close", "code": 1008})
                return
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers") or [])
        if self.token is not None:
            given = headers.get(b"authorization", b"")
            scheme, _, credentials = given.partition(b" ")
            if scheme.lower() != b"bearer" or not hmac.compare_digest(
                credentials.strip(), self.token
            ):
                message = "missing bearer token" if not given else "invalid bearer token"
                await send_error(
                    send,
                    401,
                    f"{message}: send 'Authorization: Bearer <token>'",
                    [(b"www-authenticate", b'Bearer realm="prsm-health"')],
                )
                return
        limit = self.limit_for(scope["path"])
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
            except ValueError:
                await send_error(send, 400, "invalid Content-Length header")
                return
            if declared > limit:
                await send_error(
                    send,
                    413,
                    f"request body of {declared} bytes is larger than the {limit} bytes this endpoint accepts",
                )
                return
        received = 0

        async def limited_receive():
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise BodyTooLarge(limit)
            return message

        await self.app(scope, limited_receive, send)


async def send_error(send, status: int, message: str, headers=()):
    body = encode({"error": message})
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                *headers,
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})


class GuardMiddleware(Guard):
    """:class:`Guard` with the keyword signature Starlette's ``add_middleware`` uses."""

    def __init__(self, app, *, token: str | None, limits: ServiceLimits):
        super().__init__(app, token, body_limits(limits))
