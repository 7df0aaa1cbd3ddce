"""A unit's history of diagnoses: the table a prognosis reads (its columns, reading a file,
validating it with one-line errors naming the row)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from prsm_health.actuator.design import PRESETS
from prsm_health.actuator.design_files import design_fingerprint, labelled_same_design
from prsm_health.core.errors import (
    ParameterError,
    PRSMHealthError,
)

#: z of the 95 % normal quantile: a diagnosis' 90 % interval is +-1.645 standard deviations.
Z90 = 1.6448536269514722

#: Required columns of a history: age [h], clearance estimate and its 90 % interval [m].
HISTORY_COLUMNS = ("age_hours", "clearance", "clearance_lower", "clearance_upper")
#: Optional columns a history may carry (checked when present).
OPTIONAL_COLUMNS = (
    "design",
    "design_fingerprint",
    "fault_class",
    "unit_id",
    "duty_hours",
    "duty_load",
)


class HistoryError(ParameterError):
    """A history that cannot be used for a prognosis.

    A :class:`~prsm_health.core.errors.ParameterError` whose one-line message names the problem
    and, where there is one, the offending row (rows counted from 0 in table order).
    """

    def __init__(self, message: str, field: str = "history", value=None):
        self.field = field
        self.value = value
        self.allowed = message
        Exception.__init__(self, message)


def _show(value) -> str:
    """A table cell for a message: numbers plain (``nan``, ``1e-05``), anything else repr."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return f"{value:g}"
    return repr(value)


def one_line(text) -> str:
    lines = str(text).strip().splitlines()
    return lines[0] if lines else type(text).__name__


# --------------------------------------------------------------------------------------------
# Histories
# --------------------------------------------------------------------------------------------


