"""Input checks shared by the thread-stiffness modules (:mod:`.thread`)."""

from __future__ import annotations

import numpy as np

from prsm_health.core.errors import ParameterError, require

#: Engagement sides of one roller.
SIDES = ("screw", "nut")
#: Ways of combining the engaged threads of one roller (:mod:`.thread_load`).
COMBINATIONS = ("distributed", "uniform", "paper01_series")


def _check_side(side) -> None:
    require(side in SIDES, "side", side, "must be 'screw' or 'nut'")


def _check_combination(combination) -> None:
    require(
        combination in COMBINATIONS,
        "combination",
        combination,
        f"must be one of {', '.join(COMBINATIONS)}",
    )


def _as_array(name: str, value, *, nonnegative: bool = True) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number or an array of numbers") from None
    require(bool(np.all(np.isfinite(arr))), name, value, "must be finite")
    if nonnegative:
        require(bool(np.all(arr >= 0.0)), name, value, "must be ≥ 0")
    return arr


def _fmt_values(values, limit: int = 5) -> str:
    """A short text of the values an error message names (at most ``limit`` of them)."""
    flat = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    text = ", ".join(f"{v:.6g}" for v in flat[:limit])
    if flat.size > limit:
        text += f", … ({flat.size} values)"
    return f"[{text}]" if flat.size > 1 else text
