"""The dashboard (docs/service.md, Dashboard): page shells at ``/``, ``/assets/{asset_id}``
and ``/upload`` whose scripts read the JSON API, their static files under ``/static/``, and
the login form that turns the token into a session cookie. Not in the OpenAPI document."""

from typing import Annotated
from urllib.parse import parse_qs

from fastapi import APIRouter, Request
from fastapi import Path as PathParam
from fastapi.responses import RedirectResponse, Response

from ..pages import PAGE_HEADERS, login_page, page, render, safe_next, static_files
from ..responses import HTTPError
from ..schemas import ASSET_ID_PATTERN
from ..security import SESSION_COOKIE, session_value, token_matches

router = APIRouter(include_in_schema=False)


def _token(request: Request) -> str | None:
    return request.app.state.token


@router.get("/")
async def fleet_page(request: Request):
    return page("Fleet", render("fleet.html"), "fleet.js", logout=_token(request) is not None)


@router.get("/assets/{asset_id}")
async def asset_page(
    request: Request, asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)]
):
    # the page shell is served for any well-formed id: its script reports an unknown asset
    return page(
        f"Asset {asset_id}",
        render("asset.html", asset_id=asset_id),
        "asset.js",
        asset_id=asset_id,
        logout=_token(request) is not None,
    )


@router.get("/upload")
async def upload_page(request: Request):
    window = f"{request.app.state.limits.max_window_seconds:g}"
    return page(
        "Diagnose a recording",
        render("upload.html", max_window=window),
        "upload.js",
        logout=_token(request) is not None,
    )


@router.get("/static/{path:path}")
async def static_file(request: Request, path: str):
    found = static_files().get(path)
    if found is None:
        raise HTTPError(404, f"no such file: /static/{path[:200]}")
    data, ctype, etag = found
    headers = {
        "etag": etag,
        "cache-control": "no-cache",
        "x-content-type-options": "nosniff",
    }
    if request.headers.get("if-none-match") == etag:
        return Response(status_code=304, headers=headers)
    return Response(data, media_type=ctype, headers=headers)


@router.get("/login")
async def login_form(request: Request, next: str = "/"):
    if _token(request) is None:  # nothing to log in to
        return RedirectResponse(safe_next(next), 303)
    return login_page(next)


@router.post("/login")
async def login(request: Request):
    """The token from the form (``application/x-www-form-urlencoded``: ``token``, ``next``),
    compared in constant time; right: the session cookie and a redirect to ``next``."""
    token = _token(request)
    try:
        form = parse_qs((await request.body()).decode("utf-8", "replace"), max_num_fields=8)
    except ValueError:  # more fields than a login form has
        return login_page("/", "Malformed login form.", status=400)
    target = safe_next((form.get("next") or ["/"])[0])
    if token is None:
        return RedirectResponse(target, 303)
    given = (form.get("token") or [""])[0].strip()
    if not token_matches(given, token):
        return login_page(target, "Wrong token.", status=401)
    response = RedirectResponse(target, 303, headers=PAGE_HEADERS)
    response.set_cookie(
        SESSION_COOKIE,
        session_value(token),
        httponly=True,
        samesite="strict",
        secure=request.url.scheme == "https",
        path="/",
    )
    return response


@router.post("/logout")
async def logout(request: Request):
    response = RedirectResponse("/login" if _token(request) else "/", 303, headers=PAGE_HEADERS)
    response.delete_cookie(SESSION_COOKIE, path="/", httponly=True, samesite="strict")
    return response
