"""The answer of a prognosis: the remaining useful life with its interval and the evidence it
rests on."""

from __future__ import annotations

from dataclasses import dataclass, field

from prsm_health.core.jsonable import json_ready

#: Quantiles of every prognosis' RUL: lower bound, estimate (median), upper bound.
QUANTILES = (0.05, 0.5, 0.95)


@dataclass(frozen=True)
class Prognosis:
    """The remaining useful life of one unit, with the evidence it rests on.

    Attributes
    ----------
    rul_hours : dict
        ``{"estimate", "lower", "upper"}`` [h]: median and 5 % / 95 % quantiles (a 90 %
        interval); all >= 0.
    health_indicator : dict
        ``{"name": "clearance", "unit": "m", "threshold", "ages_hours", "values", "lower",
        "upper", "current"}``: the history the RUL was predicted from and the failure
        threshold [m]; ``current`` is the latest clearance estimate [m].
    model : dict
        ``{"name", "version", "design", "design_fingerprint", "units_trained", …}``
        (``design_fingerprint`` None for a design known by name only): ``name`` is
        ``"degradation-exponential"``, ``"degradation-linear"`` or ``"similarity"``; the
        degradation models add the posterior of ``(ln theta, beta)`` (or ``(theta, beta)``) in
        physical units [ln m, 1/h] / [m, m/h], ``sigma2``, ``horizon_hours``; the similarity
        model its ``bandwidth`` and ``effective_units``.
    warnings : list of str
        What limits the answer (threshold already crossed, samples capped at the horizon,
        short history, no wear trend, unit older than the fleet, values below the baseline).
    """

    rul_hours: dict
    health_indicator: dict
    model: dict
    warnings: list = field(default_factory=list)

    def as_dict(self) -> dict:
        """Plain JSON-ready dict ``{"rul_hours", "health_indicator", "model", "warnings"}``."""
        return json_ready(
            {
                "rul_hours": self.rul_hours,
                "health_indicator": self.health_indicator,
                "model": self.model,
                "warnings": list(self.warnings),
            }
        )
