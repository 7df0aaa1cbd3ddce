"""One monitoring layer for every asset: the same six health-check recordings of one unit —
three as commissioned, three of the unit worn — through ``prsm-health diagnose --asset`` (the
file store) and through the service's upload endpoint (its SQLite store, a real server on
127.0.0.1) give the same baseline, evidence, posterior and change statistic after every
recording, the same recording ids, equal stored histories, and the same prognosis
(``prognose --asset`` against ``GET /v1/assets/{id}/prognosis``). A health check uploaded with
an asset id is stored as a diagnosis row: ``GET /v1/assets/{id}`` answers 200 with it and the
fleet list has the asset.

Six short checks of the shipped model's design (1 s each, cached for the session); the
diagnoses run the same code on the same samples in both paths, so the numbers agree to the
last bit (JSON writes floats in their shortest exact form) — compared at 1e-12 relative all
the same, so that a reordering of a sum in one path would show as a difference in kind, not
as noise.
"""

import json

import pytest
from live_server import LiveServer

from prsm_health.apps.cli import main
from prsm_health.apps.service import create_app
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.parquet import write_run_parquet
from prsm_health.monitoring import FileAssetStore, asset_baseline
from prsm_health.monitoring.sqlite_store import HistoryStore

# six 1 s health checks simulated and diagnosed twice: ≈ 20 s
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def checks(short_check_run, tmp_path_factory):
    """Six check files: three of a unit as commissioned (15 µm), three of it worn (30 µm)."""
    root = tmp_path_factory.mktemp("checks")
    plan = [(15e-6, 11), (15e-6, 12), (15e-6, 13), (30e-6, 21), (30e-6, 22), (30e-6, 23)]
    return [
        write_run_parquet(short_check_run(c, seed).without_truth(), root / f"check-{i}.parquet")
        for i, (c, seed) in enumerate(plan)
    ]


#: The unit's operating hours at each check.
HOURS = [0.0, 10.0, 20.0, 400.0, 500.0, 600.0]


def _close(a, b, path="asset"):
    """``a`` equals ``b``, floats to 1e-12 relative; the first difference is named."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert set(a) == set(b), f"{path}: keys {sorted(a)} != {sorted(b)}"
        for k in a:
            _close(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b), f"{path}: {len(a)} != {len(b)} items"
        for k, (x, y) in enumerate(zip(a, b)):
            _close(x, y, f"{path}[{k}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert b == pytest.approx(a, rel=1e-12, abs=1e-300), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def test_cli_and_service_keep_one_asset_the_same_way(checks, tmp_path, capsys):
    bundle = load_bundle()
    assert bundle.check is not None  # the shipped model reads checks phase by phase
    store_dir = tmp_path / "assets"
    cli = []
    # the three commissioning checks are labelled healthy (a new unit known to be so: the
    # shipped model alone reads a short 15 µm check as worn), the later three are not labelled
    for i, path in enumerate(checks):
        args = ["diagnose", str(path), "--asset", "unit-9", "--store", str(store_dir)]
        args += ["--healthy"] if i < 3 else []
        args += ["--operating-hours", str(HOURS[i])]
        assert main([*args, "--json"]) == 0
        cli.append(json.loads(capsys.readouterr().out))

    db = tmp_path / "history.sqlite"
    service = []
    with LiveServer(create_app(None, db, bundle=bundle, warmup=False)) as live:
        with live.client() as c:
            for i, path in enumerate(checks):
                r = c.post(
                    "/v1/diagnose/file",
                    files={"file": (path.name, path.read_bytes())},
                    data={
                        "asset_id": "unit-9",
                        "operating_hours": str(HOURS[i]),
                        **({"healthy": "true"} if i < 3 else {}),
                    },
                )
                assert r.status_code == 200, r.text
                service.append(r.json()["diagnosis"])
            # the checks are stored as diagnoses: the asset answers and is in the fleet list
            summary = c.get("/v1/assets/unit-9")
            assert summary.status_code == 200, summary.text
            assert summary.json()["diagnoses"] == 6
            assert summary.json()["baseline"]["recordings"] == 3
            listed = [a["asset_id"] for a in c.get("/v1/assets").json()["assets"]]
            assert listed == ["unit-9"]
            served_prognosis = c.get("/v1/assets/unit-9/prognosis")
            assert served_prognosis.status_code == 200, served_prognosis.text

    # the asset's prognosis from the CLI's store (prognose --asset) is the service's
    assert main(["prognose", "--asset", "unit-9", "--store", str(store_dir), "--json"]) == 0
    _close(json.loads(capsys.readouterr().out), served_prognosis.json(), "prognosis")

    # a check is read phase by phase in both paths, and the unit's state after each agrees
    assert all(d["check_phases"] for d in cli) and all(d["check_phases"] for d in service)
    for k, (a, b) in enumerate(zip(cli, service)):
        _close(a["asset"], b["asset"], f"recording {k}: asset")
    states = [d["asset"] for d in cli]
    assert [s["baseline"]["recordings"] for s in states] == [1, 2, 3, 3, 3, 3]
    assert [s["evidence"]["recordings"] for s in states] == [0, 0, 0, 1, 2, 3]
    assert all(s["evidence"]["change_statistic"] is not None for s in states[3:])

    # the stores hold equal histories: the same recording ids (the files' content), entries,
    # evidence, change statistic, and the same baseline fitted from them
    files, database = FileAssetStore(store_dir), HistoryStore(db)
    try:
        on_disk, in_db = files.load("unit-9").history, database.load("unit-9").history
        assert [e.recording_id for e in on_disk.entries] == [e.recording_id for e in in_db.entries]
        _close(on_disk.evidence.to_json(), in_db.evidence.to_json(), "evidence")
        _close(on_disk.cusum.to_json(), in_db.cusum.to_json(), "cusum")
        for a, b in zip(on_disk.entries, in_db.entries):
            _close(a.state.to_json(), b.state.to_json(), f"{a.recording_id}: state")
            assert a.baseline == b.baseline
        _close(
            asset_baseline(files, bundle, "unit-9").to_json(),
            asset_baseline(database, bundle, "unit-9").to_json(),
            "baseline",
        )
    finally:
        database.close()
