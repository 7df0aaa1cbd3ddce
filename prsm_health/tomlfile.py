"""Reading the package's TOML files (designs, scenarios, recipes) with one set of errors."""

from __future__ import annotations

import sys
from pathlib import Path

from .errors import PRSMHealthError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def read_toml(path: str | Path, what: str, error: type[PRSMHealthError] = PRSMHealthError) -> dict:
    """The tables of a TOML file; a missing, unreadable or invalid file raises ``error`` naming
    the file and ``what`` it should have been (e.g. "design file")."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a {what}") from None
    except UnicodeDecodeError:
        raise error(f"{path}: not a text file (expected a {what} in TOML)") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML ({exc})") from None
