"""The dashboard's one rule for a target the model could not see (``PH.observable``,
``PH.notObservableText`` in static/dashboard/common.js): the same texts as the CLI's
(prsm_health.diagnostics.not_observable) from the same JSON — run in headless Chromium on common.js
alone (no server) —, and the fleet and asset pages showing them, greyed, with the hidden
diagnoses out of the class plot (a real server; diagnoses written to its store, no
simulation)."""

import json
from importlib.resources import files

import pytest
from live_server import LiveServer
from test_dashboard_browser import (  # noqa: F401 (chromium_path: a fixture; pytestmark: the skip)
    CHROMIUM_ARGS,
    Watch,
    _loaded,
    _painted,
    chromium_path,
    pytestmark,
)

from prsm_health.apps.service import create_app
from prsm_health.diagnostics.answer import not_observable
from prsm_health.diagnostics.contract import Diagnosis
from prsm_health.diagnostics.not_observable import not_observable_text

COMMON_JS = files("prsm_health.apps.service") / "static" / "dashboard" / "common.js"
MODEL = {"name": "m", "version": "1", "design": "paper01", "instrumentation": None}


def _diagnosis(seen) -> dict:
    return Diagnosis(
        clearance={"estimate": 4.7e-6, "lower": 0.1e-6, "upper": 39.3e-6},
        fault_class="wear" if seen else "cannot_tell",
        class_probabilities={"healthy": 0.2, "wear": 0.38, "spall": 0.42},
        observability={"clearance": seen, "fault": seen},
        indicators={},
        model=MODEL,
        undecided=None if seen else not_observable(["a load or motion reversal"], has_check=True),
    ).to_json()


@pytest.fixture(scope="module")
def browser(chromium_path):  # noqa: F811
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@pytest.fixture(scope="module")
def page(browser):
    page = browser.new_page()
    page.set_content("<html><body></body></html>")
    page.add_script_tag(content=COMMON_JS.read_text())
    return page


def _call(page, expression: str, diagnosis: dict):
    return page.evaluate(f"(d) => {expression}", json.loads(json.dumps(diagnosis)))


@pytest.mark.parametrize("share", [0.0, False])
def test_the_pages_say_not_observable_as_the_cli_does(page, share):
    d = _diagnosis(False)
    d["observability"] = {"clearance": share, "fault": share}
    for target in ("clearance", "fault"):
        expected = not_observable_text(d, target)
        assert expected.startswith("not observable — needs a load or motion reversal")
        assert _call(page, f"PH.notObservableText(d, {target!r})", d) == expected
        assert _call(page, f"PH.observableClass(d, {target!r})", d) == "not-observable"
    assert _call(page, "PH.clearanceText(d)", d) == not_observable_text(d, "clearance")
    text = _call(page, "PH.classText(d)", d)
    assert text == "cannot_tell (not observable — needs a load or motion reversal)"
    assert "0.42" not in text


def test_an_observable_diagnosis_shows_its_numbers(page):
    d = _diagnosis(0.5)  # a recording that saw it in half its windows
    assert _call(page, "PH.clearanceText(d)", d) == "4.70 (0.10 – 39.30)"
    assert _call(page, "PH.classText(d)", d) == "wear (0.38)"
    assert _call(page, "PH.observableClass(d, 'clearance')", d) == ""
    # stored before observability was kept, and a check's measured clearance: numbers
    del d["observability"]
    assert _call(page, "PH.clearanceText(d)", d) == "4.70 (0.10 – 39.30)"
    measured = {**_diagnosis(False), "measured_clearance": {"commissioned": True}}
    assert _call(page, "PH.clearanceText(d)", measured) == "4.70 (0.10 – 39.30)"


@pytest.mark.slow  # ≈ 6 s: the diagnosis model's load (the service needs one) and a browser
def test_the_pages_grey_what_is_not_observable(browser, tmp_path):
    from prsm_health.diagnostics.diagnosis import load_bundle

    app = create_app(None, tmp_path / "history.sqlite", bundle=load_bundle(), warmup=False)
    store = app.state.store
    store.add("unit-1", [_diagnosis(True)], operating_hours=10.0)
    store.add("unit-1", [_diagnosis(False)], operating_hours=20.0)  # the latest: hidden
    hidden = not_observable_text(_diagnosis(False), "clearance")
    with LiveServer(app) as live:
        page = browser.new_page()
        watch = Watch(page)
        page.goto(live.url + "/")
        _loaded(page)
        cells = page.locator("#fleet tbody tr").first.locator("td")
        assert cells.nth(1).text_content().startswith("cannot_tell (not observable")
        assert cells.nth(2).text_content() == hidden
        assert "not-observable" in cells.nth(2).get_attribute("class").split()
        page.goto(live.url + "/assets/unit-1")
        _loaded(page)
        latest = dict(
            zip(
                page.locator("#latest dt").all_text_contents(),
                page.locator("#latest dd").all(),
            )
        )
        clearance = latest["Clearance [µm] (90 % interval)"]
        assert clearance.text_content() == hidden
        assert clearance.get_attribute("class") == "not-observable"
        assert (
            "1 diagnosis(es) could not see the clearance"
            in page.locator("#trend-note").text_content()
        )
        assert (
            "1 diagnosis(es) could not see the fault class"
            in page.locator("#class-note").text_content()
        )
        for plot in ("#clearance-plot", "#class-plot"):
            assert any(c["painted"] > 0 for c in _painted(page, plot)), plot
        assert watch.errors == [] and watch.dialogs == []
