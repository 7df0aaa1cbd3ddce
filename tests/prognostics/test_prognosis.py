"""The Prognosis answer, declared once: typed parts made from the mappings a model gives, read
as mappings still, and a JSON made from the declared fields; its headline, the one rule of what
a maintainer reads."""

import dataclasses
import json
import math
import re

import pytest

from prsm_health.core.jsonable import dumps
from prsm_health.prognostics import Prognosis
from prsm_health.prognostics.prognosis import (
    AT_LIMIT_HOURS,
    HEADLINE_STATES,
    Headline,
    HealthIndicator,
    RulHours,
)

INDICATOR = {
    "name": "clearance",
    "unit": "m",
    "threshold": 3e-5,
    "ages_hours": [0.0, 100.0],
    "values": [1e-5, 1.2e-5],
    "lower": [0.9e-5, 1.1e-5],
    "upper": [1.1e-5, 1.3e-5],
    "current": 1.2e-5,
}


def test_parts_typed_and_still_read_as_mappings():
    p = Prognosis({"estimate": 900.0, "lower": 400.0, "upper": math.inf}, INDICATOR, {"name": "x"})
    assert isinstance(p.rul_hours, RulHours) and isinstance(p.health_indicator, HealthIndicator)
    assert p.rul_hours.estimate == p.rul_hours["estimate"] == 900.0
    assert p.health_indicator == INDICATOR and p.warnings == []
    out = p.as_dict()
    assert list(out) == ["rul_hours", "health_indicator", "model", "warnings", "headline"]
    assert out["rul_hours"] == {"estimate": 900.0, "lower": 400.0, "upper": None}  # not finite
    assert out["health_indicator"] == INDICATOR and out["model"] == {"name": "x"}
    assert out["headline"] == p.headline and isinstance(p.headline, Headline)
    # the headline is made from the other fields, never given: read back without it
    read_back = {k: v for k, v in out.items() if k != "headline"}
    assert Prognosis(**read_back | {"rul_hours": p.rul_hours}) == p


# ----------------------------------------------------------------------------- the headline
def _prognosis(estimate, lower, upper, current, threshold=32.7e-6) -> Prognosis:
    rul = {"estimate": estimate, "lower": lower, "upper": upper}
    return Prognosis(rul, INDICATOR | {"current": current, "threshold": threshold}, {})


def _words(headline: Headline) -> str:
    return headline.text + " | " + headline.short


def _reads_0_h(words: str) -> bool:
    """Whether a text gives a RUL of 0 h (0, 0.0, 0.00 … h; not 300 h, nor [0, 242])."""
    return re.search(r"(?<![\d.])0(\.0*)? h", words) is not None


def test_reads_0_h():
    assert _reads_0_h("RUL 0 h [0, 242]") and _reads_0_h("0.00 h") and _reads_0_h("(0.0 h)")
    assert not _reads_0_h("300 h [0, 242]") and not _reads_0_h("< 1 h, up to 10 h")


def test_below_the_threshold_a_median_of_0_reads_at_the_limit_never_0_h():
    # the user's asset: the fitted trend reached the threshold, the latest reading did not
    h = _prognosis(0.0, 0.0, 242.0, 31.2e-6).headline
    assert h.state == "at_limit"
    assert h.text == (
        "at the limit by its trend: RUL < 1 h median, up to 242 h (90 %); latest clearance "
        "31.2 µm, below the 32.7 µm threshold — check it again soon"
    )
    assert h.short == "at the limit: < 1 h, up to 242 h"
    for estimate in (0.0, 0.004, 0.6, math.nextafter(AT_LIMIT_HOURS, 0)):
        h = _prognosis(estimate, 0.0, 242.0, 31.2e-6).headline
        assert h.state == "at_limit" and not _reads_0_h(_words(h))
    # the interval's upper bound below 1 h too, or unbounded
    assert "up to 0.5 h" in _prognosis(0.1, 0.0, 0.5, 31.2e-6).headline.text
    assert "no upper bound" in _prognosis(0.0, 0.0, math.inf, 31.2e-6).headline.text


def test_at_or_above_the_threshold_reads_threshold_reached_overhaul():
    for current in (32.7e-6, 33.04e-6):
        h = _prognosis(0.0, 0.0, 0.0, current).headline  # the model's RUL 0 there
        assert h.state == "threshold_reached"
        assert h.text.startswith("threshold reached — overhaul: latest clearance")
        assert "at or above the 32.7 µm threshold" in h.text and h.short.startswith("threshold")
    assert "33.0 µm" in _prognosis(0.0, 0.0, 0.0, 33.04e-6).headline.text
    # reached whatever the trend says: the reading rules
    assert _prognosis(50.0, 10.0, 90.0, 33e-6).headline.state == "threshold_reached"


def test_with_life_left_the_median_interval_reading_and_threshold_together():
    h = _prognosis(420.4, 310.2, 559.9, 24.1e-6).headline
    assert h.state == "remaining"
    assert (
        h.text == "RUL 420 h [310, 560] (90 %) — latest clearance 24.1 µm of the 32.7 µm threshold"
    )
    assert h.short == "420 h [310, 560]"
    # hours rounded as read: whole from 10 h, else two significant digits
    assert _prognosis(3.456, 0.27, 12.6, 24.1e-6).headline.short == "3.5 h [0.27, 13]"
    assert _prognosis(1.0, 0.0, 9.96, 24.1e-6).headline.short == "1 h [0, 10]"
    # a reading that rounds to the threshold gets the decimals that tell them apart
    assert "32.66 µm of the 32.70 µm threshold" in _prognosis(5, 1, 9, 32.66e-6).headline.text


@pytest.mark.parametrize(
    "rul, current, threshold, state",
    [
        ((math.nan, math.nan, math.nan), 24.1e-6, 32.7e-6, "unknown"),
        ((None, None, None), 24.1e-6, 32.7e-6, "unknown"),  # read back from JSON
        ((300.0, math.nan, math.inf), 24.1e-6, 32.7e-6, "remaining"),
        ((300.0, 100.0, 500.0), math.nan, 32.7e-6, "remaining"),
        ((0.0, 0.0, 242.0), None, math.nan, "at_limit"),
        ((math.nan, 0.0, 1.0), math.inf, 32.7e-6, "unknown"),
    ],
)
def test_non_finite_numbers_never_read_nan(rul, current, threshold, state):
    h = _prognosis(*rul, current, threshold).headline
    assert h.state == state and state in HEADLINE_STATES
    words = _words(h).lower()
    assert "nan" not in words and "inf" not in words and "none" not in words
    assert not _reads_0_h(words)
    assert json.loads(dumps(_prognosis(*rul, current, threshold).as_dict()))["headline"] == h
    if not math.isfinite(current or math.nan) or not math.isfinite(threshold):
        assert "unknown" in h.text and "below the" not in h.text


def test_the_headline_follows_the_prognosis_it_is_of():
    p = _prognosis(0.0, 0.0, 242.0, 31.2e-6)
    crossed = dataclasses.replace(
        p, health_indicator=p.health_indicator.to_json() | {"current": 33e-6}
    )
    assert crossed.headline.state == "threshold_reached" and p.headline.state == "at_limit"
    with pytest.raises(TypeError):
        Prognosis(p.rul_hours, p.health_indicator, {}, headline=p.headline)  # never given
