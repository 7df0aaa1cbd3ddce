"""CSV recordings through the service: a rig's CSV upload with its column map (multipart field
``map``), read by the library's one reader (what ``diagnose`` and ``import`` use); errors name
the file, the column and the row. In-process ASGI calls, no server."""

import anyio
import httpx
import numpy as np
import pandas as pd
import pytest

from prsm_health.apps.service import ServiceLimits, create_app, diagnosing
from prsm_health.apps.service.uploads import ReceivedUpload
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
from prsm_health.io import read_recording

MAP = b"""
[columns]
time = "t_ms"
screw_angle = "motor_deg"
nut_axial_accel = "acc_g"
nut_position = "pos_mm"
drive_torque = "torque_Nmm"
axial_load = "load_kN"
[units]
t_ms = "ms"
motor_deg = "deg"
acc_g = "g"
pos_mm = "mm"
torque_Nmm = "N*mm"
load_kN = "kN"
"""


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def app(bundle):
    return create_app(None, ":memory:", None, ServiceLimits(), bundle=bundle, warmup=False)


@pytest.fixture(scope="module")
def rig_csv(reversing_run) -> bytes:
    """A simulated recording (0.4 s, one model window) logged like a rig: its own column
    names and units, no screw speed column (derived from the angle when read)."""
    run = reversing_run(20e-6, seed=3)
    c = run.channels
    frame = pd.DataFrame(
        {
            "t_ms": 1e3 * run.time,
            "motor_deg": np.degrees(c["screw_angle"]),
            "acc_g": c["nut_axial_accel"] / 9.80665,
            "pos_mm": 1e3 * c["nut_position"],
            "torque_Nmm": 1e3 * c["drive_torque"],
            "load_kN": 1e-3 * c["axial_load"],
        }
    )
    return frame.to_csv(index=False, float_format="%.17g").encode()


def _post(app, files) -> httpx.Response:
    async def run():
        transport = httpx.ASGITransport(app=app)
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as client:
            return await client.post("/v1/diagnose/file", files=files)

    return anyio.run(run)


def test_csv_upload_with_its_map_is_diagnosed_as_the_library_reads_it(
    app, bundle, rig_csv, tmp_path
):
    r = _post(app, {"file": ("rig.csv", rig_csv), "map": ("rig-map.toml", MAP)})
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["recording"]["filename"] == "rig.csv"
    assert body["recording"]["samples"] == 8000
    assert body["recording"]["sample_rate"] == pytest.approx(20000.0, rel=1e-9)
    assert "screw_speed" in body["recording"]["channels"]  # derived from the angle
    assert body["warnings"] == []
    # the same file read by the library (what `diagnose FILE --map` does) diagnoses the same
    (tmp_path / "rig.csv").write_bytes(rig_csv)
    (tmp_path / "map.toml").write_bytes(MAP)
    local = diagnose(read_recording(tmp_path / "rig.csv", column_map=tmp_path / "map.toml"), bundle)
    assert body["diagnosis"]["fault_class"] == local.fault_class
    assert body["diagnosis"]["clearance"]["estimate"] == pytest.approx(
        local.clearance["estimate"], rel=1e-9
    )


def test_contract_csv_needs_no_map(app, reversing_run):
    run = reversing_run(20e-6, seed=3).without_truth()
    data = run.to_frame().drop(columns=["screw_speed"]).to_csv(index=False).encode()
    r = _post(app, {"file": ("contract.csv", data)})
    assert r.status_code == 200, r.text
    assert "screw_speed" in r.json()["recording"]["channels"]


@pytest.mark.parametrize(
    "change, needle",
    [
        # a column the map names is not in the file: the file and the column
        (lambda csv, m: (csv.replace(b"acc_g", b"accel", 1), m), "rig.csv: no column(s) 'acc_g'"),
        (lambda csv, m: (csv, m), None),  # the control
        # the map itself: named by the client's file name
        (lambda csv, m: (csv, m.replace(b'"g"', b'"furlong"')), "rig-map.toml: unit 'furlong'"),
        (lambda csv, m: (csv, b"[columns"), "rig-map.toml: not valid TOML"),
    ],
)
def test_csv_upload_errors_are_422_naming_the_file(app, rig_csv, change, needle):
    csv, map_ = change(rig_csv, MAP)
    r = _post(app, {"file": ("rig.csv", csv), "map": ("rig-map.toml", map_)})
    if needle is None:  # the control: unchanged, it is read
        assert r.status_code == 200, r.text
        return
    assert r.status_code == 422, r.text
    error = r.json()["error"]
    assert error.startswith(needle.split(":")[0] + ":") and needle in error, error
    assert "\n" not in error and "/tmp" not in error


def test_nan_cell_names_file_column_and_row(app, rig_csv):
    lines = rig_csv.split(b"\n")
    header = lines[0].split(b",")
    cells = lines[5].split(b",")
    cells[header.index(b"acc_g")] = b""  # data row 5 is line 6
    lines[5] = b",".join(cells)
    r = _post(app, {"file": ("rig.csv", b"\n".join(lines)), "map": ("rig-map.toml", MAP)})
    assert r.status_code == 422, r.text
    assert r.json()["error"] == "rig.csv: column 'acc_g', data row 5: is empty or NaN"


def test_a_request_cuts_its_windows_once(bundle, rig_csv, tmp_path, monkeypatch):
    # the diagnosis and the asset's last-window spectra share one cut of the recording
    calls = []
    original = Run.windows

    def counted(self, *args, **kwargs):
        calls.append(len(self))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Run, "windows", counted)
    path = tmp_path / "recording.csv"
    path.write_bytes(rig_csv)
    upload = ReceivedUpload(path, "rig.csv", ".csv", len(rig_csv), MAP, "map.toml")
    answer = diagnosing.diagnose_upload(bundle, upload, ServiceLimits(), "press-1", "now")
    assert answer.asset is not None and answer.spectra is not None
    assert calls == [8000]
