"""``prsm-health serve``: the HTTP diagnostics service (docs/service.md)."""

from __future__ import annotations

from prsm_health.apps import service


def serve(args) -> int:
    overrides = {}
    if args.max_window is not None:  # else ServiceLimits' default: the longest built-in check
        overrides["max_window_seconds"] = args.max_window
    if args.workers is not None:  # 0 or negative: ServiceLimits refuses it by name
        overrides["workers"] = args.workers
    if args.processes is not None:
        overrides["processes"] = args.processes
    try:
        # through the package attribute, so a test can stand in for the server
        service.serve(
            args.host,
            args.port,
            args.model,
            args.db,
            args.token,
            limits=service.ServiceLimits(**overrides),
            log_level=args.log_level,
            prognostics_model_path=args.prognostics_model,
        )
    except KeyboardInterrupt:  # Ctrl-C: uvicorn has shut down gracefully and said so
        return 0
    return 0