def read_history(path) -> pd.DataFrame:
    """Read a history table from a CSV or Parquet file (chosen by the suffix).

    Parameters
    ----------
    path : str or Path
        ``*.csv`` or ``*.parquet`` / ``*.pq`` file with the columns :data:`HISTORY_COLUMNS`
        (``age_hours`` [h], ``clearance``, ``clearance_lower``, ``clearance_upper`` [m]) and
        optionally ``design``, ``design_fingerprint``, ``fault_class``, ``unit_id``.

    Returns
    -------
    pandas.DataFrame
        The table as read (not yet validated: :func:`validate_history` does that).

    Raises
    ------
    PRSMHealthError
        A missing or unreadable file, an unknown suffix (one line naming the file).
    HistoryError
        A required column is missing (the message names the file and the columns).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet", ".pq"):
        raise PRSMHealthError(
            f"{path}: cannot read history (unknown suffix {suffix!r}; use .csv or .parquet)"
        )
    try:
        table = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    except FileNotFoundError:
        raise PRSMHealthError(f"{path}: cannot read history (no such file)") from None
    except (OSError, ValueError, UnicodeDecodeError, ImportError) as err:
        raise PRSMHealthError(f"{path}: cannot read history ({one_line(err)})") from None
    missing = [c for c in HISTORY_COLUMNS if c not in table.columns]
    if missing:
        raise HistoryError(
            f"{path}: history lacks column(s) {', '.join(missing)} "
            f"(required: {', '.join(HISTORY_COLUMNS)})",
            field="history.columns",
            value=missing,
        )
    return table


def validate_history(history: pd.DataFrame, model=None) -> pd.DataFrame:
    """Check a history and return a clean copy (float columns, index 0…n-1, age order).

    Parameters
    ----------
    history : pandas.DataFrame
        Diagnoses of one unit: :data:`HISTORY_COLUMNS` (``age_hours`` [h] strictly increasing
        from row to row, ``clearance``, ``clearance_lower`` <= ``clearance_upper`` [m], all
        finite), optionally ``design`` (one design name), ``design_fingerprint`` (one
        fingerprint), ``unit_id`` (one unit), ``fault_class``.
    model : RULModel, optional
        When given, the history must be of the model's design: its ``design_fingerprint``
        equal to the model's where both have one, else its ``design`` name to the model's.

    Returns
    -------
    pandas.DataFrame
        A copy with the required columns as float64 and a fresh index; other columns kept.

    Raises
    ------
    HistoryError
        (a :class:`~prsm_health.core.errors.ParameterError`) with a one-line message: not a table,
        missing column, fewer than 2 rows, a non-number or non-finite value (column and row),
        a negative age, ages not strictly increasing (the first offending row), a lower bound
        above the upper bound (row), several designs or units, a design other than the model's.
    """
    if not isinstance(history, pd.DataFrame):
        raise HistoryError(
            f"a history must be a pandas DataFrame, not {type(history).__name__}",
            value=type(history).__name__,
        )
    missing = [c for c in HISTORY_COLUMNS if c not in history.columns]
    if missing:
        raise HistoryError(
            f"history lacks column(s) {', '.join(missing)} "
            f"(required: {', '.join(HISTORY_COLUMNS)})",
            field="history.columns",
            value=missing,
        )
    n = len(history)
    if n < 2:
        raise HistoryError(
            f"a prognosis needs at least 2 diagnoses over operating hours; the history has {n}",
            field="history.rows",
            value=n,
        )
    out = history.reset_index(drop=True).copy()
    for column in HISTORY_COLUMNS:
        raw = out[column]
        values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=np.float64, na_value=np.nan)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            raise HistoryError(
                f"history {column} must be a finite number; row {i} has {_show(raw.iloc[i])}",
                field=f"history.{column}",
                value=raw.iloc[i],
            )
        out[column] = values
    ages = out["age_hours"].to_numpy()
    if ages[0] < 0:
        raise HistoryError(
            f"history age_hours must be >= 0; row 0 has {ages[0]:g} h",
            field="history.age_hours",
            value=float(ages[0]),
        )
    steps = np.flatnonzero(np.diff(ages) <= 0)
    if steps.size:
        i = int(steps[0]) + 1
        raise HistoryError(
            f"history age_hours must be strictly increasing; row {i} has {ages[i]:g} h "
            f"after {ages[i - 1]:g} h in row {i - 1}",
            field="history.age_hours",
            value=float(ages[i]),
        )
    lower = out["clearance_lower"].to_numpy()
    upper = out["clearance_upper"].to_numpy()
    crossed = np.flatnonzero(lower > upper)
    if crossed.size:
        i = int(crossed[0])
        raise HistoryError(
            f"history clearance_lower > clearance_upper in row {i} "
            f"({lower[i]:.6g} m > {upper[i]:.6g} m)",
            field="history.clearance_lower",
            value=float(lower[i]),
        )
    _check_design(out, model)
    if "unit_id" in out.columns:
        units = out["unit_id"].dropna().unique()
        if len(units) > 1:
            shown = ", ".join(_show(u) for u in list(units)[:3])
            raise HistoryError(
                f"history mixes units ({shown}{', …' if len(units) > 3 else ''}); "
                "a prognosis is of one unit",
                field="history.unit_id",
                value=len(units),
            )
    return out


def model_design(name: str, fingerprint: str | None) -> tuple[str, str | None]:
    """A model's design as (name, fingerprint): a model file from before fingerprints names
    only its design; a preset name then stands for that preset's fingerprint."""
    if fingerprint is None and name in PRESETS:
        fingerprint = design_fingerprint(name)
    return name, fingerprint


def _one_design(history: pd.DataFrame, column: str) -> str | None:
    """The one value of a design column (None: absent or empty); several raise."""
    if column not in history.columns:
        return None
    values = sorted({str(v) for v in history[column].dropna()})
    if len(values) > 1:
        raise HistoryError(
            f"history mixes designs ({column} {', '.join(repr(v) for v in values)}); "
            "a prognosis is of one unit of one design",
            field=f"history.{column}",
            value=values,
        )
    return values[0] if values else None


def _check_design(history: pd.DataFrame, model) -> None:
    """One design in the history, and the model's: by fingerprint where the history and the
    model both have one (the name is for people and may be reused), else by name."""
    name = _one_design(history, "design")
    fingerprint = _one_design(history, "design_fingerprint")
    if model is None:
        return
    model_name, model_fingerprint = model.design_id
    if labelled_same_design(name, fingerprint, model_name, model_fingerprint) is not False:
        return
    if fingerprint is not None and model_fingerprint is not None:
        shown = f"{name!r} " if name is not None else ""
        raise HistoryError(
            f"history is of design {shown}(fingerprint {fingerprint}), the prognostics "
            f"model of {model_name!r} (fingerprint {model_fingerprint}): another design",
            field="history.design_fingerprint",
            value=fingerprint,
        )
    raise HistoryError(
        f"history is of design {name!r}, the prognostics model of {model_name!r}",
        field="history.design",
        value=name,
    )


