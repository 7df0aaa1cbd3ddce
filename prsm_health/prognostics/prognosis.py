"""The answer of a prognosis, declared once: :class:`Prognosis` and its typed parts.

Every field carries its meaning (``metadata["description"]``, units in brackets), as the
Diagnosis contract's do (:mod:`prsm_health.diagnostics.contract`): :meth:`Prognosis.as_dict` is
made from these fields, and the service's response schema is generated from them
(:func:`prsm_health.apps.service.schemas.contract_model`). The parts read as the mappings they
were before they had types (``p.rul_hours["estimate"]``, equality with a dict).

What a maintainer reads of a prognosis is one rule, :meth:`Headline.read`: the median RUL with
its 90 % interval, the latest clearance and the threshold together, never "0 h" while the
latest clearance is below the threshold. Every prognosis carries its :class:`Headline`
(``Prognosis.headline``); the CLI, the service and the dashboard show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from prsm_health.core.jsonable import json_ready
from prsm_health.diagnostics.contract import ContractPart, contract_json, describe

#: Quantiles of every prognosis' RUL: lower bound, estimate (median), upper bound.
QUANTILES = (0.05, 0.5, 0.95)

#: The methods a prognosis names in ``model.name``.
MODEL_NAMES = ("degradation-exponential", "degradation-linear", "similarity", "physics")


@dataclass(frozen=True, eq=False)
class RulHours(ContractPart):
    """The remaining useful life and its 90 % interval; all ≥ 0."""

    estimate: float = describe("median remaining useful life [h]")
    lower: float = describe("5 % quantile [h] (lower bound of the 90 % interval)")
    upper: float = describe("95 % quantile [h] (upper bound of the 90 % interval)")


@dataclass(frozen=True, eq=False)
class HealthIndicator(ContractPart):
    """The history the RUL was predicted from, and the failure threshold."""

    name: str = describe("the health indicator: clearance")
    unit: str = describe("its unit: m")
    threshold: float = describe("clearance at which the unit fails [m]")
    ages_hours: list[float] = describe("operating hours of the diagnoses used [h]")
    values: list[float] = describe("their clearance estimates [m]")
    lower: list[float] = describe("their 90 % interval lower bounds [m]")
    upper: list[float] = describe("their 90 % interval upper bounds [m]")
    current: float = describe("the latest clearance estimate [m]")


#: Below this median RUL [h] the fitted trend has reached the threshold: while the latest
#: clearance is still below it, the prognosis reads "at the limit by its trend", not "0 h".
AT_LIMIT_HOURS = 1.0

#: The states of a :class:`Headline`, most urgent first.
HEADLINE_STATES = ("threshold_reached", "at_limit", "remaining", "unknown")


@dataclass(frozen=True, eq=False)
class Headline(ContractPart):
    """What a maintainer reads of a prognosis: the median RUL with its 90 % interval, the latest
    clearance and the threshold, in one line (:meth:`read`, the one rule)."""

    state: str = describe(
        "threshold_reached (the latest clearance is at or above the threshold: overhaul), "
        "at_limit (below it, but the fitted trend has reached it: median RUL < 1 h), remaining "
        "(median RUL >= 1 h) or unknown (no finite median)"
    )
    text: str = describe(
        "one line: the RUL's median and 90 % interval [h], the latest clearance and the "
        "threshold [µm], and what to do when the limit is near or reached"
    )
    short: str = describe("the RUL in brief, for a table cell: median and 90 % interval [h]")

    @classmethod
    def read(cls, rul_hours, current, threshold) -> Headline:
        """The headline of a RUL (a mapping ``estimate``, ``lower``, ``upper`` [h]), the latest
        clearance and the threshold [m]; None or non-finite numbers are read as unknown."""
        estimate, lower, upper = (_number(rul_hours[k]) for k in ("estimate", "lower", "upper"))
        current, threshold = _number(current), _number(threshold)
        now, limit = _micrometres(current, threshold)
        known = math.isfinite(current) and math.isfinite(threshold)
        if known and current >= threshold:
            return cls(
                "threshold_reached",
                f"threshold reached — overhaul: latest clearance {now}, at or above the {limit} "
                "threshold",
                "threshold reached — overhaul",
            )
        if known:
            against = f"latest clearance {now} of the {limit} threshold"
        else:
            against = f"latest clearance {now}, threshold {limit}"
        if not math.isfinite(estimate):
            return cls("unknown", f"RUL unknown (no finite median) — {against}", "RUL unknown")
        if estimate < AT_LIMIT_HOURS:
            up_to = f"up to {_hours(upper)} h" if math.isfinite(upper) else "no upper bound"
            if known:
                against = f"latest clearance {now}, below the {limit} threshold"
            return cls(
                "at_limit",
                f"at the limit by its trend: RUL < {AT_LIMIT_HOURS:g} h median, {up_to} (90 %); "
                f"{against} — check it again soon",
                f"at the limit: < {AT_LIMIT_HOURS:g} h, {up_to}",
            )
        interval = f"{_hours(estimate)} h [{_hours(lower)}, {_hours(upper)}]"
        return cls("remaining", f"RUL {interval} (90 %) — {against}", interval)


def _number(value) -> float:
    """A float; None (a JSON null) or not a number: NaN."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _hours(value: float) -> str:
    """Hours as a maintainer reads them: whole hours from 10 h, else 2 significant digits; an
    unbounded bound ∞, an unknown one –."""
    if math.isnan(value):
        return "–"
    if math.isinf(value):
        return "∞" if value > 0 else "–"
    return f"{value:.0f}" if abs(value) >= 10 else f"{value:.2g}"


