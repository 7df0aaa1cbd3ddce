"""Reading the package's TOML files (designs, scenarios, recipes, instrumentation profiles) with
one set of errors, and writing TOML values."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from .errors import PRSMHealthError, a_or_an

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
        raise error(f"{path}: is a directory, not {a_or_an(what)}") from None
    except UnicodeDecodeError:
        raise error(f"{path}: not a text file (expected {a_or_an(what)} in TOML)") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML ({exc})") from None


def toml_value(value) -> str:
    """TOML text of a value written by the package (bool, str, number, or a list of them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a JSON string is a valid TOML basic string
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"no TOML form for {value!r}")
