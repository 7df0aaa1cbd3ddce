"""The outermost ASGI layer: the token on every request (a bearer header, or the dashboard's
session cookie), then request body size limits.

Browsers cannot put a bearer header on a page navigation, so the dashboard's ``/login`` form
takes the token once and sets :data:`SESSION_COOKIE` (HttpOnly, SameSite=Strict), whose value
is an HMAC of the token (:func:`session_value`): it stands for the token without being it, and
changes when the token does. A request is let in with either; a state-changing request let in
by the cookie alone must come from the service's own pages (its ``Origin`` the request's
``Host``), as the cookie is sent by other pages of the same site (another port of the same
host) too.
"""

from __future__ import annotations

import hashlib
import hmac
from urllib.parse import urlsplit

from prsm_health.core.errors import PRSMHealthError

from .limits import ServiceLimits
from .pages import is_page, login_page
from .responses import BodyTooLarge, encode

#: Name of the dashboard's session cookie.
SESSION_COOKIE = "prsm_health_session"
#: Paths answered without a token: the login form and logging out.
PUBLIC_PATHS = ("/login", "/logout")
_SAFE_METHODS = (b"GET", b"HEAD", b"OPTIONS")


def session_value(token: str) -> str:
    """The session cookie's value for ``token``: HMAC-SHA256 of a fixed label keyed by the
    token (hex), so the cookie is not the token itself and a new token invalidates it."""
    return hmac.new(token.encode(), b"prsm-health dashboard session v1", hashlib.sha256).hexdigest()


def token_matches(given: str, token: str) -> bool:
    """Constant-time comparison of a token typed into the login form with the service's."""
    return hmac.compare_digest(given.encode(), token.encode())


def cookie_values(header: bytes, name: str) -> list[bytes]:
    """Values of the cookie ``name`` in a ``Cookie`` request header."""
    values = []
    for part in header.split(b";"):
        key, sep, value = part.strip().partition(b"=")
        if sep and key.decode("latin-1") == name:
            values.append(value.strip().strip(b'"'))
    return values


def same_origin(headers: dict) -> bool:
    """Whether a browser request comes from the service's own pages: its ``Origin`` names the
    host and port the request was sent to (``Host``), or, without ``Origin``,
    ``Sec-Fetch-Site`` is ``same-origin`` or ``none`` (typed by the user). A request with
    neither header does not come from a browser page and is let through."""
    origin = headers.get(b"origin")
    if origin is not None:
        if origin == b"null":
            return False
        try:
            netloc = urlsplit(origin.decode("latin-1")).netloc
        except ValueError:
            return False
        return netloc.lower() == headers.get(b"host", b"").decode("latin-1").lower()
    site = headers.get(b"sec-fetch-site")
    return site is None or site in (b"same-origin", b"none")


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
    """Outermost ASGI layer: the token on every request, then body size limits.

    With a token, every path but :data:`PUBLIC_PATHS` needs ``Authorization: Bearer <token>``
    or the session cookie (:func:`session_value`), both compared in constant time; without
    either, ``401`` — the login form for a dashboard page (``GET``/``HEAD``), a JSON error
    otherwise; a state-changing request carrying only the cookie from another origin is
    ``403`` (:func:`same_origin`). The body limit is checked on ``Content-Length`` before
    anything is read, and again on the bytes actually received (chunked bodies).
    """

    def __init__(self, app, token: str | None, limit_for):
        self.app = app
        self.token = token.encode() if token else None
        self.session = session_value(token).encode() if token else None
        self.limit_for = limit_for

    def _cookie_ok(self, headers: dict) -> bool:
        found = False
        for value in cookie_values(headers.get(b"cookie", b""), SESSION_COOKIE):
            found |= hmac.compare_digest(value, self.session)
        return found

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            if scope["type"] == "websocket" and self.token is not None:
                await send({"type": "websocket.close", "code": 1008})
                return
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers") or [])
        if self.token is not None and scope["path"] not in PUBLIC_PATHS:
            given = headers.get(b"authorization", b"")
            scheme, _, credentials = given.partition(b" ")
            bearer = scheme.lower() == b"bearer" and hmac.compare_digest(
                credentials.strip(), self.token
            )
            if not bearer and not self._cookie_ok(headers):
                challenge = [(b"www-authenticate", b'Bearer realm="prsm-health"')]
                method = scope.get("method", "GET")
                if method in ("GET", "HEAD") and is_page(scope["path"]):
                    await _send_response(send, login_page(scope["path"], status=401), challenge)
                    return
                message = "missing bearer token" if not given else "invalid bearer token"
                await send_error(
                    send,
                    401,
                    f"{message}: send 'Authorization: Bearer <token>' (browsers: log in at /login)",
                    challenge,
                )
                return
            if (
                not bearer
                and scope.get("method", "GET").encode() not in _SAFE_METHODS
                and not same_origin(headers)
            ):
                await send_error(
                    send,
                    403,
                    "cross-origin request refused: the session cookie is accepted from the "
                    "service's own pages only (send 'Authorization: Bearer <token>')",
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


async def _send_response(send, response, extra_headers=()) -> None:
    """A Starlette response sent from the guard (outside the app)."""
    await send(
        {
            "type": "http.response.start",
            "status": response.status_code,
            "headers": [*response.raw_headers, *extra_headers],
        }
    )
    await send({"type": "http.response.body", "body": response.body})


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
