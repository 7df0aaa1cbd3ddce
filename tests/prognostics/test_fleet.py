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
