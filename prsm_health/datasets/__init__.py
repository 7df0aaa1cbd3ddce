"""Datasets: recipes, generation (local pool or Dask), the Parquet dataset store and reader,
and the importer of a rig's own recordings (docs/formats.md, docs/import.md).

- :mod:`.recipe` — :class:`Recipe` (sweeps, splits, thresholds, life recipes) and :class:`RunSpec`
- :mod:`.store` — :class:`DatasetStore`: the dataset's files on a local disk or an object store
- :mod:`.generation` — :func:`generate`: parallel, deterministic, resumable
- :mod:`.reader` — :class:`Dataset`: a generated or imported dataset read back
- :mod:`.importer` — a rig's CSV/Parquet/MCAP recordings + labels + column map → a dataset
"""

from prsm_health.actuator.faults import FaultThresholds
from prsm_health.core.errors import RecipeError

from .generation import GenerationReport, dataset_throughput, generate, run_batch
from .reader import Dataset
from .recipe import Recipe, RunSpec, load_recipe

__all__ = [
    "Dataset",
    "FaultThresholds",
    "GenerationReport",
    "Recipe",
    "RecipeError",
    "RunSpec",
    "dataset_throughput",
    "generate",
    "load_recipe",
    "run_batch",
]
