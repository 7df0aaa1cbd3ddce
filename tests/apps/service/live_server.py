"""A real uvicorn server on 127.0.0.1 for the service tests (imported by their modules).

The server itself is the package's :func:`prsm_health.apps.service.server.serve_in_thread`
(also used by tools/figures/make_dashboard_screenshots.py); this adds an httpx client and
lets a fixture hang its data on the object.
"""

from __future__ import annotations

import httpx

from prsm_health.apps.service.server import serve_in_thread


class LiveServer:
    """``with LiveServer(app) as live:`` — the app served in a background thread at ``live.url``."""

    def __init__(self, app):
        self._serving = serve_in_thread(app)
        self.url: str | None = None

    def __enter__(self):
        self.url = self._serving.__enter__()
        return self

    def __exit__(self, *exc):
        return self._serving.__exit__(*exc)

    def client(self, **kwargs) -> httpx.Client:
        return httpx.Client(base_url=self.url, timeout=60, **kwargs)
