"""Histories of a whole fleet: a life recipe's snapshots diagnosed in batches, one history row
per age (the diagnoses of its recordings combined), with the labels a prognosis is scored
against."""

from __future__ import annotations

import numpy as np
import pandas as pd

from prsm_health.actuator.design_files import design_fingerprint
from prsm_health.core.errors import (
    PRSMHealthError,
)

from .history import DUTY_COLUMNS, Z90


def fleet_histories(
    dataset,
    bundle=None,
    *,
    units=None,
    until_age: float | None = None,
    progress: bool = False,
    batch: int = 32,
    commissioned: bool = True,
) -> pd.DataFrame:
    """Diagnose the snapshots of a fleet dataset (a life recipe's) in batches: one history row
    per age — where the recipe makes several recordings at one age (``[life] recordings``),
    their diagnoses combined (:func:`combine_recordings`).

    Health-check snapshots are read as a maintainer's would be: each unit commissioned
    (:class:`~prsm_health.diagnostics.clearance_gauge.Commissioning`) by its first check, at
    age 0, with its installed clearance then (the ``clearance_mean_true`` label: the as-built
    clearance its maker measures at acceptance), so its later checks read the clearance
    through its own lost-motion chain.

    Parameters
    ----------
    dataset : str, Path or :class:`~prsm_health.datasets.Dataset`
    bundle : ModelBundle, default the shipped diagnosis model
    units : iterable of int or None
        The units to diagnose (default all).
    until_age : float or None [h]
        Only snapshots at ages ≤ this (what was known then).
    progress : bool
        A progress bar on stderr.
    commissioned : bool
        Commission each unit by its check at age 0 (health-check snapshots only; False: every
        check read with the gauge's nominal chain).

    Returns
    -------
    DataFrame
        ``unit_id``, :data:`HISTORY_COLUMNS`, ``design`` (its name), ``design_fingerprint``
        (which design: :func:`~prsm_health.actuator.design_files.design_fingerprint`),
        ``fault_class``, and the labels a
        prognosis is scored against: ``split``, ``rul_hours``, ``failure_age_hours``,
        ``failure_mode``, ``clearance_mean_true`` — and the duty log (``duty_hours``,
        ``duty_load``) where the dataset records it, ``recordings`` (diagnoses combined into
        the row); sorted by unit and age.

    Raises
    ------
    PRSMHealthError
        A dataset without life labels (not made from a recipe with ``[life]``), or no
        snapshot left after ``units`` and ``until_age``.
    """
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.diagnosis import load_bundle

    dataset = dataset if isinstance(dataset, Dataset) else Dataset(dataset)
    labels = dataset.runs
    if "unit_id" not in labels.columns:
        raise PRSMHealthError(
            f"{dataset.path}: not a fleet dataset (no unit_id label): generate it from a recipe "
            "with a [life] table (docs/prognostics.md)"
        )
    chosen = labels
    if units is not None:
        wanted = {int(u) for u in units}
        unknown = sorted(wanted - set(labels["unit_id"].astype(int)))
        if unknown:
            raise PRSMHealthError(
                f"{dataset.path}: no unit {unknown[0]} (units 0–{int(labels['unit_id'].max())})"
            )
        chosen = chosen[chosen["unit_id"].astype(int).isin(wanted)]
    if until_age is not None:
        chosen = chosen[chosen["age_hours"] <= until_age]
    if chosen.empty:
        raise PRSMHealthError(
            f"{dataset.path}: no snapshot at or before {until_age:g} h for the chosen unit"
        )
    chosen = chosen.sort_values(["unit_id", "age_hours"])
    bundle = bundle or load_bundle()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(chosen), desc="diagnosing snapshots", unit="run")
    diagnoses = []
    for _, unit in chosen.groupby("unit_id", sort=True):
        diagnoses.extend(_diagnose_unit(dataset, unit, bundle, batch, commissioned, bar))
    if bar is not None:
        bar.close()
    out = pd.DataFrame(
        {
            "unit_id": chosen["unit_id"].astype(int).to_numpy(),
            "age_hours": chosen["age_hours"].to_numpy(float),
            "clearance": [d.clearance["estimate"] for d in diagnoses],
            "clearance_lower": [d.clearance["lower"] for d in diagnoses],
            "clearance_upper": [d.clearance["upper"] for d in diagnoses],
            "design": chosen["design"].to_numpy(),
            "design_fingerprint": _fingerprints(dataset, chosen),
            "fault_class": [d.fault_class for d in diagnoses],
        }
    )
    for label in ("split", "rul_hours", "failure_age_hours", "failure_mode", "clearance_mean_true"):
        out[label] = chosen[label].to_numpy()
    for column in DUTY_COLUMNS:  # the duty log, in datasets that record it
        if column in chosen.columns:
            out[column] = chosen[column].to_numpy(float)
    return combine_recordings(out)


