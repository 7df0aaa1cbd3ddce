"""The options of ``serve`` (:mod:`.serve`, docs/service.md)."""

from __future__ import annotations

from .options import SHIPPED_MODEL, finite_float


def add_serve_command(command) -> None:
    v = command("serve", "HTTP diagnostics service with asset health history (docs/service.md)")
    v.add_argument("--host", default="127.0.0.1", help="bind address (non-loopback needs a token)")
    v.add_argument("--port", type=int, default=8000, help="TCP port")
    v.add_argument("--model", default=None, default_text=SHIPPED_MODEL, help="model bundle")
    v.add_argument(
        "--prognostics-model",
        default=None,
        metavar="FILE",
        default_text="the shipped models/prognostics.json if present, else that endpoint "
        "answers 503",
        help="prognostics model for GET /v1/assets/{id}/prognosis",
    )
    v.add_argument(
        "--db",
        default=None,
        default_text="$PRSM_HEALTH_DB, else $XDG_DATA_HOME (~/.local/share)/prsm-health/"
        "history.sqlite",
        help="SQLite history database (docs/service.md)",
    )
    v.add_argument("--token", default=None, default_text="$PRSM_HEALTH_TOKEN", help="bearer token")
    v.add_argument(
        "--workers",
        type=int,
        default=None,
        default_text="half the cores, at least 1",
        help="diagnoses computed at once",
    )
    v.add_argument(
        "--processes",
        type=int,
        default=None,
        default_text="0",
        help="diagnosis processes, each with the model loaded once, or 0: threads",
    )
    v.add_argument(
        "--max-window",
        type=finite_float,
        default=None,
        default_text="2.5: the longest built-in health check, rounded up to the half second",
        help="longest recording of POST /v1/diagnose [s]",
    )
    v.add_argument(
        "--log-level",
        default="info",
        choices=("critical", "error", "warning", "info", "debug"),
        help="server log level",
    )
    v.set_defaults(handler="serve:serve")
