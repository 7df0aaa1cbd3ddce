"""The entry point: parse, run the command's handler, turn user errors into one line."""

from __future__ import annotations

import importlib
import sys
import warnings

from prsm_health.core.errors import PRSMHealthError

from .options import UsageError
from .parser import build_parser


def _warning_line(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``prsm-health`` console script: the exit status (2: a user error,
    printed as one line ``error: …``)."""
    parser = build_parser()
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _warning_line  # one line per warning, no source excerpt
            args = parser.parse_args(argv)
            # The command's module is imported only now: the parser stays cheap to build.
            module, _, function = args.handler.partition(":")
            handler = getattr(importlib.import_module(f"{__package__}.{module}"), function)
            return handler(args)
    except (UsageError, PRSMHealthError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into head & co.: stop quietly
        sys.stderr.close()
        return 0
