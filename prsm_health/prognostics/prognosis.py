"""The answer of a prognosis, declared once: :class:`Prognosis` and its typed parts.

Every field carries its meaning (``metadata["description"]``, units in brackets), as the
Diagnosis contract's do (:mod:`prsm_health.diagnostics.contract`): :meth:`Prognosis.as_dict` is
made from these fields, and the service's response schema is generated from them
(:func:`prsm_health.apps.service.schemas.contract_model`). The parts read as the mappings they
were before they had types (``p.rul_hours["estimate"]``, equality with a dict).
"""

from __future__ import annotations

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

    def __post_init__(self) -> None:
        object.__setattr__(self, "rul_hours", RulHours.of(self.rul_hours))
        object.__setattr__(self, "health_indicator", HealthIndicator.of(self.health_indicator))

    def as_dict(self) -> dict:
        """Plain JSON-ready dict ``{"rul_hours", "health_indicator", "model", "warnings"}``
        (non-finite numbers ``null``)."""
        return json_ready(contract_json(self))
