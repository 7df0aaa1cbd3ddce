"""The dashboard's HTML: page shells rendered from the templates in ``templates/`` (every
value inserted is HTML-escaped here), the security headers of every page, and the static
files (``static/``) served under ``/static/``.

The pages hold no data: their scripts (static files, no inline script) read the JSON API and
insert what they read as text (``textContent``), never as HTML.
"""

from __future__ import annotations

import hashlib
import html
import re
from functools import cache, lru_cache
from pathlib import Path
from string import Template

from fastapi.responses import Response

from .schemas import ASSET_ID_PATTERN

HERE = Path(__file__).resolve().parent
TEMPLATES = HERE / "templates"
STATIC = HERE / "static"

#: Content-Security-Policy of every page: scripts, styles and requests to this origin only
#: (no inline script or style, no eval), no frames, forms posting here only.
CSP = (
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
    "connect-src 'self'; form-action 'self'; base-uri 'none'; frame-ancestors 'none'"
)
PAGE_HEADERS = {
    "content-security-policy": CSP,
    "x-content-type-options": "nosniff",
    "x-frame-options": "DENY",
    "referrer-policy": "no-referrer",
    "cache-control": "no-store",
}
_ASSET_PAGE = re.compile(r"/assets/" + ASSET_ID_PATTERN.strip("^$") + r"\Z")
#: Static files by suffix → content type (anything else is not served).
CONTENT_TYPES = {
    ".js": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
    ".json": "application/json",
    "": "text/plain; charset=utf-8",  # LICENSE
}


def is_page(path: str) -> bool:
    """Whether ``path`` is a dashboard page (``/``, ``/upload``, ``/assets/{asset_id}``)."""
    return path in ("/", "/upload") or bool(_ASSET_PAGE.match(path))


def safe_next(path: str | None) -> str:
    """Where the login form may send the browser afterwards: a dashboard page, else ``/``
    (never another site)."""
    return path if path and is_page(path) else "/"


@cache
def _template(name: str) -> Template:
    return Template((TEMPLATES / name).read_text(encoding="utf-8"))


def render(name: str, **values: str) -> str:
    """The template ``name`` with ``values`` HTML-escaped into its ``$placeholders``."""
    return _template(name).substitute({k: html.escape(v, quote=True) for k, v in values.items()})


def html_response(text: str, status: int = 200, headers: dict | None = None) -> Response:
    return Response(
        text.encode(),
        status_code=status,
        media_type="text/html; charset=utf-8",
        headers={**PAGE_HEADERS, **(headers or {})},
    )


def page(
    title: str, content: str, script: str, *, asset_id: str = "", logout: bool = False
) -> Response:
    """A dashboard page: the layout around ``content`` (already rendered), its script
    (a file of ``static/dashboard/``) and the asset it shows (``data-asset-id``)."""
    layout = _template("layout.html").substitute(
        title=html.escape(title),
        asset_id=html.escape(asset_id, quote=True),
        script=html.escape(script, quote=True),
        content=content,  # rendered by render(): its values are escaped
        logout=_template("logout.html").template if logout else "",
    )
    return html_response(layout)


def login_page(next_path: str = "/", message: str = "", status: int = 200) -> Response:
    """The login form (no script, no stylesheet: it is served without a token)."""
    notice = f'<p class="error" role="alert">{html.escape(message)}</p>' if message else ""
    text = _template("login.html").substitute(
        next=html.escape(safe_next(next_path), quote=True), message=notice
    )
    return html_response(text, status)


@lru_cache(maxsize=1)
def static_files() -> dict[str, tuple[bytes, str, str]]:
    """Every file under ``static/``: URL path below ``/static/`` → (content, content type,
    ETag). Read once; only these paths are served (no path is ever built from a request)."""
    files = {}
    for path in sorted(STATIC.rglob("*")):
        ctype = CONTENT_TYPES.get(path.suffix)
        if path.is_file() and ctype is not None:
            data = path.read_bytes()
            etag = '"' + hashlib.sha256(data).hexdigest()[:32] + '"'
            files[path.relative_to(STATIC).as_posix()] = (data, ctype, etag)
    return files
