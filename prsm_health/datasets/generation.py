"""Generating a dataset from a recipe: parallel (local process pool or a Dask cluster),
deterministic and resumable.

Runs are grouped into fixed batches, so the dataset is identical whatever the worker count or
scheduler. Each batch is written by its worker as one Parquet shard (one row group per run),
atomically; a batch whose shard exists is done. An interrupted generation (Ctrl-C, kill, crash)
therefore resumes on the next call with no duplicate and no missing run, and never shows a
half-written file.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from prsm_health.actuator.faults import FAULT_CLASSES, FAULT_RULE
from prsm_health.core.channels import CHANNEL_NAMES, TRUTH_PREFIX, UNITS
from prsm_health.core.errors import (
    PRSMHealthError,
    require,
)
from prsm_health.core.jsonable import dumps

from .recipe import FORMATS, Recipe, load_recipe
from .store import DatasetStore, dataset_counts, mcap_name, shard_name


def run_batch(recipe_source: dict, batch: int, out_dir: str, formats: str) -> list[dict]:
    """Simulate one batch and write its shard (and MCAP files); returns the batch's labels.

    Runs in a worker process (local pool or Dask worker): takes only plain data, writes its own
    files straight to ``out_dir`` (a local path or a store URL: a Dask worker needs no
    filesystem shared with the client), returns only the small label dicts.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    from prsm_health.io.columns import run_columns, units_schema

    recipe = Recipe.from_dict(recipe_source)
    store = DatasetStore(out_dir)
    specs = recipe.runs()
    dtype = np.float32 if recipe.dtype == "float32" else np.float64
    tables, labels = [], []
    for run_id in recipe.batches()[batch]:
        spec = specs[run_id]
        scenario = spec.scenario()
        run = scenario.simulate()
        label = spec.labels(scenario=scenario, run=run)
        run = replace(run, labels=label)  # the dataset's labels, in its MCAP file too
        if formats in ("mcap", "both"):
            from prsm_health.io.mcap import write_mcap

            with store.staged(mcap_name(run_id)) as tmp:
                write_mcap(run, tmp)
        run_id_column = np.full(len(run), run_id, np.int32)
        tables.append(pa.table({"run_id": run_id_column, **run_columns(run, dtype)}))
        labels.append(label)
    # One shard per batch, one row group per run, the columns and units of a single-run file
    # (io.columns); the labels ride in the footer so a shard and its labels appear together,
    # atomically (staged, see DatasetStore.staged). The runs of a recipe share their
    # instrumentation, hence their columns.
    schema = units_schema(tables[0].schema, recipe.sample_rate)
    schema = schema.with_metadata(
        {
            **schema.metadata,
            b"prsm_health.recipe": recipe.name.encode(),
            b"prsm_health.labels": json.dumps(labels).encode(),
        }
    )
    with store.staged(shard_name(batch)) as tmp:
        with pq.ParquetWriter(tmp, schema, compression="zstd") as writer:
            for table in tables:
                writer.write_table(table.cast(schema), row_group_size=table.num_rows)
    return labels


def _shard_schema(store: DatasetStore, rel: str):
    import pyarrow.parquet as pq

    with store._io("read", rel):
        return pq.read_schema(store.path(rel), filesystem=store.fs)


def _shard_labels(store: DatasetStore, rel: str) -> list[dict]:
    meta = _shard_schema(store, rel).metadata or {}
    return json.loads(meta[b"prsm_health.labels"])


@dataclass
class GenerationReport:
    """What one call of :func:`generate` did."""

    out: Path | str
    """The dataset directory: a Path, or the URL of an object-store dataset."""
    total_runs: int
    generated_runs: int
    resumed_runs: int
    seconds: float

    @property
    def runs_per_minute(self) -> float:
        return 60.0 * self.generated_runs / self.seconds if self.seconds > 0 else float("nan")