def _micrometres(current: float, threshold: float) -> tuple[str, str]:
    """The latest clearance and the threshold [m] in µm, with one decimal, or as many (up to
    three) as they need to read apart; unknown where not finite."""
    digits = 1
    if math.isfinite(current) and math.isfinite(threshold) and current != threshold:
        while digits < 3 and f"{1e6 * current:.{digits}f}" == f"{1e6 * threshold:.{digits}f}":
            digits += 1
    return tuple(
        f"{1e6 * v:.{digits}f} µm" if math.isfinite(v) else "unknown" for v in (current, threshold)
    )


@dataclass(frozen=True)
class Prognosis:
    """The remaining useful life of one unit, with the evidence it rests on.

    ``rul_hours`` and ``health_indicator`` may be given as mappings of their fields (converted
    to :class:`RulHours` and :class:`HealthIndicator`).
    """

    rul_hours: RulHours = describe("the RUL [h]: median and 5 % / 95 % quantiles")
    health_indicator: HealthIndicator = describe(
        "the history the RUL was predicted from and the failure threshold"
    )
    model: dict = describe(
        "the prognostics model: name (the method used: "
        + ", ".join(MODEL_NAMES)
        + "), version, design, design_fingerprint (null for a design known by name only), "
        "units_trained, threshold [m], horizon_hours (the RUL cap [h]); by method, the "
        "degradation models' posterior of (ln theta, beta) or (theta, beta) in physical "
        "units [ln m, 1/h] / [m, m/h] and sigma2, the similarity model's bandwidth, "
        "effective_units and nearest_unit, the physics model's states, posterior, "
        "failure_clearance [m], n_particles, n_samples and capped_fraction"
    )
    warnings: list[str] = describe(
        "what limits the answer (threshold already crossed, samples capped at the horizon, "
        "short history, no wear trend, unit older than the fleet, values below the baseline)",
        default_factory=list,
    )
    headline: Headline = describe(
        "what a maintainer reads: the RUL's median and 90 % interval with the latest clearance "
        "and the threshold, in one line and in brief, and its state (made from the fields above "
        "by one rule)",
        init=False,
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "rul_hours", RulHours.of(self.rul_hours))
        object.__setattr__(self, "health_indicator", HealthIndicator.of(self.health_indicator))
        hi = self.health_indicator
        headline = Headline.read(self.rul_hours, hi["current"], hi["threshold"])
        object.__setattr__(self, "headline", headline)

    def as_dict(self) -> dict:
        """Plain JSON-ready dict ``{"rul_hours", "health_indicator", "model", "warnings",
        "headline"}`` (non-finite numbers ``null``)."""
        return json_ready(contract_json(self))
