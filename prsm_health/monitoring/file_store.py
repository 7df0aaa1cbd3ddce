"""Asset histories on disk, one JSON file per asset: the CLI's store (``--store DIR``), an
:class:`~.store.AssetStore`."""

from __future__ import annotations

import contextlib
import json
import re
import threading
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote, unquote

from prsm_health.core.atomic import write_atomic
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.identifiers import ASSET_ID_PATTERN
from prsm_health.core.jsonable import dumps

from .asset import AssetHistory, validate_asset_id
from .store import AssetStore, Stored, VersionConflict


class FileAssetStore(AssetStore):
    """Asset histories in ``directory`` (created on the first save): the file of an asset is
    its id (``:`` percent-encoded) with ``.json``, holding ``AssetHistory.to_json()`` and the
    store's ``version``.

    :meth:`save` writes a temporary file beside it and renames it over the old one, so a
    reader (or a run that was interrupted) finds the old history or the new one, never half of
    one. :meth:`locked` serialises load → record → save of one asset between processes (an
    advisory lock file, where the system has ``fcntl``) and between threads.
    """

    SUFFIX = ".json"

    def __init__(self, directory: str | Path):
        self.directory = Path(directory)
        self._threads = threading.RLock()
        self._held: set[str] = set()  # assets whose lock this store holds now

    def path(self, asset_id: str) -> Path:
        """The file of ``asset_id``."""
        return self.directory / (quote(validate_asset_id(asset_id), safe="") + self.SUFFIX)

    def load(self, asset_id: str) -> Stored:
        """The history of ``asset_id`` and its version; a new, empty one at version 0 if it
        has none.

        Raises
        ------
        PRSMHealthError
            The file exists and cannot be read as a history (truncated, edited, another
            asset's): the message names the file, which is left as it is.
        """
        path = self.path(asset_id)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return Stored(0, AssetHistory(asset_id))
        except (OSError, UnicodeDecodeError) as err:
            raise PRSMHealthError(f"{path}: cannot read the asset history ({err})") from None
        try:
            data = json.loads(text)
            history = AssetHistory.from_json(data)
            # files written before the store kept versions count as version 1
            version = int(data.get("version", 1))
        except (ValueError, KeyError, TypeError, AttributeError) as err:
            reason = err if isinstance(err, PRSMHealthError) else f"{type(err).__name__}: {err}"
            raise PRSMHealthError(
                f"{path}: not a readable asset history ({reason}); it was left as it is — "
                "restore it, or move it aside to start the asset afresh"
            ) from None
        if history.asset_id != asset_id:
            raise PRSMHealthError(
                f"{path}: holds asset {history.asset_id!r}, not {asset_id!r} (asset ids that "
                "differ only in case share a file on a case-insensitive file system)"
            )
        return Stored(version, history)

    def save(self, history: AssetHistory, *, expected_version: int, extra=None) -> int:
        """Write ``history`` atomically (temporary file, fsync, rename) if its stored version
        is ``expected_version``; the new version."""
        if extra is not None:
            raise PRSMHealthError("the file store keeps the asset history only (no extra rows)")
        with self.locked(history.asset_id):
            stored = self.load(history.asset_id).version
            if stored != expected_version:
                raise VersionConflict(
                    f"{self.path(history.asset_id)}: asset {history.asset_id!r} is at version "
                    f"{stored}, not {expected_version}: another run changed it; load it again"
                )
            data = {"version": expected_version + 1, **history.to_json()}
            try:
                self.directory.mkdir(parents=True, exist_ok=True)
            except OSError as err:
                raise PRSMHealthError(
                    f"{self.directory}: cannot write asset histories there ({err.strerror})"
                ) from None
            write_atomic(
                self.path(history.asset_id),
                dumps(data, indent=1).encode("utf-8"),
                "the asset history",
            )
            return expected_version + 1

    def asset_ids(self) -> list[str]:
        """The ids of the assets stored, sorted."""
        if not self.directory.is_dir():
            return []
        found = []
        for p in self.directory.iterdir():
            if p.suffix != self.SUFFIX or p.name.startswith("."):
                continue
            asset_id = unquote(p.name[: -len(self.SUFFIX)])
            if re.fullmatch(ASSET_ID_PATTERN, asset_id):
                found.append(asset_id)
        return sorted(found)

    @contextlib.contextmanager
    def locked(self, asset_id: str) -> Iterator[None]:
        """Hold the asset's lock: two processes (or threads) recording the same asset take
        turns instead of one overwriting the other's entry. Re-entrant in one thread (the
        thread lock is held for the block; the file lock is taken once)."""
        with self._threads:
            if asset_id in self._held:
                yield
                return
            handle = self._lock_file(asset_id)
            self._held.add(asset_id)
            try:
                yield
            finally:
                self._held.discard(asset_id)
                if handle is not None:
                    import fcntl

                    fcntl.flock(handle, fcntl.LOCK_UN)
                    handle.close()

    def _lock_file(self, asset_id: str):
        """The asset's advisory lock file, locked; None where the system has no ``fcntl``
        (Windows: the compare-and-swap of :meth:`save` still holds)."""
        try:
            import fcntl
        except ImportError:
            return None
        path = self.path(asset_id)
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            handle = open(path.with_name(f".{path.name}.lock"), "a")  # noqa: SIM115
        except OSError as err:
            raise PRSMHealthError(
                f"{self.directory}: cannot write asset histories there ({err.strerror})"
            ) from None
        fcntl.flock(handle, fcntl.LOCK_EX)
        return handle


__all__ = ["FileAssetStore"]