def generate(
    recipe: Recipe | str | Path,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | object | None = None,
    formats: str = "parquet",
    progress: bool = True,
    on_batch: Callable[[int], None] | None = None,
) -> GenerationReport:
    """Generate (or resume) a dataset.

    Parameters
    ----------
    recipe : Recipe or path to a TOML recipe
    out : path or str
        Dataset directory: a local path, or an fsspec URL (``s3://bucket/prefix``, ``gs://…``,
        ``memory://…``, ``file://…``; credentials and endpoint from the environment,
        docs/formats.md). Created if missing. A directory holding another recipe's dataset is
        refused.
    workers : int or None
        Local worker processes (default: CPU count; 1 for ``memory://``, which lives in this
        process). 1 runs in this process.
    scheduler : str, distributed.Client or None
        Dask scheduler address (or a Client); default from ``DASK_SCHEDULER_ADDRESS``. When set,
        batches run on the cluster and the workers write the files to ``out``: a shared
        filesystem for a local path, none needed for an object-store URL.
    formats : {"parquet", "mcap", "both"}
    progress : bool
        Progress bar with runs done, rate and ETA.
    on_batch : callable or None
        Called with each finished batch index (tests use it to interrupt).
    """
    import time

    recipe = recipe if isinstance(recipe, Recipe) else load_recipe(recipe)
    require(formats in FORMATS, "format", formats, f"must be one of {', '.join(FORMATS)}")
    store = DatasetStore(out)
    _prepare(store, recipe, formats)
    batches = recipe.batches()
    total = sum(len(b) for b in batches)
    done = {f"signals/{name}" for name in store.list("signals")}
    pending = [i for i in range(len(batches)) if shard_name(i) not in done]
    resumed = total - sum(len(batches[i]) for i in pending)
    scheduler = (
        scheduler if scheduler is not None else os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    )
    start = time.perf_counter()
    bar = None
    if progress and pending:
        from tqdm import tqdm

        bar = tqdm(total=total, initial=resumed, unit="run", desc=recipe.name, smoothing=0.1)
    done_runs = 0

    def finished(batch: int) -> None:
        nonlocal done_runs
        done_runs += len(batches[batch])
        if bar is not None:
            bar.update(len(batches[batch]))
        if on_batch is not None:
            on_batch(batch)

    try:
        if scheduler:
            _run_dask(scheduler, recipe, store, formats, pending, finished)
        else:
            _run_local(workers, recipe, store, formats, pending, finished)
    finally:
        if bar is not None:
            bar.close()
    _finalise(store, recipe, formats)
    return GenerationReport(store.location, total, done_runs, resumed, time.perf_counter() - start)


def _prepare(store: DatasetStore, recipe: Recipe, formats: str) -> None:
    mcap = formats in ("mcap", "both")
    store.makedirs("", "signals", *(["mcap"] if mcap else []))
    stamp = ".recipe.json"
    if store.exists(stamp):
        previous = json.loads(store.read_text(stamp))
        if previous.get("fingerprint") != recipe.fingerprint:
            raise PRSMHealthError(
                f"{store} holds a dataset of recipe {previous.get('name')!r} with other content "
                f"({_recipe_changes(previous.get('source'), recipe.source)}); runs made with "
                "different settings cannot be mixed: use a new --out directory or undo the edit"
            )
    else:
        # the first write: an unreachable store or a missing bucket fails here, before any run
        store.write_text(
            stamp,
            dumps(
                {"name": recipe.name, "fingerprint": recipe.fingerprint, "source": recipe.source}
            ),
        )
    # a killed worker's unfinished shard or MCAP file
    store.discard_partials("signals", *(["mcap"] if mcap else []))


def _recipe_changes(before: dict | None, after: dict) -> str:
    """Which recipe keys differ, as 'key: old → new' (dotted keys for tables)."""
    if before is None:
        return "the directory predates change tracking"

    def flat(d, prefix=""):
        out = {}
        for k, v in d.items():
            out.update(flat(v, f"{prefix}{k}.") if isinstance(v, dict) else {prefix + k: v})
        return out

    a, b = flat(before), flat(after)
    changed = [
        f"{k}: {a.get(k, '(unset)')!r} → {b.get(k, '(unset)')!r}"
        for k in sorted(set(a) | set(b))
        if a.get(k) != b.get(k)
    ]
    return "changed " + "; ".join(changed[:5]) + (" …" if len(changed) > 5 else "")


