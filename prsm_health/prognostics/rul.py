"""Prognostics: remaining useful life (RUL) of a unit from the history of its diagnoses.

A **history** is a table of diagnoses of one asset over its operating hours (columns
:data:`HISTORY_COLUMNS`: the age [h] and the diagnosed clearance [m] with its 90 % interval;
optionally ``design``, ``fault_class``, ``unit_id``). The health indicator is the clearance; a
unit fails when its true clearance reaches ``threshold`` [m]. A :class:`RULModel` is
fitted on a training fleet (the histories of units run to failure and their failure ages) and
predicts a :class:`Prognosis`: the RUL [h] with a 90 % interval (5 % and 95 % quantiles).

The model holds three methods behind one interface (:class:`~.method.RULMethod`: ``fit`` on a
training fleet, ``predict`` from a unit's history), each in its own module:

- ``"degradation"`` (default), the Bayesian degradation model after Gebraeel et al. [1]_
  (:class:`~.degradation.DegradationRUL`);
- ``"similarity"``, the similarity baseline after Wang et al. [2]_
  (:class:`~.similarity.SimilarityRUL`);
- ``"physics"``, the PRSM's ageing model in progpy, when fitted on a fleet dataset whose
  ``[life]`` recipe gives the physics (:class:`~.ageing_rul.PhysicsRUL`).

This module gathers the fleet, dispatches to a method and turns its estimate into a
:class:`Prognosis` with the warnings every method shares; it also reads and writes the
model's dict. Metrics and the fleet evaluation are in :mod:`prsm_health.prognostics.metrics`.

References
----------
.. [1] N. Z. Gebraeel, M. A. Lawley, R. Li, J. K. Ryan, "Residual-life distributions from
   component degradation signals: a Bayesian approach", IIE Transactions 37 (2005) 543-557.
.. [2] T. Wang, J. Yu, D. Siegel, J. Lee, "A similarity-based prognostics approach for
   remaining useful life estimation of engineered systems", Int. Conf. on Prognostics and
   Health Management (PHM 2008), Denver, 2008.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
import pandas as pd

from prsm_health.core.errors import (
    ModelVersionError,
    ParameterError,
    PRSMHealthError,
    require,
    require_positive,
)
from prsm_health.core.jsonable import json_ready
from prsm_health.core.version import __version__

from .ageing_rul import AgeingRUL, PhysicsRUL
from .degradation import FORMS, DegradationRUL
from .history import (
    Z90,
    HistoryError,
    history_of_readings,
    model_design,
    one_line,
    validate_history,
)
from .method import Estimate, FleetSummary, RULMethod, TrainingFleet, UnitHistory
from .prognosis import Prognosis
from .similarity import SimilarityRUL

#: Methods :meth:`RULModel.predict` accepts. ``"degradation"`` uses the form chosen at
#: fit time; ``"degradation-exponential"`` / ``"degradation-linear"`` force a form.
METHODS = (
    "degradation",
    "degradation-exponential",
    "degradation-linear",
    "similarity",
    "physics",
)
#: A history spanning less than this fraction of the fleet's median life gets a warning.
SHORT_HISTORY_FRACTION = 0.1

_FORMAT = "prsm_health-prognostics"
_FORMAT_VERSION = 1


class RULModel:
    """RUL from a history of diagnoses: the degradation model, the similarity baseline and,
    where fitted, the physics model.

    ``__init__`` stores its arguments; :meth:`fit` learns from a training fleet (attributes
    ending in ``_``); :meth:`predict` returns a :class:`Prognosis`. The methods are in their
    modules (module docstring). Every prediction's RUL is clipped to [0, horizon], the horizon
    being ``HORIZON_FACTOR`` x the fleet's longest life; when the latest clearance estimate
    is at or above the threshold the RUL is 0 with a warning.

    Parameters
    ----------
    method : {"degradation", "similarity", "physics", "degradation-exponential", "degradation-linear"}
        Default method of :meth:`predict`.
    threshold : float, default 30e-6
        Clearance at which a unit fails [m], > 0.
    design : str, default "paper01"
        Name of the design the model is for (any design, not only a preset).
    design_fingerprint : str or None, default None
        :func:`~prsm_health.actuator.design_files.design_fingerprint` of that design; None
        for a preset named by ``design`` (its fingerprint) or a design known by name only.
        A history must be of the model's design: its ``design_fingerprint`` column equal to
        this where both exist, else its ``design`` column equal to the name
        (:func:`~prsm_health.prognostics.validate_history`).
    n_samples : int, default 4000
        Posterior samples per degradation prediction, >= 100.
    random_state : int or None, default 0
        Seed of the posterior sampling (every prediction restarts from it, so a prediction
        does not depend on the ones before it); None draws a fresh seed per prediction.

    Attributes
    ----------
    degradation_ : DegradationRUL
        The degradation model; ``form_``, ``loo_rmse_`` and ``forms_`` are its.
    similarity_ : SimilarityRUL
    ageing_ : AgeingRUL or None
        The physics model's estimator (None: no physics part).
    form_ : {"exponential", "linear"}
        Degradation form chosen at fit time.
    loo_rmse_ : dict
        Leave-one-unit-out RMSE of RUL [h] of each form.
    forms_ : dict
        Per form: ``phi`` [m], ``sigma2``, prior ``mean`` and ``cov``, per-unit ``params``
        and ``residual_var`` [m^2] (scaled time; linear form in units of the threshold).
    units_ : list
        Training unit ids; ``failure_ages_`` [h] in the same order.
    t_scale_ : float
        Time scale [h] (median failure age); parameters are fitted against ``age / t_scale_``.
    horizon_ : float
        RUL cap [h]: ``HORIZON_FACTOR`` x the longest training life.
    c_ref_ : float
        The fleet's initial clearance level [m].
    """

    def __init__(
        self,
        method="degradation",
        threshold=30e-6,
        design="paper01",
        n_samples=4000,
        random_state=0,
        design_fingerprint=None,
    ):
        self.method = method
        self.threshold = threshold
        self.design = design
        self.design_fingerprint = design_fingerprint
        self.n_samples = n_samples
        self.random_state = random_state

    # ---------------------------------------------------------------------------- parameters

    def _check_params(self) -> None:
        require(
            self.method in METHODS, "method", self.method, f"must be one of {', '.join(METHODS)}"
        )
        require_positive("threshold", self.threshold)
        require(
            isinstance(self.design, str) and self.design != "",
            "design",
            self.design,
            "must be a non-empty design name",
        )
        require(
            self.design_fingerprint is None
            or (isinstance(self.design_fingerprint, str) and self.design_fingerprint != ""),
            "design_fingerprint",
            self.design_fingerprint,
            "must be None or a design fingerprint (hex text)",
        )
        require(
            isinstance(self.n_samples, (int, np.integer))
            and not isinstance(self.n_samples, bool)
            and self.n_samples >= 100,
            "n_samples",
            self.n_samples,
            "must be an integer >= 100",
        )
        require(
            self.random_state is None
            or (
                isinstance(self.random_state, (int, np.integer))
                and not isinstance(self.random_state, bool)
                and self.random_state >= 0
            ),
            "random_state",
            self.random_state,
            "must be None or an integer >= 0",
        )

    @property
    def design_id(self) -> tuple[str, str | None]:
        """(name, fingerprint) of the model's design; a preset's fingerprint when only a
        preset name was given (model files from before fingerprints)."""
        return model_design(self.design, self.design_fingerprint)

    def _is_fitted(self) -> bool:
        return hasattr(self, "degradation_")

    def _require_fitted(self) -> None:
        if not self._is_fitted():
            raise PRSMHealthError(
                "the prognostics model is not fitted: call fit(histories, failure_ages) first"
            )

    # ---------------------------------------------------------------------------- fitting

    def fit(self, histories: pd.DataFrame, failure_ages: Mapping, physics=None) -> RULModel:
        """Fit the methods on a training fleet run to failure.

        Parameters
        ----------
        histories : pandas.DataFrame
            Column ``unit_id`` plus :data:`HISTORY_COLUMNS`: each training unit's diagnoses
            over its life (ages [h], clearances [m]); each unit needs >= 2 diagnoses.
        failure_ages : Mapping
            Unit id -> true age at failure [h] (when its true clearance reached
            ``threshold``), > 0 for every unit in ``histories``.
        physics : PhysicsRUL or None
            The physics method to fit too (it needs the fleet recipe); None: no physics part.

        Returns
        -------
        RULModel
            self.

        Raises
        ------
        ParameterError
            Invalid parameters, fewer than 3 units, a unit without a failure age, a unit's
            history failing :func:`validate_history` (the message names the unit), a fleet
            that starts at or above the threshold.
        """
        self._check_params()
        fleet = TrainingFleet.from_histories(histories, failure_ages, self.threshold, self)
        self._set_fleet(fleet.summary)
        self.degradation_ = DegradationRUL(self.n_samples, self.random_state).fit(fleet)
        self.similarity_ = SimilarityRUL(self.degradation_).fit(fleet)
        self.ageing_ = None if physics is None else physics.fit(fleet).estimator_
        return self

    def _set_fleet(self, fleet: FleetSummary) -> None:
        self.units_ = fleet.units
        self.failure_ages_ = fleet.lives
        self.t_scale_ = fleet.t_scale
        self.horizon_ = fleet.horizon
        self.c_ref_ = fleet.c_ref

    @property
    def form_(self) -> str:
        return self.degradation_.form_

    @property
    def forms_(self) -> dict:
        return self.degradation_.forms_

    @property
    def loo_rmse_(self) -> dict:
        return self.degradation_.loo_rmse_

    # ---------------------------------------------------------------------------- prediction

    def predict(self, history: pd.DataFrame, method=None) -> Prognosis:
        """RUL of the unit whose diagnoses ``history`` holds.

        Parameters
        ----------
        history : pandas.DataFrame
            One unit's diagnoses (:data:`HISTORY_COLUMNS`; checked by
            :func:`validate_history`).
        method : str, optional
            One of :data:`METHODS`; default ``self.method``.

        Returns
        -------
        Prognosis
            RUL [h] with its 90 % interval, the health indicator, the model, warnings.

        Raises
        ------
        HistoryError
            A history :func:`validate_history` refuses.
        ParameterError
            An unknown method.
        PRSMHealthError
            An unfitted model.
        """
        rul_method = self._method(method)
        unit = UnitHistory.from_table(validate_history(history, self))
        return self._prognosis(unit, rul_method.predict(unit))

    def predict_prefixes(self, history: pd.DataFrame, method=None, min_rows: int = 2) -> list:
        """Prognoses at every prefix of the history, each from the rows up to it only.

        Parameters
        ----------
        history : pandas.DataFrame
            One unit's diagnoses, validated once by :func:`validate_history`.
        method : str, optional
            One of :data:`METHODS`; default ``self.method``.
        min_rows : int, default 2
            Shortest prefix predicted from (>= 2).

        Returns
        -------
        list of Prognosis
            One per prefix of ``min_rows`` … ``len(history)`` rows, in age order.
        """
        rul_method = self._method(method)
        require(
            isinstance(min_rows, (int, np.integer)) and min_rows >= 2,
            "min_rows",
            min_rows,
            "must be an integer >= 2",
        )
        unit = UnitHistory.from_table(validate_history(history, self))
        estimates = rul_method.predict_prefixes(unit, min_rows)
        return [
            self._prognosis(unit.prefix(k), estimate)
            for k, estimate in zip(range(min_rows, len(unit.t) + 1), estimates)
        ]

    def _method(self, method) -> RULMethod:
        """The fitted method a prediction by ``method`` (default ``self.method``) uses."""
        self._require_fitted()
        method = self.method if method is None else method
        require(method in METHODS, "method", method, f"must be one of {', '.join(METHODS)}")
        if method == "similarity":
            return self.similarity_
        if method == "physics":
            return PhysicsRUL(estimator=self._ageing())
        if method == "degradation":
            return self.degradation_
        return self.degradation_.with_form(method.split("-", 1)[1])

    def _ageing(self):
        ageing = getattr(self, "ageing_", None)
        if ageing is None:
            raise PRSMHealthError(
                "this prognostics model has no physics part: fit it with "
                "fit_prognostics_model on a fleet dataset (its [life] recipe gives the physics)"
            )
        return ageing

    def _prognosis(self, unit: UnitHistory, estimate: Estimate) -> Prognosis:
        """A method's estimate as a :class:`Prognosis`: the model's design and fleet, the
        health indicator and the warnings every method shares."""
        thr = float(self.threshold)
        t, value, sd = unit.t, unit.value, unit.sd
        rul = estimate.rul_hours
        model = {
            "name": estimate.model["name"],
            "version": __version__,
            "design": self.design,
            "design_fingerprint": self.design_id[1],
            "units_trained": len(self.units_),
            "threshold": thr,
            "horizon_hours": self.horizon_,
            **estimate.model,
        }
        warnings = self._history_warnings(t, value, sd) + list(estimate.warnings)
        indicator = {
            "name": "clearance",
            "unit": "m",
            "threshold": thr,
            "ages_hours": t.tolist(),
            "values": value.tolist(),
            "lower": (value - Z90 * sd).tolist(),
            "upper": (value + Z90 * sd).tolist(),
            "current": float(value[-1]),
        }
        if value[-1] >= thr:
            warnings.insert(
                0,
                f"threshold already crossed: the latest clearance {value[-1]:.4g} m is at or "
                f"above the threshold {thr:.4g} m; RUL 0",
            )
            rul = {"estimate": 0.0, "lower": 0.0, "upper": 0.0}
        return Prognosis(rul_hours=rul, health_indicator=indicator, model=model, warnings=warnings)

    def _history_warnings(self, t, value, sd) -> list:
        warnings = []
        span = float(t[-1] - t[0])
        median_life = float(np.median(self.failure_ages_))
        if span < SHORT_HISTORY_FRACTION * median_life:
            warnings.append(
                f"history shorter than the model's minimum span: {span:.4g} h < "
                f"{SHORT_HISTORY_FRACTION:.0%} of the training fleet's median life "
                f"({median_life:.4g} h); the RUL mostly reflects the fleet"
            )
        if t[-1] > self.failure_ages_.max():
            warnings.append(
                f"unit age {t[-1]:.4g} h is beyond the longest training life "
                f"{self.failure_ages_.max():.4g} h: the RUL is extrapolated"
            )
        w = 1.0 / (sd**2 + (1e-8 * float(self.threshold)) ** 2)
        tm = np.sum(w * t) / np.sum(w)
        slope = np.sum(w * (t - tm) * value)
        if slope <= 0:
            warnings.append(
                "health indicator decreasing: no wear trend yet, interval is the fleet's"
            )
        return warnings

    # ---------------------------------------------------------------------------- persistence

    def to_dict(self) -> dict:
        """Plain JSON-able dict of the parameters and the fitted state (no pickle)."""
        out = {
            "format": _FORMAT,
            "format_version": _FORMAT_VERSION,
            "version": __version__,
            "params": {
                "method": self.method,
                "threshold": self.threshold,
                "design": self.design,
                "design_fingerprint": self.design_fingerprint,
                "n_samples": self.n_samples,
                "random_state": self.random_state,
            },
            "fitted": None,
        }
        if self._is_fitted():
            out["fitted"] = {
                "units": list(self.units_),
                "failure_ages": self.failure_ages_,
                "t_scale": self.t_scale_,
                "horizon": self.horizon_,
                "c_ref": self.c_ref_,
                "form": self.form_,
                "selection_rule": "lower leave-one-unit-out RMSE of RUL on the training fleet",
                "loo_rmse": dict(self.loo_rmse_),
                "forms": self.forms_,
                "ageing": None
                if getattr(self, "ageing_", None) is None
                else self.ageing_.to_dict(),
            }
        return json_ready(out)

    @classmethod
    def from_dict(cls, d: dict) -> RULModel:
        """Rebuild a model from :meth:`to_dict` output.

        Raises
        ------
        PRSMHealthError
            Not a prognostics-model dict, or a malformed one (one line naming the problem).
        ModelVersionError
            A dict of another format version.
        """
        if not isinstance(d, dict) or d.get("format") != _FORMAT:
            raise PRSMHealthError("not a prsm_health prognostics model (unknown format)")
        if d.get("format_version") != _FORMAT_VERSION:
            raise ModelVersionError(
                f"prognostics model format version {d.get('format_version')!r}; this "
                f"prsm_health {__version__} reads version {_FORMAT_VERSION}"
            )
        try:
            model = cls(**d["params"])
            model._check_params()
            fitted = d["fitted"]
            if fitted is not None:
                fleet = FleetSummary(
                    units=list(fitted["units"]),
                    lives=np.asarray(fitted["failure_ages"], dtype=np.float64),
                    threshold=float(model.threshold),
                    t_scale=float(fitted["t_scale"]),
                    horizon=float(fitted["horizon"]),
                    c_ref=float(fitted["c_ref"]),
                )
                loo_rmse = {f: float(fitted["loo_rmse"][f]) for f in FORMS}
                form = fitted["form"]
                if form not in FORMS:
                    raise ValueError(f"unknown form {form!r}")
                forms = {}
                for name in FORMS:
                    s = fitted["forms"][name]
                    forms[name] = {
                        "phi": float(s["phi"]),
                        "sigma2": float(s["sigma2"]),
                        "mean": np.asarray(s["mean"], dtype=np.float64).reshape(2),
                        "cov": np.asarray(s["cov"], dtype=np.float64).reshape(2, 2),
                        "params": np.asarray(s["params"], dtype=np.float64).reshape(-1, 2),
                        "residual_var": np.asarray(s["residual_var"], dtype=np.float64),
                    }
                    units = len(fleet.units)
                    if len(forms[name]["params"]) != units or len(fleet.lives) != units:
                        raise ValueError("unit count mismatch")
                    if not all(np.all(np.isfinite(v)) for v in forms[name].values()):
                        raise ValueError("non-finite parameter")
                model._set_fleet(fleet)
                model.degradation_ = DegradationRUL(model.n_samples, model.random_state).restored(
                    fleet, forms, form, loo_rmse
                )
                model.similarity_ = SimilarityRUL(model.degradation_)
                ageing = fitted.get("ageing")
                model.ageing_ = None if ageing is None else AgeingRUL.from_dict(ageing)
        except ParameterError as err:
            raise PRSMHealthError(f"malformed prognostics model ({one_line(err)})") from None
        except (KeyError, TypeError, ValueError, AttributeError) as err:
            what = f"missing {err}" if isinstance(err, KeyError) else one_line(err)
            raise PRSMHealthError(f"malformed prognostics model ({what})") from None
        return model


def prognose(history: pd.DataFrame, model: RULModel, method=None) -> Prognosis:
    """RUL of one unit: :func:`validate_history` then :meth:`RULModel.predict`.

    Parameters
    ----------
    history : pandas.DataFrame
        One unit's diagnoses (:data:`HISTORY_COLUMNS`).
    model : RULModel
        A fitted model.
    method : str, optional
        One of :data:`METHODS`; default ``model.method``.

    Returns
    -------
    Prognosis
    """
    require(
        isinstance(model, RULModel),
        "model",
        type(model).__name__,
        "must be a RULModel",
    )
    clean = validate_history(history, model)
    return model.predict(clean, method=method)


def prognose_readings(
    rows, model: RULModel, method=None, *, asset: str = "asset"
) -> tuple[Prognosis, pd.DataFrame]:
    """The prognosis of an asset from its stored readings (rows with operating hours, the
    clearance with its interval and the diagnosing model's design: the CLI's
    :meth:`~prsm_health.monitoring.asset.AssetHistory.operating_history`, the service's
    :meth:`~prsm_health.monitoring.sqlite_store.HistoryStore.operating_history`), the
    readings' notes first in its warnings; and the history it was made from.

    Raises
    ------
    HistoryError
        Fewer than 2 readings at distinct operating hours, a reading whose design is not
        recorded, another design than the model's, a history :func:`prognose` refuses: one
        sentence naming ``asset``.
    """
    missing = sum(1 for r in rows if r.design is None)
    if missing:
        raise HistoryError(
            f"{asset}: {missing} of its diagnoses do not record the design that diagnosed them "
            "(recorded before the design was kept): diagnose those recordings again",
            field="history.design",
        )
    history, notes = history_of_readings(rows)
    if len(history) < 2:
        raise HistoryError(
            f"{asset} has {len(history)} diagnosis(es) at distinct operating hours; a "
            "prognosis needs at least 2 (give each recording its operating hours)",
            field="history.age_hours",
        )
    try:
        prognosis = prognose(history, model, method)
    except HistoryError as exc:
        raise HistoryError(f"{asset}: {exc}", field=exc.field, value=exc.value) from None
    return replace(prognosis, warnings=[*notes, *prognosis.warnings]), history
