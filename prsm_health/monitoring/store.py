"""The one interface every store of asset histories offers (:class:`AssetStore`) and the one
way a history is changed through it (:meth:`AssetStore.update`).

Two backends implement it: :class:`~.file_store.FileAssetStore` (one JSON file per asset, the
CLI's ``--store``) and :class:`~.sqlite_store.HistoryStore` (an SQLite database, the
service's). Both keep a *version* per asset — 0 before anything is stored, +1 with every save —
and save by compare-and-swap: :meth:`AssetStore.save` writes only if the stored version is
still the one the history was loaded at, else :class:`VersionConflict`. :meth:`AssetStore.locked`
holds the asset's lock (between processes), so load → change → save under it never conflicts;
the compare-and-swap guards a save made without it.
"""

from __future__ import annotations

import contextlib
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

from prsm_health.core.errors import PRSMHealthError

from .asset import AssetHistory


class VersionConflict(PRSMHealthError):
    """A save found the asset's stored history at another version than the one it was loaded
    at: another writer changed it in between (load again and redo the change)."""


@dataclass(frozen=True)
class Stored:
    """An asset's history as a store holds it: its ``version`` (0: none stored — ``history``
    is then a new, empty one) and the history."""

    version: int
    history: AssetHistory


class AssetStore(ABC):
    """Asset histories by asset id: versioned load, compare-and-swap save, a lock per asset.

    ``extra`` of :meth:`save` carries what a backend stores beside the history in the same
    write (the SQLite store's diagnosis rows and spectra); a backend that keeps nothing beside
    the history refuses it.
    """

    @abstractmethod
    def load(self, asset_id: str) -> Stored:
        """The asset's stored history and its version; a new, empty history at version 0 if
        none is stored. A stored history that cannot be read is a ``PRSMHealthError`` naming
        where it is, never a silent fresh start."""

    @abstractmethod
    def save(self, history: AssetHistory, *, expected_version: int, extra=None) -> int:
        """Write ``history`` if the stored version is ``expected_version`` (else
        :class:`VersionConflict`, nothing written); returns the new version."""

    @abstractmethod
    def locked(self, asset_id: str) -> contextlib.AbstractContextManager:
        """Hold the asset's lock for the block (re-entrant within one thread)."""

    @abstractmethod
    def asset_ids(self) -> list[str]:
        """The ids of the assets stored, sorted."""

    def update(
        self,
        asset_id: str,
        change: Callable[[AssetHistory], tuple[AssetHistory, object]],
        *,
        extra: Callable[[AssetHistory, object], object] | None = None,
    ) -> tuple[int, object]:
        """Load, change and save the asset's history under its lock: ``change(history)``
        returns ``(new history, result)``; the new history is saved unless it is the same
        object (nothing changed), with ``extra(new, result)`` stored beside it. Returns the
        version after it and ``result``. ``change`` raising writes nothing."""
        with self.locked(asset_id):
            stored = self.load(asset_id)
            new, result = change(stored.history)
            version = stored.version
            if new is not stored.history:
                version = self.save(
                    new,
                    expected_version=stored.version,
                    extra=None if extra is None else extra(new, result),
                )
            elif extra is not None:
                self.store_beside(asset_id, extra(new, result))
            return version, result

    def store_beside(self, asset_id: str, extra) -> None:
        """Store ``extra`` with the asset when its history does not change (a recording
        recorded before, sent again): the SQLite store keeps the request's diagnosis rows."""
        if extra is not None:
            raise PRSMHealthError(f"{type(self).__name__} stores nothing beside a history")


__all__ = ["AssetStore", "Stored", "VersionConflict"]
