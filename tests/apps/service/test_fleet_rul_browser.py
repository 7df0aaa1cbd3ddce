"""The fleet page in a real browser (headless Chromium against a real server on 127.0.0.1, as
test_dashboard_browser.py drives it): the RUL column reads each asset's prognosis headline —
never "0 h" while the clearance is below the threshold — and its header button sorts the
assets by RUL, most urgent first, then the reverse, by mouse and by keyboard.

Cheap: no simulation. The prognostics model is fitted on a small synthetic fleet (the
exponential degradation model, as test_service_prognosis.py does), the assets' diagnoses are
written to the store directly, and the one state a real history does not give on demand (the
fitted trend past the threshold while the latest reading is below it) is the route's answer
for one asset replaced by such a prognosis.
"""

import dataclasses
import os
import re

import numpy as np
import pytest
from live_server import LiveServer
from synthetic_units import Z90, fitted_model, unit
from test_dashboard_browser import CHROMIUM, CHROMIUM_ARGS, Watch, _loaded

from prsm_health.apps.service import create_app
from prsm_health.apps.service.routes import prognosis as prognosis_route
from prsm_health.diagnostics.diagnosis import load_bundle

pytestmark = pytest.mark.skipif(
    os.environ.get("PRSM_HEALTH_SKIP_BROWSER") == "1", reason="PRSM_HEALTH_SKIP_BROWSER=1"
)

#: Most urgent first: the threshold reached, at the limit by its trend, then by median RUL;
#: the asset without a prognosis last.
URGENT_FIRST = ["worn-out", "edge", "old", "middle", "young"]
NO_PROGNOSIS = "new-one"


def _store(store, asset: str, points) -> None:
    for hours, clearance, sd in points:
        diagnosis = {
            "clearance": {
                "estimate": clearance,
                "lower": clearance - Z90 * sd,
                "upper": clearance + Z90 * sd,
            },
            "fault_class": "wear",
            "class_probabilities": {"wear": 1.0},
            "indicators": {},
            "model": {"name": "prsm-default", "version": "1", "design": "paper01"},
        }
        store.add(asset, [diagnosis], operating_hours=hours)


def _life_so_far(seed: int, fraction: float, n_points=12):
    """The first ``fraction`` of a unit's life, ``n_points`` diagnoses."""
    ages, estimate, sd, _ = unit(np.random.default_rng(seed), round(n_points / fraction))
    return list(zip(ages[:n_points].tolist(), estimate[:n_points].tolist(), sd[:n_points].tolist()))


def _reads_0_h(text: str) -> bool:
    return re.search(r"(?<![\d.])0(\.0*)? h", text) is not None


@pytest.fixture(scope="module")
def chromium_path():
    if not os.access(CHROMIUM, os.X_OK):
        pytest.fail(f"{CHROMIUM} not found (apt-get install -y chromium)")
    return CHROMIUM


