"""Where a dataset lives: a local directory or an fsspec URL (``s3://bucket/prefix``, ``gs://…``,
``memory://…``, ``file://…``). Every file operation goes through :class:`DatasetStore`. On an object
store a file is staged on the writer's local disk and uploaded in one put, which the store makes
visible only once complete, so workers that share no filesystem write their shards straight to
the store; locally a file is written under a temporary name and renamed, so a reader never sees
half of it.

Layout (contract, docs/formats.md)::

    DIR/manifest.json        recipe, package version, sample rate, units, counts
    DIR/runs.parquet         one row per run: labels and parameters
    DIR/signals/part-NNNNN.parquet   run_id, time, the measured channels, truth_<name>;
                                     row group = run
    DIR/mcap/run-NNNNNN.mcap         with --format mcap|both
"""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

from prsm_health.core.errors import (
    PRSMHealthError,
    StorageError,
)


class DatasetStore:
    """A dataset directory — a local path or an fsspec URL — and the few file operations that
    generation and :class:`Dataset` need, all through fsspec.

    Paths given to the methods are relative to the dataset directory, with ``/``. Writes are
    staged (:meth:`staged`), so a file appears under its name only once complete. Failures of
    the store itself (unknown protocol, backend not installed, unreachable endpoint, missing
    bucket, denied access) raise :class:`~prsm_health.core.errors.StorageError` naming the location.

    Parameters
    ----------
    location : str or path-like
        A plain local path (used as is, like :class:`pathlib.Path`), or a URL such as
        ``s3://bucket/prefix``. Storage options (endpoint, credentials) come from the
        environment, as the fsspec backend reads them (docs/formats.md, "Object stores").
    """

    def __init__(self, location: str | os.PathLike):
        import fsspec
        from fsspec.implementations.local import LocalFileSystem

        text = os.fspath(location)
        #: What a worker rebuilds the store from: the location exactly as given.
        self.url = text
        if "://" not in text and "::" not in text:
            # A plain path keeps its plain-path meaning (relative to the working directory,
            # no ~ expansion), as before object stores were supported.
            self.fs, self.root = LocalFileSystem(), os.path.abspath(text)
            self.location: Path | str = Path(text)
        else:
            try:
                self.fs, root = fsspec.core.url_to_fs(text)
            except (ValueError, ImportError) as exc:  # unknown protocol, backend not installed
                raise StorageError(f"{text}: unusable dataset location ({exc})") from None
            self.root = root.rstrip("/")
            local = isinstance(self.fs, LocalFileSystem)
            self.location = Path(self.root) if local else text.rstrip("/")
            if not self.root.strip("/"):
                raise StorageError(
                    f"{text}: the URL names no location (write e.g. s3://bucket/datasets/name)"
                )
        self.local = isinstance(self.fs, LocalFileSystem)
        #: memory:// lives in one process: worker processes would each write their own copy.
        self.in_process = "memory" in _protocols(self.fs)
        # fsspec shares one filesystem object per process and URL: its listings may predate
        # what another process wrote since
        self.refresh()

    def __str__(self) -> str:
        return str(self.location)

    def path(self, rel: str = "") -> str:
        """The full path of ``rel`` inside the store's filesystem (what ``self.fs`` takes)."""
        return f"{self.root}/{rel}" if rel else self.root

    def name(self, rel: str) -> str:
        """``rel`` as a user would write it (messages)."""
        if isinstance(self.location, Path):
            return str(self.location / rel)
        return f"{self.location}/{rel}" if rel else self.location

    @contextmanager
    def _io(self, action: str, rel: str):
        try:
            yield
        except PRSMHealthError:
            raise
        except Exception as exc:  # any backend's error type: botocore, aiohttp, gcsfs, OSError
            detail = " ".join(str(exc).split()) or type(exc).__name__
            raise StorageError(
                f"{self.name(rel)}: cannot {action} ({type(exc).__name__}: {detail})"
            ) from exc

    def refresh(self) -> None:
        """Forget cached listings: other processes (workers) write to the store, and an fsspec
        filesystem would otherwise answer from a listing made before they did. All of them:
        s3fs's ``invalidate_cache(path)`` forgets a path and its parents, not its children."""
        with self._io("list", ""):
            self.fs.invalidate_cache()

    def makedirs(self, *rels: str) -> None:
        """Create directories — local ones only: object stores have none, and s3fs would
        create a missing *bucket* instead of reporting it."""
        if self.local:
            for rel in rels:
                with self._io("create directory", rel):
                    self.fs.makedirs(self.path(rel), exist_ok=True)

    def exists(self, rel: str) -> bool:
        with self._io("check", rel):
            return self.fs.exists(self.path(rel))

    def list(self, rel: str) -> list[str]:
        """Names (not paths) in directory ``rel``; empty if it does not exist."""
        self.refresh()
        with self._io("list", rel):
            try:
                paths = self.fs.ls(self.path(rel), detail=False)
            except FileNotFoundError:
                return []
        return [p.rstrip("/").rsplit("/", 1)[-1] for p in paths]

    def read_text(self, rel: str) -> str:
        with self._io("read", rel):
            return self.fs.cat_file(self.path(rel)).decode()

    def open(self, rel: str):
        """A binary file object to read ``rel``."""
        with self._io("read", rel):
            return self.fs.open(self.path(rel), "rb")

    def write_text(self, rel: str, text: str) -> None:
        with self.staged(rel) as tmp:
            Path(tmp).write_text(text)

    def remove(self, rel: str) -> None:
        with self._io("remove", rel):
            self.fs.rm_file(self.path(rel))

    @contextmanager
    def staged(self, rel: str):
        """Yield a local file path to write; when the block ends without error, the file
        becomes ``rel`` at once, else it is dropped.

        Local: a temporary name next to the destination (``NAME.partial-<pid>``), renamed.
        Object store: a local temporary file, uploaded in one put — an object appears only
        when its upload completes, so a killed writer leaves nothing under the name (an
        interrupted multipart upload leaves invisible parts, which the bucket's lifecycle
        rule for incomplete uploads removes).
        """
        if self.local:
            tmp = f"{self.path(rel)}.partial-{os.getpid()}"
            try:
                yield tmp
                # os.replace, not fs.mv: fsspec's local mv is shutil.move, which on Windows
                # copies onto an existing target instead of replacing it atomically
                with self._io("write", rel):
                    os.replace(tmp, self.path(rel))
            finally:
                if os.path.exists(tmp):
                    os.unlink(tmp)
            return
        with tempfile.TemporaryDirectory(prefix="prsm-health-") as folder:
            tmp = os.path.join(folder, rel.rsplit("/", 1)[-1])
            yield tmp
            with self._io("write", rel):
                self.fs.put_file(tmp, self.path(rel))

    def discard_partials(self, *rels: str) -> None:
        """Remove what killed writers left in directories ``rels`` (local stores: staged
        files under ``.partial-`` names; object stores stage on the writer's disk)."""
        if self.local:
            for rel in rels:
                for name in self.list(rel):
                    if ".partial-" in name:
                        self.remove(f"{rel}/{name}")


def _protocols(fs) -> tuple[str, ...]:
    protocol = fs.protocol
    return (protocol,) if isinstance(protocol, str) else tuple(protocol)


# ---------------------------------------------------------------------- generation
def shard_name(batch: int) -> str:
    return f"signals/part-{batch:05d}.parquet"


def mcap_name(run_id: int) -> str:
    return f"mcap/run-{run_id:06d}.mcap"


def dataset_counts(frame) -> dict:
    """The manifest's ``counts`` of a labels table: runs, train, test, runs per fault class."""
    classes = frame["fault_class"].value_counts().sort_index() if "fault_class" in frame else {}
    return {
        "runs": len(frame),
        "train": int((frame["split"] == "train").sum()),
        "test": int((frame["split"] == "test").sum()),
        "fault_class": {k: int(v) for k, v in dict(classes).items()},
    }