def _diagnose_unit(dataset, unit: pd.DataFrame, bundle, batch: int, commissioned: bool, bar):
    """The diagnoses of one unit's snapshots (its rows of the labels, sorted by age)."""
    from prsm_health.diagnostics.check_model import is_check
    from prsm_health.diagnostics.clearance_gauge import Commissioning
    from prsm_health.diagnostics.diagnosis import diagnose_runs

    ids = [int(i) for i in unit["run_id"]]
    commissioning = None
    first = dataset.run(ids[0], truth=False)
    ages = unit["age_hours"].to_numpy(float)
    if commissioned and bundle.check is not None and is_check(first) and ages[0] == 0.0:
        built = diagnose_runs([first], bundle)[0]
        as_built = float(unit["clearance_mean_true"].iloc[0])
        commissioning = Commissioning.from_indicators([built.indicators], as_built)
    out = []
    for start in range(0, len(ids), batch):
        runs = [
            first if i == ids[0] else dataset.run(i, truth=False)
            for i in ids[start : start + batch]
        ]
        out.extend(diagnose_runs(runs, bundle, commissioning=commissioning))
        if bar is not None:
            bar.update(len(runs))
    return out


def combine_recordings(table: pd.DataFrame) -> pd.DataFrame:
    """One row per (``unit_id``, ``age_hours``): the diagnoses of n recordings at one age
    combined — the clearance their mean, each side of the 90 % interval the root mean square
    of theirs divided by √n (the recordings' errors taken as independent: each has its own
    recording conditions and sensor noise; the fleet's window errors at successive ages
    correlate by 0.04, docs/prognostics.md), the fault class the most frequent one; every
    other column the first row's (the same at one age). Adds ``recordings`` (n)."""
    keys = ["unit_id", "age_hours"]
    grouped = table.groupby(keys, sort=True)
    out = grouped.first()
    n = grouped.size()
    value = grouped["clearance"].mean()
    below = (table["clearance"] - table["clearance_lower"]) ** 2
    above = (table["clearance_upper"] - table["clearance"]) ** 2
    sides = pd.DataFrame({"below": below, "above": above, **{k: table[k] for k in keys}})
    rms = np.sqrt(sides.groupby(keys, sort=True)[["below", "above"]].mean())
    out["clearance"] = value
    out["clearance_lower"] = value - rms["below"] / np.sqrt(n)
    out["clearance_upper"] = value + rms["above"] / np.sqrt(n)
    if "fault_class" in table.columns:
        out["fault_class"] = grouped["fault_class"].agg(lambda c: c.value_counts().index[0])
    out["recordings"] = n
    return out.reset_index()[[*table.columns, "recordings"]]


def _fingerprints(dataset, chosen: pd.DataFrame):
    """The runs' ``design_fingerprint`` labels; for a dataset generated before runs carried
    them, its design's (every run of a recipe is of the recipe's design)."""
    if "design_fingerprint" in chosen.columns:
        return chosen["design_fingerprint"].to_numpy()
    design = dataset.design
    return None if design is None else design_fingerprint(design)


def simulated_histories(
    lives, snapshots: int, noise: float, rng, *, min_half_width: float = 0.0
) -> pd.DataFrame:
    """Histories of life-model units observed without the dynamics: each unit's true mean
    clearance at ``snapshots`` ages (``UnitLife.snapshot_ages``) plus a Gaussian diagnosis
    error of ``noise`` [m] drawn from ``rng`` unit after unit, its 90 % interval
    ±max(Z90·noise, ``min_half_width``) (Z90 = 1.6449, the history's own); with the truth and duty columns of the snapshots'
    labels. What limits a RUL, seen apart from the diagnosis (sensitivity tables, studies).

    Parameters
    ----------
    lives : sequence of :class:`~prsm_health.physics.life.UnitLife`
    snapshots : int
    noise : float [m]
    rng : numpy.random.Generator
    min_half_width : float [m]
        Narrowest interval half-width (a noise-free history still gets an interval).
    """
    frames = []
    half = max(Z90 * noise, min_half_width)
    for unit in lives:
        ages = unit.snapshot_ages(snapshots)
        true = unit.clearance(ages)
        value = true + rng.normal(0.0, noise, len(ages))
        labels = [unit.labels(age) for age in ages]
        frames.append(
            pd.DataFrame(
                {
                    "unit_id": unit.unit_id,
                    "age_hours": ages,
                    "clearance": value,
                    "clearance_lower": value - half,
                    "clearance_upper": value + half,
                    "clearance_mean_true": true,
                    "failure_age_hours": unit.failure_age,
                    **{c: [label[c] for label in labels] for c in DUTY_COLUMNS},
                }
            )
        )
    return pd.concat(frames, ignore_index=True)
