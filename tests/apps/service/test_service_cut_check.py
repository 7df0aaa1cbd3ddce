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
