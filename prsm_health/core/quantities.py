"""Forces as a user writes them: newtons, a unit, or a share of the design's load rating.

Wherever a load is given (a scenario's ``[profile]``, a recipe's sweep, a health check's phase,
the life model's duty, ``--load`` on the command line) it may be

* a number: newtons (``4400``, ``-250.0``);
* a number with a unit: ``"4.4 kN"``, ``"4400 N"``, ``"-300N"``;
* a share of a basic axial load rating of the design (:mod:`prsm_health.physics.load_rating`):
  ``"20 % C_a"``, ``"20%C_a"``, ``"0.2 C_a"``, ``"0.2*C_a"``, ``"5 % C_0a"``.

Parsing needs no design (this module); turning a share into newtons needs the ratings
(:meth:`ForceSpec.newtons`), which the scenario supplies from its design.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .errors import ParameterError

#: The ratings a force may be a share of: the basic dynamic and static axial load ratings.
RATINGS = ("C_a", "C_0a")
_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_FORCE = re.compile(
    rf"^\s*(?P<value>{_NUMBER})\s*(?:(?P<percent>%)\s*\*?\s*|\*?\s*)(?P<unit>[A-Za-z_0-9]+)?\s*$"
)
ALLOWED = (
    "a force in N (a number), a number with a unit (N, kN, MN: '4.4 kN') or a share of the "
    "design's load rating ('20 % C_a', '0.2 C_a', '5 % C_0a')"
)


@dataclass(frozen=True)
class ForceSpec:
    """A force as given: ``value`` in newtons (``of`` None) or a share of rating ``of``."""

    value: float
    of: str | None = None

    def newtons(self, ratings: dict[str, float] | None, field: str = "load") -> float:
        """The force [N]; a share needs ``ratings`` (``{"C_a": …, "C_0a": …}`` [N])."""
        if self.of is None:
            return self.value
        if not ratings or self.of not in ratings:
            raise ParameterError(
                field,
                self.text(),
                f"a share of {self.of} needs a design with load ratings (give the design)",
            )
        return self.value * float(ratings[self.of])

    def text(self) -> str:
        """The canonical written form (``"20 % C_a"``, or the number of newtons)."""
        if self.of is None:
            return f"{self.value:g} N"
        return f"{100.0 * self.value:g} % {self.of}"


def parse_force(value, field: str = "load") -> ForceSpec:
    """A :class:`ForceSpec` from a number or a string (module docstring); the error names the
    field and the accepted forms."""
    if isinstance(value, ForceSpec):
        return value
    if isinstance(value, bool):
        raise ParameterError(field, value, f"must be {ALLOWED}")
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise ParameterError(field, value, f"must be finite: {ALLOWED}")
        return ForceSpec(float(value))
    if not isinstance(value, str):
        raise ParameterError(field, value, f"must be {ALLOWED}")
    match = _FORCE.match(value)
    if match is None:
        raise ParameterError(field, value, f"must be {ALLOWED}")
    number = float(match["value"])
    unit = match["unit"]
    percent = match["percent"] is not None
    if unit is None:
        if percent:
            raise ParameterError(field, value, f"a percentage needs its rating: {ALLOWED}")
        return ForceSpec(number)
    if unit in RATINGS:
        return ForceSpec(number / 100.0 if percent else number, unit)
    if unit in _UNITS and not percent:
        return ForceSpec(number * _UNITS[unit])
    raise ParameterError(field, value, f"unknown unit or rating '{unit}': must be {ALLOWED}")


def force_newtons(value, ratings: dict[str, float] | None, field: str = "load") -> float:
    """Parse and resolve in one step: the force [N] of ``value``."""
    return parse_force(value, field).newtons(ratings, field)
