"""A health-check MCAP cut in its slow reversal, uploaded to the service, gets the library's
diagnosis: the clearance not observable and the one warning line naming the cut phase
(diagnostics.check_model.cut_note). One short check (cached for the session), one upload."""

import pytest
from live_server import LiveServer

from prsm_health.apps.service import create_app
from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
from prsm_health.io import read_recording
from prsm_health.io.mcap import write_mcap


@pytest.fixture(scope="module")
def cut_file(short_check_run, tmp_path_factory):
    check = short_check_run()
    swing = next(p for p in check.check.phases if p.name == "swing")
    cut = check.slice(0, int((swing.start + 0.09) * check.sample_rate)).without_truth()
    return write_mcap(cut, tmp_path_factory.mktemp("cut") / "cut-check.mcap")


def test_a_cut_check_uploaded_is_warned_as_the_library_warns(cut_file, tmp_path):
    bundle = load_bundle()
    library = diagnose(read_recording(cut_file), bundle)
    assert library.warnings[0].startswith("check cut short")
    with LiveServer(create_app(None, tmp_path / "h.sqlite", bundle=bundle, warmup=False)) as live:
        with live.client() as c:
            r = c.post("/v1/diagnose/file", files={"file": (cut_file.name, cut_file.read_bytes())})
    assert r.status_code == 200, r.text
    served = r.json()["diagnosis"]
    line = next(w for w in served["warnings"] if w.startswith("check cut short"))
    assert line == library.warnings[0]
    assert '"swing"' in line and "record the whole check" in line
    assert "reversal" not in served["check_phases"]
    assert not served["observability"]["clearance"]
    assert [served["clearance"]["lower"], served["clearance"]["upper"]] == list(
        bundle.check["clearance_range"]
    )


def test_an_asset_commissioned_through_the_service_reads_its_own_chain(short_check_run, tmp_path):
    """PUT the as-built clearance, then two checks under the asset: the first joins the
    baseline (not yet commissioned), the second reads against the unit's own chain, its
    interval narrower (no bearing play or gearhead backlash left in its budget)."""
    bundle = load_bundle()
    files = [
        write_mcap(short_check_run(seed=seed).without_truth(), tmp_path / f"check-{seed}.mcap")
        for seed in (4, 5)
    ]
    with LiveServer(create_app(None, tmp_path / "h.sqlite", bundle=bundle, warmup=False)) as live:
        with live.client() as c:
            bad = c.put("/v1/assets/u-1/commissioning", json={"as_built_clearance": 1.0})
            assert bad.status_code == 422 and "error" in bad.json()
            r = c.put("/v1/assets/u-1/commissioning", json={"as_built_clearance": 6e-6})
            assert r.status_code == 200 and r.json() == {"as_built_clearance": 6e-6}
            answers = [
                c.post(
                    "/v1/diagnose/file",
                    files={"file": (f.name, f.read_bytes())},
                    data={"asset_id": "u-1", "healthy": "true"},
                ).json()["diagnosis"]
                for f in files
            ]
    first, second = (a["measured_clearance"] for a in answers)
    assert not first["commissioned"] and second["commissioned"]
    assert (
        "thrust-bearing play" in first["budget"] and "thrust-bearing play" not in second["budget"]
    )
    width = [a["clearance"]["upper"] - a["clearance"]["lower"] for a in answers]
    assert width[1] < width[0]
