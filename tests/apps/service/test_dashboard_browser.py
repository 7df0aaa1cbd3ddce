"""The dashboard in a real browser: headless Chromium (Debian's ``/usr/bin/chromium``, driven
by Playwright; Playwright never downloads a browser here) against a real server on 127.0.0.1
with real data — simulated flight-ema recordings diagnosed through ``POST /v1/diagnose`` with
operating hours (the shipped prognostics model then gives a prognosis).

With the service's token set, the browser logs in through the ``/login`` form; then every page
loads without a console error and draws its plots from the data it fetched (uPlot canvases of
non-zero size with painted pixels; the JSON the page received non-empty), the upload form
diagnoses a file, and a file name carrying markup is shown as text (no dialog, no element).
The asset id pattern (``^[A-Za-z0-9][A-Za-z0-9._:-]{0,127}$``) cannot hold markup, so the
escaping is tested with an uploaded file's name, which the asset page shows.

Set ``PRSM_HEALTH_SKIP_BROWSER=1`` to skip (nothing sets it by default: without Chromium the
test fails; ``make test`` installs it). ``PRSM_HEALTH_CHROMIUM`` names another executable.
"""

import os

import httpx
import pytest
from live_server import LiveServer

from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate
from prsm_health.apps.service import create_app
from prsm_health.apps.service.security import SESSION_COOKIE
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.arrow import write_run_arrow
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet

