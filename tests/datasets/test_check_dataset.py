"""A recipe of health checks: each run's phase column and phases survive the dataset store."""

import numpy as np

from prsm_health.core.channels import CHECK_PHASE
from prsm_health.datasets import Dataset, Recipe, generate

#: Two short phases (0.07 s simulated in all: ramps 0.01 s, phases 0.02 s, the ramp to rest).
CHECK = {
    "name": "tiny",
    "phases": [
        {"name": "free", "speed": 50.0, "load": 0.0, "duration": 0.02, "ramp_time": 0.01},
        {"name": "loaded", "speed": -50.0, "load": "10 % C_a", "duration": 0.02, "ramp_time": 0.01},
    ],
}
RECIPE = {
    "name": "checks",
    "design": "paper01",
    "instrumentation": "flight-ema",
    "duration": 0.07,  # the check's own length
    "sample_rate": 20000,
    "seed": 1,
    "test_fraction": 0.5,
    "dtype": "float32",
    "sweep": {"mode": "grid", "clearance": [10e-6, 20e-6]},
    "profile": {"check": CHECK},
}


def test_phases_are_read_back_from_the_dataset(tmp_path):
    import pyarrow.parquet as pq

    generate(Recipe.from_dict(RECIPE), tmp_path / "ds", workers=1, progress=False)
    ds = Dataset(tmp_path / "ds")
    assert set(ds.runs["check"]) == {"tiny"}
    for run_id in ds.runs["run_id"]:
        run = ds.run(int(run_id))
        assert run.check_phase.dtype == np.int16  # not cast to the recipe's float32
        assert set(run.check_phase) == {-1, 0, 1}
        assert [p.name for p in run.check.phases] == ["free", "loaded"]
        assert list(run.phases()) == ["free", "loaded"]
    shards = list((tmp_path / "ds" / "signals").glob("*.parquet"))
    assert shards
    for shard in shards:  # read independently of the package
        assert str(pq.read_schema(shard).field(CHECK_PHASE).type) == "int16"
