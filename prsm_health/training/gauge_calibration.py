"""The clearance gauge calibrated on a dataset of health checks: the conformal factors of its
90 % interval, not commissioned and commissioned, from the checks' realised clearances
(:mod:`prsm_health.diagnostics.clearance_gauge`).

The gauge needs no training — its reading is the actuator's physics — but its interval is an
error budget of documented ranges, whose spread over real builds is calibrated: split
conformal (Angelopoulos & Bates 2021, §2) on the scores |reading − realised mean clearance| /
budget sd of the training units' checks; the held-out units' checks say how it covers.
Commissioned: each unit's baseline checks (the same units new, their as-built clearance the
realised one) fix its offset (:class:`~prsm_health.diagnostics.clearance_gauge.Commissioning`).
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.diagnostics.clearance_gauge import Commissioning
from prsm_health.diagnostics.estimators import conformal_quantile

#: The interval's level.
LEVEL = 0.9
#: The labels of a run's realised half-clearances, screw and nut sides (mean over the rollers).
REALISED = ("clearance_screw_realised_mean", "clearance_nut_realised_mean")


def conformal_factor(scores, level: float = LEVEL) -> float:
    """The split-conformal quantile of the finite ``scores`` at ``level``
    (:func:`~prsm_health.diagnostics.estimators.conformal_quantile`; the largest when they are
    too few for the level); NaN without any."""
    finite = [s for s in scores if math.isfinite(s)]
    return conformal_quantile(finite, 1.0 - level)[0] if finite else math.nan


def realised_clearance(table) -> np.ndarray:
    """The realised mean half-clearance [m] of each run (NaN without the labels)."""
    import pandas as pd

    if not all(name in table for name in REALISED):
        return np.full(len(table), np.nan)
    screw, nut = (pd.to_numeric(table[n], errors="coerce").to_numpy(float) for n in REALISED)
    return 0.5 * (screw + nut)


def _commissionings(gauge, base_table) -> dict:
    """Unit id → its :class:`Commissioning` from its baseline checks."""
    real = realised_clearance(base_table)
    out = {}
    for unit, rows in base_table.groupby("unit_id").indices.items():
        readings = [gauge.read(base_table["reversals"].iloc[i]) for i in rows]
        readings = [r.indicators() for r in readings if r is not None]
        as_built = real[rows]
        if readings and np.isfinite(as_built).any():
            out[unit] = Commissioning.from_indicators(readings, float(np.nanmean(as_built)))
    return out


def calibrate_gauge(gauge, table, base_table) -> tuple[dict, dict]:
    """(the check part's ``gauge`` entry, metrics): the conformal factors on the training
    units' checks, the error and coverage on the held-out units'.

    Parameters
    ----------
    gauge : Gauge
        The dataset's actuator (:func:`~prsm_health.diagnostics.clearance_gauge.gauge_for`).
    table, base_table : DataFrame
        The checks and the same units' baselines, with ``reversals`` (each run's
        :attr:`~prsm_health.signals.check_indicators.CheckReading.reversals`), ``unit_id``,
        ``split`` and the realised clearance labels.
    """
    real = realised_clearance(table)
    commissionings = _commissionings(gauge, base_table)
    rows = {"nominal": [], "commissioned": []}
    for i in range(len(table)):
        reversals = table["reversals"].iloc[i]
        unit = table["unit_id"].iloc[i]
        for kind, commissioning in (("nominal", None), ("commissioned", commissionings.get(unit))):
            reading = gauge.read(reversals, commissioning)
            if reading is None or (kind == "commissioned" and commissioning is None):
                continue
            rows[kind].append((i, reading.estimate - real[i], reading.sd))
    train = (table["split"] == "train").to_numpy()
    entry, metrics = {}, {}
    for kind, key in (("nominal", "conformal_scale"), ("commissioned", "commissioned_scale")):
        fit = [abs(e) / sd for i, e, sd in rows[kind] if train[i] and math.isfinite(e)]
        scale = conformal_factor(fit)
        if math.isfinite(scale):
            entry[key] = scale
        held = [(e, sd) for i, e, sd in rows[kind] if not train[i] and math.isfinite(e)]
        errors = np.array([e for e, _ in held])
        metrics[kind] = {
            "conformal_scale": scale,
            "calibration_checks": len(fit),
            "held_out_checks": len(held),
            "held_out_error_mean": float(errors.mean()) if len(held) else None,
            "held_out_error_sd": float(errors.std(ddof=1)) if len(held) > 1 else None,
            "held_out_coverage": (
                float(np.mean([abs(e) <= scale * sd for e, sd in held]))
                if held and math.isfinite(scale)
                else None
            ),
        }
    return entry, metrics