CHROMIUM = os.environ.get("PRSM_HEALTH_CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
TOKEN = "browser-token-0b6a"
XSS_NAME = "<img src=x onerror=alert(1)>.parquet"
PLOTS = ("#clearance-plot", "#class-plot", "#spectrum-plot", "#envelope-plot")

pytestmark = pytest.mark.skipif(
    os.environ.get("PRSM_HEALTH_SKIP_BROWSER") == "1",
    reason="PRSM_HEALTH_SKIP_BROWSER=1",
)


def _recording(clearance: float, seed: int) -> Run:
    """0.5 s (one model window) of the documented reversing load, flight-ema sensors."""
    profile = OperatingProfile(
        duration=0.5,
        speed=100.0,
        load=0.0,
        load_profile="reversing",
        load_amplitude=300.0,
        load_frequency=10.0,
        accel_time=0.002,
    )
    run = simulate(
        "paper01",
        HealthState.uniform(clearance),
        profile,
        "flight-ema",
        seed,
        options=SimulationOptions(contact_law="hertz"),
    )
    return run.without_truth()


@pytest.fixture(scope="module")
def chromium_path():
    if not os.access(CHROMIUM, os.X_OK):
        pytest.fail(
            f"{CHROMIUM} not found: install Debian's chromium (apt-get install -y chromium; "
            "`make test` does it as root) or set PRSM_HEALTH_SKIP_BROWSER=1"
        )
    return CHROMIUM


@pytest.fixture(scope="module")
def service(tmp_path_factory, short_check_run):
    """A real server with a token, and its data: press-1 (three diagnoses at 0, 400 and 800
    operating hours, sent as JSON, Arrow and MCAP), press-2 (no nut axial acceleration: no
    spectra), rig-3 (an upload whose file name carries markup), check-4 (a health check
    uploaded with its asset id: read whole, stored like any recording)."""
    d = tmp_path_factory.mktemp("dashboard")
    runs = [_recording(c, seed) for seed, c in enumerate((10e-6, 14e-6, 19e-6))]
    app = create_app(None, d / "history.sqlite", TOKEN, bundle=load_bundle(), warmup=False)
    with LiveServer(app) as live, live.client(headers={"Authorization": f"Bearer {TOKEN}"}) as c:
        first = runs[0]
        body = {
            "sample_rate": first.sample_rate,
            "channels": {k: v.tolist() for k, v in first.channels.items()},
        }
        answers = [
            c.post("/v1/diagnose", json={**body, "asset_id": "press-1", "operating_hours": 0}),
            c.post(
                "/v1/diagnose",
                content=write_run_arrow(runs[1]),
                headers={"content-type": "application/vnd.apache.arrow.stream"},
                params={"asset_id": "press-1", "operating_hours": "400"},
            ),
            c.post(
                "/v1/diagnose",
                content=write_mcap(runs[2], d / "run.mcap").read_bytes(),
                headers={"content-type": "application/vnd.mcap"},
                params={"asset_id": "press-1", "operating_hours": "800"},
            ),
        ]
        no_accel = {k: v for k, v in body["channels"].items() if k != "nut_axial_accel"}
        answers.append(
            c.post("/v1/diagnose", json={**body, "channels": no_accel, "asset_id": "press-2"})
        )
        parquet = write_run_parquet(runs[1], d / "run.parquet")
        answers.append(
            c.post(
                "/v1/diagnose/file",
                files={"file": (XSS_NAME, parquet.read_bytes())},
                data={"asset_id": "rig-3"},
            )
        )
        check = write_run_parquet(short_check_run().without_truth(), d / "check.parquet")
        answers.append(
            c.post(
                "/v1/diagnose/file",
                files={"file": ("check.parquet", check.read_bytes())},
                data={"asset_id": "check-4"},
            )
        )
        assert [a.status_code for a in answers] == [200] * 6, [a.text for a in answers]
        assert answers[-1].json()["diagnosis"]["check_phases"]  # read phase by phase
        assert c.get("/v1/assets/check-4").json()["diagnoses"] == 1
        assert c.get("/v1/assets/press-1/prognosis").status_code == 200
        live.parquet = parquet
        yield live


@pytest.fixture(scope="module")
def browser(chromium_path):
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


class Watch:
    """What a page reports: console errors, uncaught exceptions, dialogs, and the JSON
    answers of the API it fetched (:meth:`received`, read before the next navigation)."""

    def __init__(self, page):
        self.errors: list[str] = []
        self.dialogs: list[str] = []
        self.responses: list = []
        self.urls: list[str] = []  # of every API answer, OK or not
        self.json: dict[str, object] = {}
        page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        page.on("pageerror", lambda e: self.errors.append(f"uncaught: {e}"))
        page.on("requestfailed", lambda r: self.errors.append(f"failed: {r.url}"))
        page.on("dialog", self._dialog)
        page.on("response", self._response)

    def _dialog(self, dialog):
        self.dialogs.append(dialog.message)
        dialog.dismiss()

    def _response(self, response):
        if "/v1/" in response.url:
            self.responses.append(response)
            self.urls.append(response.url.split("://", 1)[1].split("/", 1)[1])

    def received(self) -> dict[str, object]:
        """URL (without scheme and host) → JSON body of the API answers so far."""
        for response in self.responses:
            assert response.ok, (response.url, response.status)
            self.json[response.url.split("://", 1)[1].split("/", 1)[1]] = response.json()
        self.responses.clear()
        return self.json

    def reset(self):
        self.errors.clear()
        self.responses.clear()
        self.urls.clear()
        self.json.clear()


def _painted(page, selector: str) -> list[dict]:
    """Size and painted pixels of the canvases under ``selector``."""
    return page.evaluate(
        """(selector) => [...document.querySelectorAll(selector + " canvas")].map((c) => {
            const data = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
            let painted = 0;
            for (let i = 3; i < data.length; i += 4) if (data[i] !== 0) painted++;
            return {width: c.width, height: c.height, painted};
        })""",
        selector,
    )


def _loaded(page):
    page.wait_for_function(
        "() => !document.getElementById('status').textContent.startsWith('Loading')"
    )


def test_dashboard_in_chromium(service, browser, tmp_path):
    context = browser.new_context(viewport={"width": 1200, "height": 900})
    page = context.new_page()
    watch = Watch(page)

    # ---- the token: a page answers the login form (401); the form sets the cookie
    first = page.goto(service.url + "/assets/press-1")
    assert first.status == 401
    page.fill("input[name=token]", TOKEN)
    page.click("button[type=submit]")
    page.wait_for_url(service.url + "/assets/press-1")
    _loaded(page)
    page.wait_for_load_state("networkidle")  # its requests done before the next page
    cookies = {c["name"]: c for c in context.cookies()}
    session = cookies[SESSION_COOKIE]
    assert session["httpOnly"] and session["sameSite"] == "Strict"
    assert TOKEN not in session["value"]
    assert page.evaluate("document.cookie") == ""  # HttpOnly: no script can read it
    with httpx.Client(base_url=service.url) as c:
        jar = {"Cookie": f"{SESSION_COOKIE}={session['value']}"}
        for url in (
            "/",
            "/assets/press-1",
            "/upload",
            "/v1/assets",
            "/v1/assets/press-1/spectra",
            "/static/dashboard/asset.js",
        ):
            assert c.get(url).status_code == 401, url
            assert c.get(url, headers=jar).status_code == 200, url

    # ---- the fleet overview
    watch.reset()
    page.goto(service.url + "/")
    _loaded(page)
    rows = page.locator("#fleet tbody tr")
    assert rows.count() == 4
    assets = watch.received()["v1/assets?prognosis=true&limit=200"]["assets"]
    assert {a["asset_id"] for a in assets} == {"press-1", "press-2", "rig-3", "check-4"}
    assert page.locator("#fleet tbody tr", has_text="check-4").count() == 1
    press1 = page.locator("#fleet tbody tr", has_text="press-1")
    cells = press1.locator("td").all_text_contents()
    brief = next(a for a in assets if a["asset_id"] == "press-1")["prognosis"]
    assert cells[3].startswith(brief["headline"]["short"])  # the RUL as the library words it
    assert "µ" not in cells[2] and "(" in cells[2] and cells[4] == "3"
    press2 = page.locator("#fleet tbody tr", has_text="press-2").locator("td").all_text_contents()
    assert press2[3].startswith("–") and "at least 2" in press2[3]  # no RUL, and why
    # the status column: each asset's level as the service's rule gave it, in word and colour
    colours: dict[str, set] = {}
    for asset in assets:
        link = page.locator(f"a:text-is('{asset['asset_id']}')")
        word = page.locator("#fleet tbody tr", has=link).locator("td").first.locator(".status-word")
        level = asset["status"]["level"]
        assert level in ("healthy", "unknown", "watch", "alarm")
        assert word.text_content() == level
        assert f"status-{level}" in word.get_attribute("class").split()
        colour = word.evaluate("(e) => getComputedStyle(e).backgroundColor")
        assert colour not in ("", "rgba(0, 0, 0, 0)", "transparent"), (level, colour)
        colours.setdefault(level, set()).add(colour)
    # one colour per level, a different one for each level shown
    assert all(len(c) == 1 for c in colours.values())
    assert len(set().union(*colours.values())) == len(colours)
    assert watch.errors == [] and watch.dialogs == []
    page.screenshot(path=tmp_path / "overview.png", full_page=True)

    # ---- an asset: trends, probabilities, spectra with the defect frequencies
    watch.reset()
    page.click("#fleet a:text-is('press-1')")
    page.wait_for_url(service.url + "/assets/press-1")
    _loaded(page)
    page.wait_for_function(
        "(sel) => sel.every((s) => document.querySelector(s + ' canvas'))", arg=list(PLOTS)
    )
    for selector in PLOTS:
        canvases = _painted(page, selector)
        assert canvases, selector
        assert all(c["width"] > 300 and c["height"] > 100 for c in canvases), (selector, canvases)
        assert max(c["painted"] for c in canvases) > 2000, (selector, canvases)
    history = watch.received()["v1/assets/press-1/history?limit=1000"]["diagnoses"]
    assert [e["operating_hours"] for e in history] == [0.0, 400.0, 800.0]
    spectra = watch.json["v1/assets/press-1/spectra"]
    assert len(spectra["spectrum"]["frequency"]) > 500 and spectra["source"] == "mcap"
    assert len(spectra["envelope"]["amplitude"]) > 100
    defects = page.locator("#defects tbody th").all_text_contents()
    assert {"screw_flank", "nut_flank", "roller_flank", "gear_mesh"} <= set(defects)
    headline = watch.json["v1/assets/press-1?prognosis=true"]["prognosis"]["headline"]
    assert page.locator("#rul").text_content() == headline["text"]  # the library's one line
    assert f"rul-{headline['state']}" in page.locator("#rul").get_attribute("class").split()
    assert page.locator("#check").is_hidden()  # its recordings are no health check
    assert "Over operating hours" in page.locator("#trend-note").text_content()
    assert watch.errors == [] and watch.dialogs == []
    page.screenshot(path=tmp_path / "asset.png", full_page=True)

    # ---- a health check's asset: its phases, each with its reading and verdict
    watch.reset()
    page.goto(service.url + "/assets/check-4")
    _loaded(page)
    summary = watch.received()["v1/assets/check-4?prognosis=true"]
    check = summary["latest"]["check"]
    assert page.locator("#check").is_visible()
    rows = page.locator("#check-phases tbody tr")
    assert rows.count() == len(check) == 4
    for k, verdict in enumerate(check):
        cells = rows.nth(k).locator("td").all_text_contents()
        assert rows.nth(k).locator("th").text_content() == verdict["role"].replace("_", " ")
        assert cells[0] == (verdict["phase"] or "–")
        assert cells[1] == "read" if verdict["read"] else cells[1].startswith("not read")
        shown = [r for r in verdict["readings"] if r["value"] is not None]
        assert len(shown) > 0 and all(r["name"][len("check_") :] in cells[2] for r in shown)
    assert summary["status"]["level"] in page.locator("#check-note").text_content()
    assert watch.errors == [] and watch.dialogs == []
    page.screenshot(path=tmp_path / "check.png", full_page=True)

    # ---- an asset without the accelerometer channel: no spectra, said so
    watch.reset()
    page.goto(service.url + "/assets/press-2")
    _loaded(page)
    assert "No spectra stored" in page.locator("#spectra-note").text_content()
    assert page.locator("#spectra").is_hidden()
    assert len(_painted(page, "#clearance-plot")) > 0
    assert "v1/assets/press-2/spectra" not in watch.received()
    assert page.locator("#rul").text_content() == "–"
    assert "at least 2" in page.locator("#rul-detail").text_content()
    assert watch.errors == [] and watch.dialogs == []

    # ---- markup in data is text: the uploaded file's name
    watch.reset()
    page.goto(service.url + "/assets/rig-3")
    _loaded(page)
    page.wait_for_function("() => document.querySelector('#spectrum-plot canvas')")
    assert XSS_NAME in page.locator("#latest").text_content()
    assert XSS_NAME in page.locator("#spectra-note").text_content()
    assert page.locator("main img").count() == 0
    assert page.evaluate("() => document.querySelectorAll('img[src=x]').length") == 0
    assert watch.errors == [] and watch.dialogs == []

    # ---- the upload form: with operating hours (POST /v1/diagnose), then without (upload)
    watch.reset()
    page.goto(service.url + "/upload")
    for hours in ("120", ""):
        page.set_input_files("input[name=file]", str(service.parquet))
        page.fill("input[name=asset_id]", "press-4")
        page.fill("input[name=operating_hours]", hours)
        page.click("#upload-form button[type=submit]")
        page.wait_for_function("() => !document.getElementById('result').hidden")
        assert "Diagnosed run.parquet" in page.locator("#status").text_content()
        assert "(" in page.locator("#diagnosis").text_content()  # class and probability
    assert page.locator("#asset-link").get_attribute("href") == "/assets/press-4"
    # (Chromium does not keep the answers of requests with large bodies: the URLs, and what
    # the page shows and the service stored, tell)
    posted = [url for url in watch.urls if url.startswith("v1/diagnose")]
    assert posted == ["v1/diagnose?asset_id=press-4&operating_hours=120", "v1/diagnose/file"]
    assert watch.errors == [] and watch.dialogs == []
    with httpx.Client(base_url=service.url, headers={"Authorization": f"Bearer {TOKEN}"}) as c:
        stored = c.get("/v1/assets/press-4/history").json()["diagnoses"]
        assert [(e["source"], e["operating_hours"]) for e in stored] == [
            ("parquet", 120.0),
            ("file", None),
        ]
        assert c.get("/v1/assets/press-4/spectra").json()["source"] == "file"

    # ---- the watch sees console errors: an unknown asset's page reports its 404
    watch.reset()
    page.goto(service.url + "/assets/nobody")
    _loaded(page)
    assert page.locator("#status").text_content() == "No diagnosis is stored for asset nobody."
    assert any("404" in e for e in watch.errors), watch.errors

    # ---- an asset id carrying markup never becomes a page: the id pattern refuses it with a
    # JSON error (the browser shows it as text), and nothing in it runs
    watch.reset()
    refused = page.goto(service.url + "/assets/%3Cscript%3Ealert(1)%3C%2Fscript%3E")
    assert refused.status in (404, 422)
    assert refused.headers["content-type"].startswith("application/json")
    assert watch.dialogs == []
    assert page.evaluate("() => document.querySelectorAll('body script').length") == 0
    context.close()
