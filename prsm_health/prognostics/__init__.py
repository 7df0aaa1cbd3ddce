"""Prognostics: remaining useful life from a unit's history of diagnoses, its models, their
files, fleet pipelines and the prognostic metrics (docs/prognostics.md).

Import from here, not from the modules: their split is this package's business.
"""

from .rul import (
    DEFAULT_PROGNOSTICS_MODEL,
    HISTORY_COLUMNS,
    HORIZON_FACTOR,
    METHODS,
    HistoryError,
    Prognosis,
    PrognosticsModel,
    fleet_histories,
    load_prognostics_model,
    prognose,
    read_history,
    save_prognostics_model,
    validate_history,
)

__all__ = [
    "DEFAULT_PROGNOSTICS_MODEL",
    "HISTORY_COLUMNS",
    "HORIZON_FACTOR",
    "METHODS",
    "HistoryError",
    "Prognosis",
    "PrognosticsModel",
    "fleet_histories",
    "load_prognostics_model",
    "prognose",
    "read_history",
    "save_prognostics_model",
    "validate_history",
]