def _run_local(workers, recipe, store, formats, pending, finished) -> None:
    workers = workers or (1 if store.in_process else os.cpu_count() or 1)
    require(isinstance(workers, int) and workers >= 1, "workers", workers, "must be an integer ≥ 1")
    require(
        workers == 1 or not store.in_process,
        "workers",
        workers,
        f"must be 1 for {store.url}: a memory:// store lives in this process, worker processes "
        "would each write to their own",
    )
    if workers == 1:
        for batch in pending:
            run_batch(recipe.source, batch, store.url, formats)
            finished(batch)
        return
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    # Workers ignore SIGINT: on Ctrl-C the parent stops them at once (shards are written
    # atomically, so a killed batch leaves no file and is redone on resume); otherwise each
    # worker would finish its batch and start queued ones before the pool noticed.
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint)
    try:
        futures = {pool.submit(run_batch, recipe.source, b, store.url, formats): b for b in pending}
        remaining = set(futures)
        while remaining:
            done, remaining = wait(remaining, return_when=FIRST_COMPLETED)
            for fut in done:
                fut.result()
                finished(futures[fut])
    except BaseException:
        processes = list((pool._processes or {}).values())  # no public API to stop a worker
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        for process in processes:
            process.join(timeout=2.0)
        raise
    pool.shutdown()


def _ignore_sigint() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_dask(scheduler, recipe, store, formats, pending, finished) -> None:
    from distributed import Client, as_completed

    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        futures = client.map(
            run_batch,
            [recipe.source] * len(pending),
            pending,
            # workers open the store themselves: an object-store URL needs no shared filesystem
            [store.url] * len(pending),
            [formats] * len(pending),
            pure=False,
        )
        index = {f.key: b for f, b in zip(futures, pending)}
        for fut in as_completed(futures):
            fut.result()
            finished(index[fut.key])
    finally:
        if client is not scheduler:
            client.close()


def _finalise(store: DatasetStore, recipe: Recipe, formats: str) -> None:
    """Assemble runs.parquet and manifest.json from the shards (idempotent)."""
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    from prsm_health.core.version import __version__

    store.refresh()  # the workers' shards, not a listing cached before they wrote them
    rows = []
    for batch in range(len(recipe.batches())):
        shard = shard_name(batch)
        for group, label in enumerate(_shard_labels(store, shard)):
            rows.append(dict(label, shard=shard, row_group=group))
    frame = pd.DataFrame(rows).sort_values("run_id").reset_index(drop=True)
    stored = _shard_schema(store, shard_name(0)).names
    table = pa.Table.from_pandas(frame, preserve_index=False)
    with store.staged("runs.parquet") as tmp:
        pq.write_table(table, tmp)
    manifest = {
        "name": recipe.name,
        "recipe": recipe.source,
        # which design the runs are of, at a glance (the design itself is the recipe's)
        "design": {"name": recipe.prsm_design.name, "fingerprint": recipe.design_fingerprint},
        "package": {"name": "prsm_health", "version": __version__},
        "sample_rate": recipe.sample_rate,
        "duration": recipe.duration,
        "channels": {k: UNITS[k] for k in stored if k == "time" or k in CHANNEL_NAMES},
        "truth": {k: UNITS[k] for k in stored if k in UNITS and k.startswith(TRUTH_PREFIX)},
        "dtype": recipe.dtype,
        "formats": formats,
        "fault_taxonomy": {
            "classes": list(FAULT_CLASSES),
            "thresholds": recipe.faults.as_dict(),
            "rule": FAULT_RULE,
        },
        "counts": dataset_counts(frame),
    }
    store.write_text("manifest.json", dumps(manifest, indent=2))


def dataset_throughput(report: GenerationReport) -> str:
    """One line for logs and docs: runs, time, runs/min."""
    return (
        f"{report.generated_runs} runs in {report.seconds:.1f} s "
        f"({report.runs_per_minute:.0f} runs/min; {report.resumed_runs} already done)"
    )
