"""Exceptions a user can cause.

The CLI and the service turn every :class:`PRSMHealthError` into a one-line message
(``error: …``, exit status 2 / HTTP 4xx); anything else is a bug and keeps its traceback.
"""

from __future__ import annotations


class PRSMHealthError(Exception):
    """Base class of all errors caused by user input."""


class ParameterError(PRSMHealthError, ValueError):
    """A parameter is outside its allowed range.

    The message names the field, the value and the allowed range.
    """

    def __init__(self, field: str, value, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field} = {_fmt(value)} is invalid: {allowed}")


class RecipeError(PRSMHealthError):
    """A dataset recipe that cannot be used (the message names the key)."""


class StorageError(PRSMHealthError):
    """A dataset location that cannot be used: an unknown URL protocol, a storage backend that is
    not installed, an unreachable store, a missing bucket, denied access (the message names the
    location)."""


class SimulationError(PRSMHealthError):
    """The integration cannot proceed (unstable step, non-finite state)."""


class ConvergenceError(PRSMHealthError):
    """An iterative solver (Newton, ODE integration) did not converge for these inputs."""


class RecordingError(PRSMHealthError):
    """A recording that cannot be processed: too short, non-finite samples, bad time axis."""


class RecordingTooLongError(RecordingError):
    """A recording longer than the caller accepts (the service's size limits)."""


class ModelVersionError(PRSMHealthError):
    """A saved model from another, incompatible package or library version."""


class TruncatedRecordingWarning(UserWarning):
    """A recording ended early or was damaged; what preceded the damage was read."""


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return repr(value) if isinstance(value, str) else str(value)


def require(condition: bool, field: str, value, allowed: str) -> None:
    """Raise :class:`ParameterError` unless ``condition`` holds."""
    if not condition:
        raise ParameterError(field, value, allowed)


def require_positive(field: str, value: float) -> None:
    """Require a finite, strictly positive number."""
    require(
        isinstance(value, (int, float)) and value > 0 and value < float("inf"),
        field,
        value,
        "must be a finite number > 0",
    )


def require_range(
    field: str, value: float, low: float, high: float, *, inclusive=True, unit: str = ""
) -> None:
    """Require ``low <= value <= high`` (or strict when ``inclusive`` is False)."""
    ok = isinstance(value, (int, float)) and (
        low <= value <= high if inclusive else low < value < high
    )
    brackets = ("[", "]") if inclusive else ("(", ")")
    suffix = f" {unit}" if unit else ""
    require(ok, field, value, f"must lie in {brackets[0]}{low:g}, {high:g}{brackets[1]}{suffix}")


def require_known_keys(table: str, values: dict, allowed) -> None:
    """Refuse a key of ``values`` not in ``allowed``, naming ``table.key`` and the allowed keys."""
    allowed = list(allowed)
    unknown = sorted(set(values) - set(allowed))
    if unknown:
        raise ParameterError(
            f"{table}.{unknown[0]}",
            values[unknown[0]],
            f"unknown key; allowed: {', '.join(allowed)}",
        )
