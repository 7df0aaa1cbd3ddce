"""Prognostics: remaining useful life from a unit's history of diagnoses (docs/prognostics.md).

- :mod:`.history` — the history table: columns, reading a file, validation with row-naming errors
- :mod:`.method` — the interface the RUL methods implement (``fit`` on a training fleet,
  ``predict`` from a unit's history)
- :mod:`.degradation` — the Bayesian degradation model (Gebraeel et al. 2005)
- :mod:`.similarity` — the similarity baseline (Wang et al. 2008)
- :mod:`.ageing_model`, :mod:`.ageing_rul` — the physics model: the PRSM's ageing in progpy
- :mod:`.rul` — :class:`RULModel` (the three methods) → :class:`Prognosis`
- :mod:`.model_files` — JSON model files
- :mod:`.fleet` — a fleet dataset's snapshots diagnosed into histories
- :mod:`.fitting` — a model fitted for a fleet of any design, scored on its held-out units
- :mod:`.metrics` — RMSE, α–λ accuracy, prognostic horizon, coverage (Saxena et al. 2010)

Import from here, not from the modules: their split is this package's business.
"""

from .fitting import FitReport, cross_validate_units, diagnosed_threshold, fit_prognostics_model
from .fleet import fleet_histories, simulated_histories
from .history import (
    HISTORY_COLUMNS,
    HistoryError,
    history_of_readings,
    read_history,
    validate_history,
)
from .method import HORIZON_FACTOR
from .model_files import DEFAULT_PROGNOSTICS_MODEL, load_prognostics_model, save_prognostics_model
from .prognosis import Prognosis
from .rul import METHODS, RULModel, prognose, prognose_readings

__all__ = [
    "DEFAULT_PROGNOSTICS_MODEL",
    "FitReport",
    "HISTORY_COLUMNS",
    "HORIZON_FACTOR",
    "METHODS",
    "HistoryError",
    "Prognosis",
    "RULModel",
    "cross_validate_units",
    "diagnosed_threshold",
    "fit_prognostics_model",
    "fleet_histories",
    "simulated_histories",
    "load_prognostics_model",
    "prognose",
    "prognose_readings",
    "history_of_readings",
    "read_history",
    "save_prognostics_model",
    "validate_history",
]
