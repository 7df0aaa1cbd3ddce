"""A fleet's histories: several recordings at one age combined into one history row."""

import numpy as np
import pandas as pd
import pytest

from prsm_health.prognostics.fleet import combine_recordings


def test_recordings_at_one_age_combine_to_their_mean_with_a_narrower_interval():
    table = pd.DataFrame(
        {
            "unit_id": [0, 0, 0, 0, 1],
            "age_hours": [0.0, 10.0, 10.0, 10.0, 0.0],
            "clearance": [5e-6, 9e-6, 11e-6, 13e-6, 4e-6],
            # asymmetric intervals: 2 µm below, 4 µm above each estimate
            "clearance_lower": [3e-6, 7e-6, 9e-6, 11e-6, 2e-6],
            "clearance_upper": [9e-6, 13e-6, 15e-6, 17e-6, 8e-6],
            "fault_class": ["healthy", "wear", "healthy", "wear", "healthy"],
            "failure_age_hours": [100.0, 100.0, 100.0, 100.0, 80.0],
        }
    )
    out = combine_recordings(table)
    assert list(out.columns) == [*table.columns, "recordings"]
    assert out["recordings"].tolist() == [1, 3, 1]
    row = out[(out["unit_id"] == 0) & (out["age_hours"] == 10.0)].iloc[0]
    assert row["clearance"] == pytest.approx(11e-6)
    # each side of the interval shrinks by √3: independent errors averaged
    assert row["clearance"] - row["clearance_lower"] == pytest.approx(2e-6 / np.sqrt(3))
    assert row["clearance_upper"] - row["clearance"] == pytest.approx(4e-6 / np.sqrt(3))
    assert row["fault_class"] == "wear"
    # a single recording is left as it was
    single = out[out["unit_id"] == 1].iloc[0]
    assert single["clearance_lower"] == 2e-6 and single["clearance_upper"] == 8e-6


CHECK_FLEET = {
    "name": "check-fleet",
    "design": "paper01",
    "instrumentation": "flight-ema",
    "duration": 2.62,
    "sample_rate": 20000,
    "seed": 5,
    "test_fraction": 0.5,
    "profile": {"check": "health-check"},
    "options": {"contact_law": "hertz"},
    "sweep": {"mode": "random", "temperature": [293.15, 313.15]},
    "life": {"units": 2, "snapshots": 2},
}


@pytest.mark.slow
def test_check_snapshots_are_read_commissioned_by_each_units_first_check(tmp_path):
    # Two units, checks at age 0 and at half life: each unit's check at age 0 and its installed
    # clearance then commission its gauge, so that check reads its own as-built value back (by
    # construction, to rounding) and the later one reads through the unit's own chain — within
    # 2 µm of the truth (the commissioned error sd is 0.3–0.5 µm on fresh units, docs/
    # diagnostics.md: > 4σ, so a pass does not hang on one trajectory).
    from prsm_health.datasets import Dataset, Recipe, generate
    from prsm_health.prognostics import fleet_histories

    generate(Recipe.from_dict(CHECK_FLEET), tmp_path / "fleet", workers=1)
    dataset = Dataset(tmp_path / "fleet")
    table = fleet_histories(dataset)
    nominal = fleet_histories(dataset, commissioned=False)
    assert len(table) == 4 and table["recordings"].eq(1).all()
    error = (table["clearance"] - table["clearance_mean_true"]).abs()
    first = table["age_hours"] == 0.0
    assert (error[first] < 0.05e-6).all()
    assert (error[~first] < 2e-6).all()
    # commissioning narrows the interval the prognosis reads as the measurement's noise
    width = table["clearance_upper"] - table["clearance_lower"]
    assert (width < nominal["clearance_upper"] - nominal["clearance_lower"]).all()
