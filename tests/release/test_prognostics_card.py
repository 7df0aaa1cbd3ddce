"""prsm_health.release.prognostics_card: the prognostics model's card, from its metrics alone."""

import copy
import json

from prsm_health.prognostics import DEFAULT_PROGNOSTICS_MODEL
from prsm_health.release.prognostics_card import prognostics_card, write_prognostics_card

SHIPPED_METRICS = DEFAULT_PROGNOSTICS_MODEL.with_name("prognostics.metrics.json")
SHIPPED_CARD = DEFAULT_PROGNOSTICS_MODEL.with_name("PROGNOSTICS_CARD.md")


def test_card_of_the_shipped_metrics_is_the_shipped_card(tmp_path):
    # The card is generated from the metrics file, never edited by hand: regenerating it from
    # the shipped metrics gives the shipped card, character for character.
    metrics = json.loads(SHIPPED_METRICS.read_text(encoding="utf-8"))
    assert prognostics_card(metrics) == SHIPPED_CARD.read_text(encoding="utf-8")
    path = write_prognostics_card(metrics, tmp_path / "CARD.md")
    assert path.read_text(encoding="utf-8") == SHIPPED_CARD.read_text(encoding="utf-8")


def test_tables_follow_the_metrics():
    metrics = json.loads(SHIPPED_METRICS.read_text(encoding="utf-8"))
    fewer = copy.deepcopy(metrics)
    del fewer["held_out"]["physics"]
    fewer["per_unit"] = fewer["per_unit"][:2]
    fewer["sensitivity"]["usage"] = fewer["sensitivity"]["usage"][:1]
    fewer["sensitivity"]["cells"] = fewer["sensitivity"]["cells"][:1]
    lines = prognostics_card(fewer).splitlines()
    full = prognostics_card(metrics).splitlines()
    # one held-out method, two units and one usage row fewer: 1 + 4 + 2 lines
    assert len(full) - len(lines) == 7
    assert sum(line.startswith("| physics |") for line in lines) == 2  # CV table and by-age