#: The duty log's columns a history may carry (docs/prognostics.md): the unit's duty hours
#: (operating hours × its usage intensity, cumulative) and its load factor (× the duty the
#: prognostics model was built for) at each diagnosis.
DUTY_COLUMNS = ("duty_hours", "duty_load")


def duty_arrays(history: pd.DataFrame) -> dict:
    """The duty log of a history as the physics model's inputs over the interval before each
    diagnosis: ``usage_rate`` (duty hours per operating hour) and ``load``; absent columns are
    None. Refuses non-finite or negative values and duty hours that run backwards."""
    out = {"load": None, "usage_rate": None}
    t = history["age_hours"].to_numpy(dtype=np.float64)
    for column in DUTY_COLUMNS:
        if column not in history.columns:
            continue
        values = pd.to_numeric(history[column], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(values) | (values < 0))
        if bad.size:
            raise HistoryError(
                f"row {int(bad[0])}: {column} {_show(history[column].iloc[bad[0]])} is not a "
                "finite value >= 0",
                f"history.{column}",
                history[column].iloc[bad[0]],
            )
        if column == "duty_load":
            out["load"] = values
            continue
        steps = np.diff(np.concatenate([[0.0], values]))
        back = np.flatnonzero(steps < 0)
        if back.size:
            raise HistoryError(
                f"row {int(back[0])}: duty_hours {values[back[0]]:.6g} h is below the row "
                "before it (duty hours only grow)",
                "history.duty_hours",
                float(values[back[0]]),
            )
        spans = np.diff(np.concatenate([[0.0], t]))
        with np.errstate(divide="ignore", invalid="ignore"):
            out["usage_rate"] = np.where(spans > 0, steps / spans, np.nan)
    return out


def history_arrays(history: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ages [h], clearance estimates [m] and measurement standard deviations [m]."""
    t = history["age_hours"].to_numpy(dtype=np.float64)
    value = history["clearance"].to_numpy(dtype=np.float64)
    half_width = 0.5 * (
        history["clearance_upper"].to_numpy(dtype=np.float64)
        - history["clearance_lower"].to_numpy(dtype=np.float64)
    )
    return t, value, half_width / Z90


def history_of_readings(rows):
    """The history table a prognosis is made from (:func:`prsm_health.prognostics.prognose`),
    from an asset's stored readings — rows with ``operating_hours``, ``clearance_estimate``,
    ``clearance_lower``, ``clearance_upper``, ``fault_class`` and ``design`` attributes (the
    service's :meth:`prsm_health.monitoring.sqlite_store.HistoryStore.operating_history`) —
    and notes on the rows left out.

    ``age_hours`` is the stored operating hours; ``clearance``, ``clearance_lower``,
    ``clearance_upper`` [m] the stored estimate and 90 % interval; ``design`` the diagnosing
    model's; ``fault_class``. Of several diagnoses at the same operating hours only the latest
    received is kept (a repeated reading replaces the earlier one); diagnoses without a
    clearance estimate or interval (a model without a clearance estimator) carry nothing to
    predict from and are left out, with a note.

    Returns
    -------
    (pandas.DataFrame, list of str)
        The table, oldest first (operating hours strictly increasing), and the notes.
    """
    import pandas as pd

    usable = [
        r for r in rows if None not in (r.clearance_estimate, r.clearance_lower, r.clearance_upper)
    ]
    notes = []
    if len(usable) < len(rows):
        notes.append(
            f"{len(rows) - len(usable)} stored diagnosis(es) with operating hours but without a "
            "clearance estimate and interval were left out"
        )
    stored = {  # the history's column → the stored row's field
        "age_hours": "operating_hours",
        "clearance": "clearance_estimate",
        "clearance_lower": "clearance_lower",
        "clearance_upper": "clearance_upper",
        "fault_class": "fault_class",
        "design": "design",
    }
    table = pd.DataFrame(
        {column: [getattr(r, name) for r in usable] for column, name in stored.items()},
        columns=[*HISTORY_COLUMNS, "fault_class", "design"],
    )
    table = table.drop_duplicates("age_hours", keep="last").reset_index(drop=True)
    return table, notes