@pytest.mark.slow  # ≈ 5.5 s: the diagnosis model's load (3.5 s) and a browser
def test_fleet_page_sorts_by_rul_most_urgent_first(chromium_path, tmp_path, monkeypatch):
    from playwright.sync_api import sync_playwright

    app = create_app(
        None,
        tmp_path / "history.sqlite",
        bundle=load_bundle(),
        warmup=False,
        prognostics_model=fitted_model(),
    )
    store = app.state.store
    # stored in an order unlike the urgency (the page lists the most recently seen first)
    _store(store, "young", _life_so_far(1, 0.3))
    _store(store, NO_PROGNOSIS, [(5.0, 9e-6, 0.3e-6)])  # one diagnosis: no prognosis
    _store(store, "old", _life_so_far(2, 0.9))
    worn = _life_so_far(3, 0.95)
    _store(store, "worn-out", worn[:-1] + [(worn[-1][0], 31e-6, 0.3e-6)])  # past 30 µm
    _store(store, "middle", _life_so_far(4, 0.6))
    _store(store, "edge", _life_so_far(5, 0.9))

    real = prognosis_route.prognose_readings

    def at_the_limit(rows, model, method, asset):
        # "edge": the fitted trend has reached the threshold, the latest reading has not
        prognosis, history = real(rows, model, method, asset=asset)
        if asset == "asset 'edge'":
            prognosis = dataclasses.replace(
                prognosis,
                rul_hours={"estimate": 0.0, "lower": 0.0, "upper": 242.0},
                health_indicator=prognosis.health_indicator.to_json() | {"current": 29.2e-6},
            )
        return prognosis, history

    monkeypatch.setattr(prognosis_route, "prognose_readings", at_the_limit)

    with LiveServer(app) as live, sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path, args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        watch = Watch(page)
        page.goto(live.url + "/")
        _loaded(page)
        assets = watch.received()["v1/assets?prognosis=true&limit=200"]["assets"]
        briefs = {a["asset_id"]: a["prognosis"] for a in assets}
        assert briefs["worn-out"]["headline"]["state"] == "threshold_reached"
        assert briefs["edge"]["headline"]["state"] == "at_limit"
        assert briefs["edge"]["rul_hours"]["estimate"] == 0.0
        assert {briefs[a]["headline"]["state"] for a in ("old", "middle", "young")} == {"remaining"}
        medians = [briefs[a]["rul_hours"]["estimate"] for a in URGENT_FIRST[2:]]
        assert 1.0 <= medians[0] < medians[1] < medians[2]
        assert "headline" not in briefs[NO_PROGNOSIS] and briefs[NO_PROGNOSIS]["status"] == 422

        def names():
            return page.locator("#fleet tbody th").all_text_contents()

        def rul_cell(asset):
            row = page.locator("#fleet tbody tr", has=page.locator(f"a:text-is('{asset}')"))
            return row.locator("td").nth(3).text_content()

        seen_first = names()
        assert seen_first == ["edge", "middle", "worn-out", "old", NO_PROGNOSIS, "young"]
        # the RUL cells: each asset's headline in brief, never "0 h" below the threshold
        for asset in URGENT_FIRST:
            assert rul_cell(asset).startswith(briefs[asset]["headline"]["short"])
        assert rul_cell("young") == briefs["young"]["headline"]["short"]  # "… h [lower, upper]"
        assert re.fullmatch(r"\d+ h \[\d+, \d+\]", rul_cell("young"))
        edge = rul_cell("edge")
        assert edge.startswith("at the limit: < 1 h, up to 242 h") and not _reads_0_h(edge)
        assert "29.2 µm, below the 30.0 µm threshold" in edge  # the headline below it
        assert rul_cell("worn-out").startswith("threshold reached — overhaul")
        assert rul_cell(NO_PROGNOSIS).startswith("–") and "at least 2" in rul_cell(NO_PROGNOSIS)

        header = page.locator("#rul-column")
        button = page.locator("#rul-column button")
        assert header.get_attribute("aria-sort") == "none"
        assert button.get_attribute("type") == "button"
        # a click: most urgent first; again: the reverse; without a prognosis last either way
        button.click()
        assert names() == URGENT_FIRST + [NO_PROGNOSIS]
        assert header.get_attribute("aria-sort") == "ascending"
        button.click()
        assert names() == URGENT_FIRST[::-1] + [NO_PROGNOSIS]
        assert header.get_attribute("aria-sort") == "descending"
        # the keyboard: the header's button takes the focus, Enter and Space sort
        page.focus("#fleet tbody a >> nth=0")
        page.keyboard.press("Shift+Tab")  # back to the header's button
        assert page.evaluate("document.activeElement.id") == "sort-rul"
        page.keyboard.press("Enter")
        assert names() == URGENT_FIRST + [NO_PROGNOSIS]
        page.keyboard.press("Space")
        assert names() == URGENT_FIRST[::-1] + [NO_PROGNOSIS]
        # the rows move whole: each keeps its own cells
        assert rul_cell("young") == briefs["young"]["headline"]["short"]
        assert watch.errors == [] and watch.dialogs == []
        page.screenshot(path=tmp_path / "fleet-sorted.png", full_page=True)
        browser.close()
