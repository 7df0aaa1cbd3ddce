"""Screenshots of the dashboard for docs/service.md: docs/figures/dashboard_overview.png (the
fleet) and docs/figures/dashboard_asset.png (one asset).

Starts the service on 127.0.0.1 (a free port, a throw-away database, the shipped models),
sends it simulated flight-ema recordings of three actuators through ``POST /v1/diagnose``
(binary Arrow bodies with operating hours; one as an upload without them), then takes the
screenshots with headless Chromium (Debian's /usr/bin/chromium, driven by Playwright; nothing
is downloaded). Takes about half a minute.

    python tools/figures/make_dashboard_screenshots.py [--out docs/figures] [--chromium /usr/bin/chromium]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import httpx

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.apps.service import create_app
from prsm_health.apps.service.server import serve_in_thread
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.parquet import write_run_parquet

ROOT = Path(__file__).resolve().parents[2]
#: Headless Chromium without a sandbox, GPU or background traffic (as the browser test,
#: tests/apps/service/test_dashboard_browser.py, launches it).
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: asset → (operating hours, clearance [m]) of its snapshots
FLEET = {
    "press-1": [(0, 8e-6), (200, 10e-6), (400, 12e-6), (600, 14e-6), (800, 17e-6), (1000, 20e-6)],
    "press-2": [(0, 7e-6), (350, 8e-6), (700, 9e-6)],
}


def recording(clearance: float, seed: int):
    profile = OperatingProfile(
        duration=0.5,
        speed=100.0,
        load=0.0,
        load_profile="reversing",
        load_amplitude=300.0,
        load_frequency=10.0,
        accel_time=0.002,
    )
    return simulate(
        "paper01",
        HealthState.uniform(clearance),
        profile,
        "flight-ema",
        seed,
        options=SimulationOptions(contact_law="hertz"),
    ).without_truth()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory(prefix="prsm-health-screens-") as tmp:
        app = create_app(None, Path(tmp) / "history.sqlite")
        with serve_in_thread(app) as url, httpx.Client(base_url=url, timeout=120) as c:
            seed = 0
            for asset, snapshots in FLEET.items():
                for hours, clearance in snapshots:
                    seed += 1
                    r = c.post(
                        "/v1/diagnose",
                        content=write_run_arrow(recording(clearance, seed)),
                        headers={"content-type": "application/vnd.apache.arrow.stream"},
                        params={"asset_id": asset, "operating_hours": str(hours)},
                    )
                    r.raise_for_status()
            parquet = write_run_parquet(recording(15e-6, 99), Path(tmp) / "bench-run.parquet")
            r = c.post(
                "/v1/diagnose/file",
                files={"file": ("bench-run.parquet", parquet.read_bytes())},
                data={"asset_id": "rig-3"},
            )
            r.raise_for_status()
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path=args.chromium, args=CHROMIUM_ARGS)
                page = browser.new_page(viewport={"width": 1200, "height": 700})
                args.out.mkdir(parents=True, exist_ok=True)
                shots = {"/": "dashboard_overview.png", "/assets/press-1": "dashboard_asset.png"}
                for path, name in shots.items():
                    page.goto(url + path)
                    page.wait_for_load_state("networkidle")
                    page.wait_for_function(
                        "() => !document.getElementById('status').textContent.startsWith('Loading')"
                    )
                    page.screenshot(path=args.out / name, full_page=True)
                    print(f"wrote {args.out / name}")
                browser.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
