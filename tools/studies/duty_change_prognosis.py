"""Does a RUL follow a unit whose duty changes mid-life? (docs/prognostics.md, "A duty change")

Units of the shipped fleet recipe (datasets/fleet-check.toml ``[life]``) whose loads double at
mid-life (``--change`` of the unit's unchanged life; ``[life.duty] change_age``,
``change_load = 2``): their life simulations (:func:`prsm_health.physics.life.fleet_lives`, no
dynamics) checked at ``--snapshots`` ages over their (changed) lives with a Gaussian diagnosis
error of ``--noise`` — by default the commissioned health check's, ≈ 0.35 µm late in life —
(interval ±1.645σ) and their duty log (``duty_hours``, ``duty_load``). Training fleet: units of the same recipe without the change; the three methods
of :class:`~prsm_health.prognostics.RULModel` (the physics part fitted as
``fit_prognostics_model`` fits it). For each test unit and each snapshot after the change: is
the median RUL within ±α·true RUL (α = 0.2)? Printed per method: the share within α at the
k-th snapshot after the change (k = 1 … 5) and over all after it.

    python tools/studies/duty_change_prognosis.py [--units 6] [--noise 0.35e-6] [--snapshots 20]
        [--change 0.5] [--seed 31]

≈ 1 min on one core.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
import pandas as pd

from prsm_health.actuator.design import preset
from prsm_health.datasets import load_recipe
from prsm_health.physics.life import fleet_lives, unit_life
from prsm_health.prognostics import HISTORY_COLUMNS, RULModel, simulated_histories
from prsm_health.prognostics.ageing_model import rate_tables
from prsm_health.prognostics.ageing_rul import AgeingRUL

ALPHA = 0.2


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--units", type=int, default=6)
    parser.add_argument("--noise", type=float, default=0.35e-6)
    parser.add_argument("--snapshots", type=int, default=20)
    parser.add_argument("--change", type=float, default=0.5, help="share of the unchanged life")
    parser.add_argument("--seed", type=int, default=31)
    args = parser.parse_args(argv)
    recipe = load_recipe("datasets/fleet-check.toml")
    snapshots = args.snapshots
    design = preset(recipe.design)
    spec = replace(recipe.life_spec, units=14)
    train = simulated_histories(
        fleet_lives(design, spec, args.seed), snapshots, args.noise, np.random.default_rng(1)
    )
    failure = train.groupby("unit_id")["failure_age_hours"].first().to_dict()
    model = RULModel(threshold=spec.failure_clearance).fit(
        train[["unit_id", *HISTORY_COLUMNS]], failure
    )
    model.ageing_ = AgeingRUL.fit(rate_tables(design, spec), spec, train, horizon=model.horizon_)
    # test units: their own seed; the loads double at --change of the unit's unchanged life
    plain = fleet_lives(design, replace(spec, units=args.units), args.seed + 1)
    changed = []
    for unit in plain:
        duty = replace(spec.duty, change_age=args.change * unit.failure_age, change_load=2.0)
        changed.append(unit_life(design, replace(spec, duty=duty), unit.unit_id, args.seed + 1))
    test = simulated_histories(changed, snapshots, args.noise, np.random.default_rng(2))
    rows = []
    for unit in changed:
        h = test[test["unit_id"] == unit.unit_id].reset_index(drop=True)
        after = np.flatnonzero(h["age_hours"].to_numpy() >= unit.change_age)
        for method in ("degradation", "similarity", "physics"):
            prognoses = model.predict_prefixes(h, method=method)
            for k, p in enumerate(prognoses, start=2):
                age = h["age_hours"].iloc[k - 1]
                if k - 1 < after[0] or age >= unit.failure_age:
                    continue
                true = unit.failure_age - age
                rows.append(
                    {
                        "unit": unit.unit_id,
                        "method": method,
                        "since_change": int(k - 1 - after[0] + 1),
                        "within": abs(p.rul_hours["estimate"] - true) <= ALPHA * true,
                    }
                )
    table = pd.DataFrame(rows)
    print(
        f"{args.units} units, loads doubled at {args.change:.0%} of the unchanged life, "
        f"{snapshots} checks per life, diagnosis σ = {args.noise:g} m; share within ±20 % of "
        "the true RUL, by check after the change:"
    )
    print("| method | " + " | ".join(f"check {k}" for k in range(1, 6)) + " | all after |")
    print("|---|" + "---|" * 6)
    for method, part in table.groupby("method", sort=False):
        cells = [part[part["since_change"] == k]["within"].mean() for k in range(1, 6)]
        print(
            f"| {method} | "
            + " | ".join(f"{c:.2f}" for c in cells)
            + f" | {part['within'].mean():.2f} |"
        )


if __name__ == "__main__":
    main()
