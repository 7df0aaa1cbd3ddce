"""Datasets on object stores: memory:// write and resume, file:// URLs, one-line errors, and a
real S3 (moto server) written by a Dask cluster whose workers share no filesystem with the
client, one of them killed mid-run. Nothing talks to any host but 127.0.0.1."""

import json
import os
import signal
import socket
import textwrap
import threading
import time
import uuid

import fsspec
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import prsm_health.datasets.generation as dataset_module
from prsm_health.apps.cli import main
from prsm_health.core.errors import ParameterError, PRSMHealthError, StorageError
from prsm_health.datasets import Dataset, generate

TINY = textwrap.dedent(
    """
    name = "tiny-store"
    design = "paper01"
    duration = 0.02
    sample_rate = 20000
    instrumentation = "ideal"
    seed = 11
    batch_size = 2
    test_fraction = 0.34
    [sweep]
    clearance = [5e-6, 25e-6, 40e-6]
    speed = [80.0]
    load = [100.0, 200.0]
    repeats = 1
    """
)


@pytest.fixture
def recipe_path(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


@pytest.fixture
def memory_url():
    """A fresh memory:// dataset location, removed afterwards (the store is process-global)."""
    root = f"/prsm-test-{uuid.uuid4().hex}"
    yield f"memory://{root}/ds"
    fs = fsspec.filesystem("memory")
    if fs.exists(root):
        fs.rm(root, recursive=True)


def _files(fs, root: str) -> set[str]:
    return {p[len(root) + 1 :] for p in fs.find(root)}


def _signals(ds: Dataset) -> pd.DataFrame:
    frames = [
        pd.read_parquet(ds._store.path(s), filesystem=ds._store.fs)
        for s in sorted(set(ds.runs["shard"]))
    ]
    return pd.concat(frames).sort_values(["run_id", "time"]).reset_index(drop=True)


def test_memory_store_write_interrupt_resume_read(recipe_path, tmp_path, memory_url, monkeypatch):
    # batch 1 fails the first time (a crashed worker): batch 0 is kept, nothing of batch 1
    real = dataset_module.run_batch
    failures = []

    def flaky(source, batch, out, formats):
        if batch == 1 and not failures:
            failures.append(batch)
            raise RuntimeError("worker lost")
        return real(source, batch, out, formats)

    monkeypatch.setattr(dataset_module, "run_batch", flaky)
    with pytest.raises(RuntimeError, match="worker lost"):
        generate(recipe_path, memory_url, formats="both", progress=False)
    fs, root = fsspec.core.url_to_fs(memory_url)
    assert _files(fs, root) == {
        ".recipe.json",
        "signals/part-00000.parquet",
        "mcap/run-000000.mcap",
        "mcap/run-000001.mcap",
    }
    # the same call again completes it: default workers is 1 for memory:// (one process)
    report = generate(recipe_path, memory_url, formats="both", progress=False)
    assert (report.resumed_runs, report.generated_runs, report.out) == (2, 4, memory_url)
    expected = {".recipe.json", "manifest.json", "runs.parquet"}
    expected |= {f"signals/part-{b:05d}.parquet" for b in range(3)}
    expected |= {f"mcap/run-{r:06d}.mcap" for r in range(6)}
    assert _files(fs, root) == expected  # no temporary or duplicate object
    again = generate(recipe_path, memory_url, formats="both", progress=False)
    assert (again.resumed_runs, again.generated_runs) == (6, 0)

    ds = Dataset(memory_url)
    assert ds.path == memory_url and len(ds) == 6
    assert list(ds.runs["run_id"]) == list(range(6))
    assert ds.manifest["counts"]["runs"] == 6 and ds.manifest["formats"] == "both"
    # identical to the same recipe written to a local directory
    generate(recipe_path, tmp_path / "local", workers=1, progress=False)
    local = Dataset(tmp_path / "local")
    pd.testing.assert_frame_equal(ds.runs, local.runs)
    pd.testing.assert_frame_equal(_signals(ds), _signals(local))
    assert np.array_equal(ds.run(3)["nut_axial_accel"], local.run(3)["nut_axial_accel"])
    # the MCAP files made it to the store, complete
    from prsm_health.io.mcap import read_mcap

    copy = tmp_path / "run-2.mcap"
    fs.get_file(f"{root}/mcap/run-000002.mcap", str(copy))
    assert read_mcap(copy).labels["run_id"] == 2

    # another recipe in the same location is refused; memory:// with worker processes too
    edited = tmp_path / "edited.toml"
    edited.write_text(TINY.replace("speed = [80.0]", "speed = [90.0]"))
    with pytest.raises(PRSMHealthError, match="other content"):
        generate(edited, memory_url, progress=False)
    with pytest.raises(ParameterError, match="workers = 2"):
        generate(recipe_path, memory_url, workers=2, progress=False)


def test_file_url_is_the_local_layout(recipe_path, tmp_path):
    report = generate(recipe_path, f"file://{tmp_path}/f", workers=1, progress=False)
    assert report.out == tmp_path / "f"
    names = {p.relative_to(tmp_path / "f").as_posix() for p in (tmp_path / "f").rglob("*")}
    assert names == {".recipe.json", "manifest.json", "runs.parquet", "signals"} | {
        f"signals/part-{b:05d}.parquet" for b in range(3)
    }
    assert len(Dataset(tmp_path / "f")) == len(Dataset(f"file://{tmp_path}/f")) == 6


def test_bad_store_url_is_one_line_exit_2(recipe_path, capsys):
    code = main(["generate", str(recipe_path), "--out", "nosuch://bucket/ds"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("error: nosuch://bucket/ds: ")
    assert "Protocol not known: nosuch" in err
    with pytest.raises(StorageError, match="names no location"):
        Dataset("memory://")


# ------------------------------------------------------------------ real S3 + Dask (slow)
BUCKET = "prsm-test"
KEY, SECRET = "testing-key", "testing-secret"
# 8 batches of one 0.1 s run: long enough that a worker is busy when it is killed
KILL_RECIPE = textwrap.dedent(
    """
    name = "kill"
    design = "paper01"
    duration = 0.1
    sample_rate = 2000
    instrumentation = "ideal"
    seed = 5
    batch_size = 1
    test_fraction = 0.25
    [sweep]
    clearance = [5e-6, 15e-6, 25e-6, 40e-6]
    speed = [80.0]
    load = [100.0, 200.0]
    """
)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def s3_endpoint():
    """A moto S3 server on 127.0.0.1 with one bucket; the environment points s3fs, botocore and
    the Dask workers (spawned later, they inherit it) at it and away from any real account."""
    import logging

    import boto3
    from moto.server import ThreadedMotoServer

    logging.getLogger("werkzeug").setLevel(logging.ERROR)  # one log line per request
    port = _free_port()
    server = ThreadedMotoServer(ip_address="127.0.0.1", port=port, verbose=False)
    server.start()
    endpoint = f"http://127.0.0.1:{port}"
    with pytest.MonkeyPatch.context() as mp:
        for name in ("AWS_PROFILE", "AWS_SESSION_TOKEN", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY"):
            mp.delenv(name, raising=False)
            mp.delenv(name.lower(), raising=False)
        mp.setenv("AWS_ENDPOINT_URL", endpoint)
        mp.setenv("AWS_ACCESS_KEY_ID", KEY)
        mp.setenv("AWS_SECRET_ACCESS_KEY", SECRET)
        mp.setenv("AWS_DEFAULT_REGION", "us-east-1")
        mp.setenv("AWS_EC2_METADATA_DISABLED", "true")
        mp.setenv("AWS_CONFIG_FILE", os.devnull)
        mp.setenv("AWS_SHARED_CREDENTIALS_FILE", os.devnull)
        mp.setenv("NO_PROXY", "127.0.0.1,localhost")
        try:
            boto3.client("s3", endpoint_url=endpoint).create_bucket(Bucket=BUCKET)
            yield endpoint
        finally:
            import s3fs

            s3fs.S3FileSystem.clear_instance_cache()  # its client points at this server
            server.stop()


def _keys(endpoint: str, prefix: str) -> set[str]:
    import boto3

    pages = boto3.client("s3", endpoint_url=endpoint).get_paginator("list_objects_v2")
    return {
        o["Key"][len(prefix) + 1 :]
        for page in pages.paginate(Bucket=BUCKET, Prefix=prefix + "/")
        for o in page.get("Contents", [])
    }


@pytest.mark.slow
def test_s3_dask_workers_without_shared_filesystem_survive_a_kill(s3_endpoint, tmp_path, capsys):
    from distributed import Client, LocalCluster

    recipe = tmp_path / "kill.toml"
    recipe.write_text(KILL_RECIPE)
    n_runs = len(dataset_module.load_recipe(recipe).runs())
    assert n_runs == 8
    url = f"s3://{BUCKET}/ds"
    outcome = {}

    def run_generate(address):
        try:
            outcome["report"] = generate(recipe, url, scheduler=address, progress=False)
        except BaseException as exc:  # the main thread decides
            outcome["error"] = exc

    with (
        LocalCluster(
            n_workers=2,
            processes=True,
            threads_per_worker=1,
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster,
        Client(cluster, timeout=60) as client,
    ):
        client.wait_for_workers(2, timeout=120)
        thread = threading.Thread(target=run_generate, args=(cluster.scheduler_address,))
        thread.daemon = True
        thread.start()
        deadline = time.monotonic() + 180
        shards = set()
        while time.monotonic() < deadline and thread.is_alive():
            shards = {k for k in _keys(s3_endpoint, "ds") if k.startswith("signals/")}
            if shards:
                break
            time.sleep(0.05)
        assert shards, f"no shard appeared: {outcome}"
        # kill (SIGKILL, no cleanup) a worker that holds a batch
        busy = [a for a, keys in client.processing().items() if keys] or list(
            client.scheduler_info()["workers"]
        )
        pids = client.run(os.getpid)
        os.kill(pids[busy[0]], signal.SIGKILL)
        assert len(shards) < n_runs  # mid-run: work was left
        thread.join(timeout=300)
        assert not thread.is_alive(), "generate did not finish"
        # Rerun, as a user would, through the command line: it completes what is missing
        # (nothing if Dask rescheduled the lost batch) and finalises.
        code = main(
            ["generate", str(recipe), "--out", url, "--scheduler", cluster.scheduler_address]
            + ["--json"]
        )
        out, err = capsys.readouterr()
        assert code == 0, err
        rerun = json.loads(out)
        assert rerun["runs"] == n_runs and rerun["resumed"] + rerun["generated"] == n_runs
        if "error" not in outcome:
            assert rerun["generated"] == 0

    # exactly the expected objects: every shard once, no temporary or stray object
    expected = {".recipe.json", "manifest.json", "runs.parquet"}
    expected |= {f"signals/part-{b:05d}.parquet" for b in range(n_runs)}
    assert _keys(s3_endpoint, "ds") == expected

    ds = Dataset(url)
    assert ds.path == url
    assert sorted(ds.runs["run_id"]) == list(range(n_runs)) and ds.runs["run_id"].is_unique
    counts = ds.manifest["counts"]
    assert counts["runs"] == n_runs and counts["train"] + counts["test"] == n_runs
    assert sum(counts["fault_class"].values()) == n_runs

    # independent readers: pyarrow's own S3 client, and pandas with storage_options
    from pyarrow.fs import S3FileSystem

    s3 = S3FileSystem(
        access_key=KEY,
        secret_key=SECRET,
        region="us-east-1",
        endpoint_override=s3_endpoint.removeprefix("http://"),
        scheme="http",
    )
    signals = pq.read_table(f"{BUCKET}/ds/signals", filesystem=s3).to_pandas()
    runs = pd.read_parquet(
        f"{url}/runs.parquet",
        storage_options={"key": KEY, "secret": SECRET, "endpoint_url": s3_endpoint},
    )
    pd.testing.assert_frame_equal(runs, ds.runs)
    sizes = signals.groupby("run_id").size()
    assert list(sizes.index) == list(range(n_runs))
    assert sizes.tolist() == runs.sort_values("run_id")["n_samples"].tolist()
    # the same signals as a local single-process generation
    generate(recipe, tmp_path / "local", workers=1, progress=False)
    local = Dataset(tmp_path / "local")
    pd.testing.assert_frame_equal(_signals(ds), _signals(local))

    # Resume on the store by local workers: an interruption that lost batch 5 and the final
    # files is completed by the same command, that batch alone.
    import boto3

    client = boto3.client("s3", endpoint_url=s3_endpoint)
    for key in ("signals/part-00005.parquet", "runs.parquet", "manifest.json"):
        client.delete_object(Bucket=BUCKET, Key=f"ds/{key}")
    report = generate(recipe, url, workers=2, progress=False)
    assert (report.generated_runs, report.resumed_runs) == (1, n_runs - 1)
    assert _keys(s3_endpoint, "ds") == expected
    pd.testing.assert_frame_equal(_signals(Dataset(url)), _signals(local))

    # a bucket that does not exist: one line, exit 2, before any simulation
    code = main(["generate", str(recipe), "--out", "s3://no-such-bucket/ds", "--workers", "1"])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("error: s3://no-such-bucket/ds/.recipe.json: cannot write")
    assert "bucket does not exist" in err
