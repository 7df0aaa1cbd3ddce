"""Datasets: recipes, generation (local pool or Dask), the Parquet dataset store and reader,
and the importer of a rig's own recordings (docs/formats.md, docs/import.md).

Import from here, not from the modules: their split is this package's business.
"""

from .dataset import (
    Dataset,
    FaultThresholds,
    Recipe,
    RecipeError,
    dataset_throughput,
    generate,
    load_recipe,
)

__all__ = [
    "Dataset",
    "FaultThresholds",
    "Recipe",
    "RecipeError",
    "dataset_throughput",
    "generate",
    "load_recipe",
]
