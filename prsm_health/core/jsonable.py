"""Plain JSON out of the library's values: one conversion for the CLI, files, MCAP and the service.

numpy arrays and scalars become lists and Python numbers, paths strings, and non-finite floats
``null`` (JSON has no NaN or infinity).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np


def json_ready(value):
    """``value`` with every nested numpy/Path/non-finite item made plain JSON."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def as_finite(value) -> float | None:
    """``value`` as a finite float, or None (missing, None, a bool, NaN, ±inf, not a number):
    the lenient reading of a number that came through a table or a JSON file."""
    if value is None or isinstance(value, bool):
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def finite_or_none(value) -> float | None:
    """A finite float, or None for None/NaN/±inf."""
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def dumps(value, *, indent: int | None = None, compact: bool = False) -> str:
    """``json.dumps`` of :func:`json_ready` (strict: no NaN)."""
    separators = (",", ":") if compact else None
    return json.dumps(json_ready(value), indent=indent, separators=separators, allow_nan=False)
