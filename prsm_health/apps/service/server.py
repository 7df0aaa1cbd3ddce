"""Serving the app on uvicorn: :func:`serve`, :func:`serve_in_thread` (a server beside a
script or a test), and the bind rules (loopback unless a token)."""

from __future__ import annotations

import contextlib
import ipaddress
import logging
import os
import signal
import socket
import threading
import time
from collections.abc import Iterator

from prsm_health.core.errors import PRSMHealthError

from .app import create_app
from .limits import ServiceLimits

#: Environment variable holding the bearer token when ``--token`` is not given.
TOKEN_ENV = "PRSM_HEALTH_TOKEN"


def is_loopback(host: str) -> bool:
    """Whether ``host`` (address or name) reaches this machine only."""
    host = host.strip().strip("[]")
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(host, None)
    except OSError:
        return False
    addresses = {info[4][0] for info in infos}
    return bool(addresses) and all(
        ipaddress.ip_address(a.split("%")[0]).is_loopback for a in addresses
    )


def check_bind(host: str, token: str | None) -> None:
    """Refuse to expose the service beyond this machine without a token."""
    if not is_loopback(host) and not token:
        raise PRSMHealthError(
            f"refusing to bind {host}: a non-loopback address requires a bearer token "
            f"(--token or the {TOKEN_ENV} environment variable); bind 127.0.0.1 to serve "
            "this machine only"
        )


def serve(
    host: str = "127.0.0.1",
    port: int = 8000,
    model_path: str | os.PathLike | None = None,
    db_path: str | os.PathLike | None = None,
    token: str | None = None,
    *,
    limits: ServiceLimits | None = None,
    log_level: str = "info",
    http: str = "auto",
    prognostics_model_path: str | os.PathLike | None = None,
) -> None:
    """Run the service on uvicorn until interrupted.

    Parameters
    ----------
    host : str
        Address to bind; a non-loopback one requires a token.
    port : int
    model_path, db_path : path or None
        Model bundle and history database (see :func:`create_app`).
    token : str or None
        Bearer token; None reads ``PRSM_HEALTH_TOKEN`` (unset or empty: no token).
    limits : ServiceLimits or None
    log_level : str
        uvicorn log level.
    http : str
        HTTP/1.1 parser: ``"auto"`` (``httptools``, a C parser, when it can be imported, else
        ``h11``, pure Python), ``"httptools"`` or ``"h11"``.
    prognostics_model_path : path or None
        Prognostics model of ``GET /v1/assets/{asset_id}/prognosis`` (see :func:`create_app`;
        None: the shipped one if it exists).

    Raises
    ------
    PRSMHealthError
        Non-loopback host without a token, bad port, unreadable model, prognostics model or
        database.
    """
    import uvicorn

    if token is None:
        token = os.environ.get(TOKEN_ENV) or None
    if not (isinstance(port, int) and 0 <= port <= 65535):
        raise PRSMHealthError(f"port = {port!r} must be an integer in [0, 65535]")
    check_bind(host, token)
    http_protocol = http_implementation(http)
    app = create_app(
        model_path, db_path, token, limits, prognostics_model_path=prognostics_model_path
    )
    sock = bind_socket(host, port)
    config = uvicorn.Config(
        app,
        log_level=log_level,
        server_header=False,
        proxy_headers=False,
        timeout_graceful_shutdown=10,
        http=http_protocol,
    )
    logging.getLogger("uvicorn.error").info(
        "prsm-health serving on http://%s:%d (HTTP parser %s): model %s v%s, prognostics "
        "model %s, history %s, bearer token %s",
        f"[{host.strip('[]')}]" if ":" in host else host,
        sock.getsockname()[1],
        http_protocol,
        app.state.bundle.name,
        app.state.bundle.version,
        _prognostics_text(app.state.prognostics),
        app.state.store.path,
        "required" if token else "not required (loopback only)",
    )
    try:
        _server_class()(config).run(sockets=[sock])
    finally:
        sock.close()


@contextlib.contextmanager
def serve_in_thread(app, *, log_level: str = "warning", timeout: float = 60.0) -> Iterator[str]:
    """Serve ``app`` on uvicorn in a background thread on a free port of 127.0.0.1.

    For scripts and tests that need a real server beside them (the dashboard's screenshots,
    end-to-end tests); :func:`serve` is the command line's blocking form. Loopback only, so no
    token is required whatever the app's.

    Parameters
    ----------
    app : FastAPI
        From :func:`create_app`.
    log_level : str
        uvicorn log level.
    timeout : float [s]
        How long to wait for the server to start.

    Yields
    ------
    str
        The server's URL, ``http://127.0.0.1:<port>``, once it accepts connections; on exit
        the server shuts down gracefully and the socket is closed.

    Raises
    ------
    PRSMHealthError
        The server did not start within ``timeout`` (e.g. the app's startup failed).
    """
    import uvicorn

    # bound before the thread starts: the port is known, and free, before the server runs
    sock = bind_socket("127.0.0.1", 0)
    server = _server_class()(uvicorn.Config(app, log_level=log_level, lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + timeout
        while not server.started:
            if not thread.is_alive() or time.monotonic() > deadline:
                raise PRSMHealthError(
                    f"the service did not start within {timeout:g} s (see its log above)"
                )
            time.sleep(0.02)
        yield f"http://127.0.0.1:{sock.getsockname()[1]}"
    finally:
        server.should_exit = True
        thread.join(timeout=30)
        sock.close()


def _prognostics_text(model) -> str:
    if model is None:
        return "none (prognosis answers 503)"
    return f"for {model.design} ({len(model.units_)} training units)"


def http_implementation(http: str = "auto") -> str:
    """uvicorn's HTTP/1.1 implementation for ``http``: ``"auto"`` is ``"httptools"`` (C
    parser: a 1.6 MB body costs the server process less CPU than with ``h11``) when it can be
    imported, else ``"h11"``; ``"httptools"`` requires it."""
    if http not in ("auto", "httptools", "h11"):
        raise PRSMHealthError(f"http = {http!r}: one of 'auto', 'httptools', 'h11'")
    if http == "h11":
        return http
    try:
        import httptools  # noqa: F401
    except ImportError:
        if http == "httptools":
            raise PRSMHealthError(
                "http = 'httptools': the httptools package is not installed"
            ) from None
        return "h11"
    return "httptools"


def _server_class():
    import uvicorn

    class Server(uvicorn.Server):
        """uvicorn's server without its last step: after a graceful shutdown on Ctrl-C or
        SIGTERM, uvicorn raises the signal again, and asyncio answers with a KeyboardInterrupt
        traceback; a stopped service is a normal end of ``serve``."""

        @contextlib.contextmanager
        def capture_signals(self):
            if threading.current_thread() is not threading.main_thread():
                yield
                return
            handled = (signal.SIGINT, signal.SIGTERM)
            original = {sig: signal.signal(sig, self.handle_exit) for sig in handled}
            try:
                yield
            finally:
                for sig, handler in original.items():
                    signal.signal(sig, handler)

    return Server


def bind_socket(host: str, port: int) -> socket.socket:
    """A listening-ready TCP socket on ``host:port``; a clear error when that fails."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(
            host.strip("[]"), port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )[0]
    except socket.gaierror as exc:
        raise PRSMHealthError(f"--host {host}: cannot resolve ({exc.strerror})") from None
    sock = socket.socket(family, kind, proto)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
    except OSError as exc:
        sock.close()
        raise PRSMHealthError(f"cannot bind {host}:{port} ({exc.strerror or exc})") from None
    sock.set_inheritable(True)
    return sock
