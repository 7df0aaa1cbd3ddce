"""Monitoring: each asset (one unit, recorded again and again) judged against its own
baseline, with the evidence of its recordings accumulated and a change statistic, kept in a
store (files for the CLI, SQLite for the service) and changed by the same steps everywhere.

- :mod:`.asset`: an asset's history (:class:`AssetHistory`, :class:`AssetEntry`)
- :mod:`.evidence`: class evidence and the change statistic (:class:`Evidence`, :class:`Cusum`)
- :mod:`.store`: the store interface (:class:`AssetStore`); :mod:`.file_store`,
  :mod:`.sqlite_store` (+ :mod:`.sqlite_assets`): its two backends
- :mod:`.steps`: baseline → diagnose → record (:func:`diagnose_asset`)
"""

from .asset import (
    BASELINE_RECORDINGS,
    HEALTHY,
    AssetEntry,
    AssetHistory,
    bundle_priors,
    names_a_fault,
    validate_asset_id,
)
from .evidence import Cusum, Evidence
from .file_store import FileAssetStore
from .steps import (
    asset_baseline,
    asset_reference,
    commission,
    diagnose_asset,
    record_diagnosis,
)
from .store import AssetStore, Stored, VersionConflict

__all__ = [
    "BASELINE_RECORDINGS",
    "HEALTHY",
    "AssetEntry",
    "AssetHistory",
    "AssetStore",
    "Cusum",
    "Evidence",
    "FileAssetStore",
    "Stored",
    "VersionConflict",
    "asset_baseline",
    "asset_reference",
    "bundle_priors",
    "commission",
    "diagnose_asset",
    "names_a_fault",
    "record_diagnosis",
    "validate_asset_id",
]
