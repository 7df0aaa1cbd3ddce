"""The Prognosis answer, declared once: typed parts made from the mappings a model gives, read
as mappings still, and a JSON made from the declared fields."""

import math

from prsm_health.prognostics import Prognosis
from prsm_health.prognostics.prognosis import HealthIndicator, RulHours

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
    assert list(out) == ["rul_hours", "health_indicator", "model", "warnings"]
    assert out["rul_hours"] == {"estimate": 900.0, "lower": 400.0, "upper": None}  # not finite
    assert out["health_indicator"] == INDICATOR and out["model"] == {"name": "x"}
    assert Prognosis(**out | {"rul_hours": p.rul_hours}) == p
