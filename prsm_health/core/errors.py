"""Exceptions a user can cause.

The CLI and the service turn every :class:`PRSMHealthError` into a one-line message
(``error: …``, exit status 2 / HTTP 4xx); anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


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

    def __reduce__(self):
        # rebuilt from its fields, so the error survives a process pool (dataset workers)
        return (type(self), (self.field, self.value, self.allowed))


class UnknownKeyError(ParameterError):
    """A key of a table (a TOML file, a recipe, a scenario …) that the table does not have —
    a typo, usually.

    The message names the key and the table, suggests the nearest allowed key, and lists the
    allowed ones: ``unknown key 'sead' in [scenario] (did you mean 'seed'?); allowed: …``. A
    key whose value is itself a table is named as a table, never printed as a dict.

    Attributes
    ----------
    table : str
        The dotted table name (``"scenario"``, ``"design.gear"``).
    key : str
        The unknown key.
    suggestion : str or None
        The nearest allowed key, if one is close enough.
    """

    def __init__(self, table: str, key: str, value, allowed: Iterable[str]):
        allowed = [str(a) for a in allowed]
        self.table = table
        self.key = key
        self.allowed_keys = allowed
        self.suggestion = nearest_key(key, allowed)
        self.field = f"{table}.{key}"
        self.value = value
        self.allowed = f"allowed: {', '.join(allowed)}"
        PRSMHealthError.__init__(self, unknown_key_message(table, key, value, allowed))

    def __reduce__(self):
        return (type(self), (self.table, self.key, self.value, self.allowed_keys))


class MissingKeyError(ParameterError):
    """A table without a key it needs: ``missing key 'seed' in [recipe] (required: …)``."""

    def __init__(self, table: str, key: str, required: Iterable[str]):
        self.table = table
        self.key = key
        self.required = [str(r) for r in required]
        self.field = f"{table}.{key}"
        self.value = None
        self.allowed = f"required: {', '.join(self.required)}"
        PRSMHealthError.__init__(self, f"missing key {key!r} in [{table}] ({self.allowed})")

    def __reduce__(self):
        return (type(self), (self.table, self.key, self.required))


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


def a_or_an(noun: str) -> str:
    """``noun`` with its indefinite article, for messages built from names: "an angle",
    "a length", "an instrumentation profile" (by its first letter: the package's nouns)."""
    return f"{'an' if noun[:1].lower() in 'aeiou' else 'a'} {noun}"


def nearest_key(key: str, allowed: Iterable[str]) -> str | None:
    """The allowed key closest to a mistyped ``key`` (:func:`difflib.get_close_matches`), or
    None when none is close."""
    allowed = [str(a) for a in allowed]
    matches = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
    if not matches:  # a wrong case or separator ("Seed", "n-rollers") is still the same key
        folded = {a.lower().replace("-", "_"): a for a in allowed}
        match = folded.get(str(key).lower().replace("-", "_"))
        matches = [match] if match else []
    return matches[0] if matches else None


def unknown_key_message(table: str, key: str, value, allowed: Iterable[str]) -> str:
    """One line naming an unknown ``key`` of ``[table]``, the nearest allowed key and the
    allowed keys; a key holding a table (a mistyped ``[helth]``) is called a table."""
    allowed = [str(a) for a in allowed]
    what = "table" if isinstance(value, dict) else "key"
    shown = f"[{key}]" if what == "table" else repr(str(key))
    suggestion = nearest_key(key, allowed)
    if suggestion is not None:
        hint = f" (did you mean {f'[{suggestion}]' if what == 'table' else repr(suggestion)}?)"
    elif what == "table" and nearest_key(key, [table.rsplit(".", 1)[-1]]) is not None:
        # [helth] inside a health table: its keys belong to the table itself
        hint = f" (its keys belong directly in [{table}], without a [{key}] header)"
    else:
        hint = ""
    return f"unknown {what} {shown} in [{table}]{hint}; allowed: {', '.join(allowed)}"


def require_known_keys(
    table: str,
    values: dict,
    allowed: Iterable[str],
    *,
    required: Iterable[str] = (),
    error: type[PRSMHealthError] | None = None,
) -> None:
    """Refuse a key of ``values`` not in ``allowed``, then a ``required`` key that is missing.

    Unknown keys are checked first, so that a typo (``sead = 3``) is reported as the typo,
    with the nearest allowed key, rather than as the key it was meant to be being missing.

    Parameters
    ----------
    table : str
        The table's dotted name as the user wrote it (``"scenario"``, ``"design.gear"``).
    values : dict
        The table.
    allowed : iterable of str
        Its allowed keys, in the order to list them.
    required : iterable of str
        Keys that must be present.
    error : PRSMHealthError subclass, optional
        Raise this with the one-line message (e.g. ``RecipeError``) instead of
        :class:`UnknownKeyError` / :class:`MissingKeyError`.

    Raises
    ------
    UnknownKeyError
        The first unknown key (in sorted order), e.g. ``unknown key 'sead' in [scenario]
        (did you mean 'seed'?); allowed: …``.
    MissingKeyError
        The first missing ``required`` key: ``missing key 'seed' in [recipe] (required: …)``.
    """
    allowed = [str(a) for a in allowed]
    unknown = sorted(set(map(str, values)) - set(allowed))
    if unknown:
        key = unknown[0]
        if error is not None:
            raise error(unknown_key_message(table, key, values[key], allowed))
        raise UnknownKeyError(table, key, values[key], allowed)
    required = [str(r) for r in required]
    missing = [k for k in required if k not in values]
    if missing:
        exc = MissingKeyError(table, missing[0], required)
        raise exc if error is None else error(str(exc))
