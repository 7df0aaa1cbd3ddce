"""The recirculating PRSM's faults against healthy units at the same speed and load, through the
whole path: a scenario (the drive train's linkage and payload, the flight-ema sensors), the
feature extraction, each indicator's AUC and a cross-validated classifier's.

    python tools/studies/recirculating_faults.py [--units 24] [--workers 2] [--load "40 % C_a"]
        [--instrumentation flight-ema]

Each unit: the paper03 preset at paper 03's 40π rad/s under a steady load (default 40 % of C_a,
≈ 8.7 kN), thread half-clearance 3–10 µm, its own seed (sensor errors included); 0.17 s
simulated, the first 20 ms left out (the model starts unloaded: its 5 ms load ramp rings the
nut). Four groups of ``--units`` units: healthy, a spall on the nut's loaded flank (one turn of
the ten engaged, the health state's spall: 1–3 mm long, 10–30 µm deep, anywhere on the rollers'
path), a worn cam chamfer (0.1–0.3 mm), a chipped re-entry edge (0.5–1.5 mm long, 0.15 mm deep).

For each fault against the healthy units: every indicator's AUC (> 0.5: higher for the faulty
units) and two-sided AUC (distance from the healthy units' median — for a healthy unit, the
median of the others —: a fault that moves an indicator either way counts), the best five; and the AUC of a random forest (100 trees, as the
shipped fault models' forest candidate) on all the indicators, cross-validated by 5 stratified folds (each unit
in exactly one test fold: the probabilities of units never used in training). Prints JSON.
"""

from __future__ import annotations

import argparse
import json
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np

SPEED = 40 * math.pi
DURATION = 0.17
SETTLED = 0.02  # s left out: the model's start (unloaded, its load ramp)
FAULTS = ("healthy", "nut_spall", "cam_wear", "reentry_edge")


def _faults(kind: str, rng: np.random.Generator) -> list[dict]:
    """The fault tables of one unit of a group, severities drawn."""
    if kind == "nut_spall":
        return [
            {
                "kind": "spall",
                "location": "nut",
                "angle": float(rng.uniform(-math.pi, math.pi)),
                "length": float(rng.uniform(1e-3, 3e-3)),
                "depth": float(rng.uniform(10e-6, 30e-6)),
            }
        ]
    if kind == "cam_wear":
        return [{"kind": "cam_wear", "depth": float(rng.uniform(0.1e-3, 0.3e-3))}]
    if kind == "reentry_edge":
        length = float(rng.uniform(0.5e-3, 1.5e-3))
        return [{"kind": "reentry_edge", "length": length, "depth": 0.15e-3}]
    return []


def unit(job) -> dict:
    """One unit's indicators (one window: the settled part of its run)."""
    from prsm_health.signals.features import extract_features
    from prsm_health.simulation.scenario import Scenario

    kind, seed, load, instrumentation = job
    rng = np.random.default_rng([seed, 45])
    scenario = Scenario.from_dict(
        {
            "design": "paper03",
            "instrumentation": instrumentation,
            "seed": seed,
            "profile": {"speed": SPEED, "duration": DURATION, "load": load},
            "health": {
                "clearance": float(rng.uniform(3e-6, 10e-6)),
                "faults": _faults(kind, rng),
            },
        }
    )
    run = scenario.simulate()
    start = int(round(SETTLED * run.sample_rate))
    row = extract_features(run.slice(start, len(run)).without_truth())
    return {"kind": kind, "seed": seed, "indicators": {k: float(v) for k, v in row.items()}}


def auc(healthy, faulty) -> float:
    """ROC AUC of the faulty against the healthy values: P(faulty > healthy), ties half."""
    from sklearn.metrics import roc_auc_score

    h, f = np.asarray(healthy, float), np.asarray(faulty, float)
    return float(roc_auc_score(np.r_[np.zeros(len(h)), np.ones(len(f))], np.r_[h, f]))


def _forest_auc(healthy: np.ndarray, faulty: np.ndarray, seed: int) -> float:
    """Cross-validated AUC of a random forest on the indicators (5 stratified folds)."""
    from sklearn.ensemble import RandomForestClassifier
    from sklearn.metrics import roc_auc_score
    from sklearn.model_selection import StratifiedKFold, cross_val_predict

    from prsm_health.diagnostics.estimators import FOREST_TREES, FaultClassifier

    x = np.vstack([healthy, faulty])
    y = np.r_[np.zeros(len(healthy)), np.ones(len(faulty))]
    forest = RandomForestClassifier(
        n_estimators=FOREST_TREES,
        max_leaf_nodes=FaultClassifier().max_leaf_nodes,
        random_state=seed,
    )
    folds = StratifiedKFold(n_splits=5, shuffle=True, random_state=seed)
    p = cross_val_predict(forest, x, y, cv=folds, method="predict_proba")[:, 1]
    return float(roc_auc_score(y, p))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=24, help="units per group")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--load", default="40 % C_a", help="steady load (N or a share of C_a)")
    parser.add_argument("--instrumentation", default="flight-ema")
    parser.add_argument("--seed", type=int, default=4500, help="first unit seed")
    args = parser.parse_args()
    jobs = [
        (kind, args.seed + g * args.units + i, args.load, args.instrumentation)
        for g, kind in enumerate(FAULTS)
        for i in range(args.units)
    ]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(unit, jobs))
    names = sorted(
        k
        for k in rows[0]["indicators"]
        if all(math.isfinite(r["indicators"][k]) for r in rows)
        and len({r["indicators"][k] for r in rows}) > 1
    )

    def matrix(kind):
        return np.array([[r["indicators"][k] for k in names] for r in rows if r["kind"] == kind])

    healthy = matrix("healthy")
    comb = [k for k in names if k.startswith("comb_")]
    out = {
        "units_per_group": args.units,
        "load": args.load,
        "instrumentation": args.instrumentation,
        "indicators": len(names),
        "comb_rms_median": {
            kind: float(np.median(matrix(kind)[:, names.index("comb_rms")])) for kind in FAULTS
        }
        if "comb_rms" in names
        else None,
        "comb_sync_share_median": {
            kind: float(np.median(matrix(kind)[:, names.index("comb_sync_share")]))
            for kind in FAULTS
        }
        if "comb_sync_share" in names
        else None,
        "faults": {},
    }
    centre = np.median(healthy, axis=0)
    # a healthy unit's distance from the median of the *other* healthy units (leave one out):
    # its own value does not pull the centre towards it
    others = np.array(
        [np.median(np.delete(healthy, i, axis=0), axis=0) for i in range(len(healthy))]
    )
    healthy_distance = np.abs(healthy - others)
    for kind in FAULTS[1:]:
        faulty = matrix(kind)
        one = {k: auc(healthy[:, j], faulty[:, j]) for j, k in enumerate(names)}
        two = {
            k: auc(healthy_distance[:, j], np.abs(faulty[:, j] - centre[j]))
            for j, k in enumerate(names)
        }
        best = sorted(names, key=lambda k: -max(one[k], 1 - one[k]))[:5]
        out["faults"][kind] = {
            "forest_cv_auc_all_indicators": _forest_auc(healthy, faulty, args.seed),
            "forest_cv_auc_reset_comb": _forest_auc(
                healthy[:, [names.index(k) for k in comb]],
                faulty[:, [names.index(k) for k in comb]],
                args.seed,
            )
            if comb
            else None,
            "best_indicators": {k: {"auc": one[k], "two_sided": two[k]} for k in best},
            "reset_comb": {k: {"auc": one[k], "two_sided": two[k]} for k in comb},
        }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
