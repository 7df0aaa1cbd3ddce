"""Prognostics model files: JSON (no pickle), written atomically, version-checked on load."""

from __future__ import annotations

import json
from pathlib import Path

from prsm_health.core.errors import (
    ModelVersionError,
    PRSMHealthError,
    require,
)

from .history import one_line
from .rul import RULModel

#: The shipped prognostics model (fitted on datasets/fleet.toml by tools/release/train_prognostics_model.py).
DEFAULT_PROGNOSTICS_MODEL = Path(__file__).resolve().parents[2] / "models" / "prognostics.json"


def save_prognostics_model(path, model: RULModel) -> Path:
    """Write a fitted model as a JSON file (atomically: temporary file, then rename).

    Parameters
    ----------
    path : str or Path
        Destination (conventionally ``*.json``); replaced if it exists.
    model : RULModel
        A fitted model.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        Not a fitted :class:`RULModel`.
    PRSMHealthError
        An unwritable path.
    """
    path = Path(path)
    require(
        isinstance(model, RULModel) and model._is_fitted(),
        "model",
        type(model).__name__,
        "must be a fitted RULModel",
    )
    from prsm_health.core.atomic import write_atomic

    text = json.dumps(model.to_dict(), indent=1, allow_nan=False)
    write_atomic(path, text.encode("utf-8"), "prognostics model")
    return path


def load_prognostics_model(path=None) -> RULModel:
    """Read a model written by :func:`save_prognostics_model` (default: the shipped one,
    :data:`DEFAULT_PROGNOSTICS_MODEL`).

    Raises
    ------
    PRSMHealthError
        A missing, unreadable, non-JSON or malformed file (one line naming the file).
    ModelVersionError
        A file of another format version.
    """
    path = DEFAULT_PROGNOSTICS_MODEL if path is None else path
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PRSMHealthError(f"{path}: cannot read prognostics model (no such file)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise PRSMHealthError(f"{path}: cannot read prognostics model ({one_line(err)})") from None
    try:
        d = json.loads(text)
    except ValueError as err:
        raise PRSMHealthError(f"{path}: not a prognostics model (invalid JSON: {err})") from None
    try:
        return RULModel.from_dict(d)
    except ModelVersionError as err:
        raise ModelVersionError(f"{path}: {err}") from None
    except PRSMHealthError as err:
        raise PRSMHealthError(f"{path}: {err}") from None
