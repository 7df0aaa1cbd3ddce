"""The interface every RUL method implements, and what it is fitted on and predicts from.

A method (:class:`RULMethod`: the degradation model, the similarity baseline, the physics
model) is fitted on a :class:`TrainingFleet` — the training units' validated histories and
failure ages, as arrays — and predicts an :class:`Estimate` from one unit's
:class:`UnitHistory`. :class:`~prsm_health.prognostics.RULModel` holds the fitted methods and
turns an estimate into a :class:`~prsm_health.prognostics.Prognosis` (the indicator, the
warnings every method shares); the CLI and the service call only it.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd

from prsm_health.core.errors import require

from .history import HistoryError, duty_arrays, history_arrays, validate_history

#: RUL is capped at this multiple of the training fleet's longest life [-] (the horizon):
#: predictions that never reach the threshold (wear rate <= 0) or reach it later get it.
HORIZON_FACTOR = 3.0
#: A capped fraction of a prediction's samples above this moves its 95 % quantile: a warning
#: says so.
CAPPED_WARNING_FRACTION = 0.05
#: Fewest training units: the leave-one-unit-out prior needs a covariance of at least 2 others.
MIN_TRAINING_UNITS = 3


@dataclass(frozen=True)
class FleetSummary:
    """What a fitted method keeps of its training fleet (and a model file stores)."""

    units: list
    """Training unit ids."""
    lives: np.ndarray
    """Their failure ages [h], in the same order."""
    threshold: float
    """Clearance at which a unit fails [m]."""
    t_scale: float
    """Time scale [h] (median failure age): parameters are fitted against ``age / t_scale``."""
    horizon: float
    """RUL cap [h]: ``HORIZON_FACTOR`` x the longest life."""
    c_ref: float
    """The fleet's initial clearance level [m] (the smallest first diagnosis of a unit)."""


@dataclass(frozen=True)
class TrainingFleet:
    """A training fleet run to failure: its summary and every unit's diagnoses as arrays
    (``codes`` the unit index of each row, units in :attr:`FleetSummary.units` order)."""

    summary: FleetSummary
    histories: pd.DataFrame
    """The units' validated histories, one after the other (other columns kept)."""
    codes: np.ndarray
    t: np.ndarray
    """Ages [h]."""
    value: np.ndarray
    """Diagnosed clearances [m]."""
    sd: np.ndarray
    """Their measurement standard deviations [m] (from the 90 % intervals)."""

    @classmethod
    def from_histories(
        cls, histories: pd.DataFrame, failure_ages: Mapping, threshold: float, model=None
    ) -> TrainingFleet:
        """Check and gather a fleet: each unit's history (:func:`validate_history`, against
        ``model``'s design), its failure age, at least :data:`MIN_TRAINING_UNITS` units and a
        threshold above the fleet's initial clearance; errors name the unit or field."""
        require(
            isinstance(histories, pd.DataFrame) and "unit_id" in histories.columns,
            "histories",
            type(histories).__name__,
            "must be a pandas DataFrame with a unit_id column",
        )
        if isinstance(failure_ages, pd.Series):
            failure_ages = failure_ages.to_dict()
        require(
            isinstance(failure_ages, Mapping),
            "failure_ages",
            type(failure_ages).__name__,
            "must be a mapping unit_id -> age at failure [h]",
        )
        units, parts, lives = [], [], []
        for uid, rows in histories.groupby("unit_id", sort=True):
            uid = uid.item() if isinstance(uid, np.generic) else uid
            try:
                part = validate_history(rows, model)
            except HistoryError as err:
                raise HistoryError(f"unit {uid!r}: {err}", err.field, err.value) from None
            require(uid in failure_ages, "failure_ages", uid, "has no failure age for this unit")
            life = failure_ages[uid]
            require(
                isinstance(life, (int, float, np.number)) and math.isfinite(life) and life > 0,
                f"failure_ages[{uid!r}]",
                life,
                "must be a finite age > 0 [h]",
            )
            units.append(uid)
            parts.append(part)
            lives.append(float(life))
        require(
            len(units) >= MIN_TRAINING_UNITS,
            "histories",
            f"{len(units)} unit(s)",
            f"a prognostics model needs at least {MIN_TRAINING_UNITS} training units",
        )
        lives = np.array(lives)
        c_ref = float(min(p["clearance"].iloc[0] for p in parts))
        require(
            threshold > c_ref,
            "threshold",
            float(threshold),
            f"must exceed the fleet's initial clearance {c_ref:.6g} m",
        )
        summary = FleetSummary(
            units=units,
            lives=lives,
            threshold=float(threshold),
            t_scale=float(np.median(lives)),
            horizon=HORIZON_FACTOR * float(lives.max()),
            c_ref=c_ref,
        )
        codes = np.concatenate([np.full(len(p), i) for i, p in enumerate(parts)])
        t, value, sd = (np.concatenate(x) for x in zip(*(history_arrays(p) for p in parts)))
        return cls(summary, pd.concat(parts, ignore_index=True), codes, t, value, sd)


@dataclass(frozen=True)
class UnitHistory:
    """One unit's diagnoses as arrays: ages [h], clearances [m], their standard deviations
    [m] and the duty log before each diagnosis (``load``, ``usage_rate``; None where the
    history has none, :func:`~prsm_health.prognostics.history.duty_arrays`)."""

    t: np.ndarray
    value: np.ndarray
    sd: np.ndarray
    load: np.ndarray | None = None
    usage_rate: np.ndarray | None = None

    @classmethod
    def from_table(cls, clean: pd.DataFrame) -> UnitHistory:
        """From a history :func:`validate_history` accepted."""
        return cls(*history_arrays(clean), **duty_arrays(clean))

    def prefix(self, k: int) -> UnitHistory:
        """The first ``k`` diagnoses."""
        cut = [None if a is None else a[:k] for a in (self.load, self.usage_rate)]
        return UnitHistory(self.t[:k], self.value[:k], self.sd[:k], *cut)

    @property
    def duty(self) -> dict:
        return {"load": self.load, "usage_rate": self.usage_rate}


class Estimate(NamedTuple):
    """A method's answer for one history."""

    rul_hours: dict
    """``{"estimate", "lower", "upper"}`` [h]: median, 5 % and 95 % quantiles."""
    model: dict
    """``{"name": …}`` and what the method rests on (posterior, bandwidth, …)."""
    warnings: list
    """What limits this method's answer."""


class RULMethod(ABC):
    """A RUL method: fitted on a training fleet, predicting one unit's RUL from its history."""

    @abstractmethod
    def fit(self, fleet: TrainingFleet) -> RULMethod:
        """Learn from the fleet; returns self."""

    @abstractmethod
    def predict(self, history: UnitHistory) -> Estimate:
        """The RUL after the whole history."""

    def predict_prefixes(self, history: UnitHistory, min_rows: int) -> list[Estimate]:
        """The RUL after each prefix of >= ``min_rows`` diagnoses, each from the rows up to
        it only."""
        return [self.predict(history.prefix(k)) for k in range(min_rows, len(history.t) + 1)]
