"""The validation report: every row well-formed, no expected reproduction failing."""

import json

import pytest

from prsm_health.cli import main
from prsm_health.validation import (
    NOT_COMPUTABLE,
    NOT_REPRODUCED,
    PAPER_INCONSISTENT,
    REPRODUCED,
    collect,
    reproduced,
    to_markdown,
)


@pytest.fixture(scope="module")
def rows():
    return collect()


def test_no_reproduction_fails(rows):
    failed = [r for r in rows if r.verdict == NOT_REPRODUCED]
    assert not failed, "\n".join(
        f"{r.paper} {r.where} {r.quantity}: {r.model_value}" for r in failed
    )


def test_rows_are_well_formed(rows):
    papers = {r.paper for r in rows}
    assert {"01", "04", "05"} <= papers
    for r in rows:
        assert r.verdict in (REPRODUCED, PAPER_INCONSISTENT, NOT_COMPUTABLE)
        if r.verdict == REPRODUCED:
            assert r.tolerance is not None and r.note, f"{r.quantity}: tolerance needs a reason"
            assert abs(r.error) <= r.tolerance
        else:
            assert r.note, f"{r.quantity}: a {r.verdict} row needs its reason"


def test_reproduced_helper_flags_a_miss():
    assert reproduced("x", "t", "q", "-", 1.0, 1.2, 0.1, "n").verdict == NOT_REPRODUCED
    assert reproduced("x", "t", "q", "-", 1.0, 1.05, 0.1, "n").verdict == REPRODUCED


def test_markdown_has_one_line_per_row(rows):
    md = to_markdown(rows)
    assert len(md.splitlines()) == len(rows) + 2


def test_validate_command_json(capsys, rows):
    assert main(["validate", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["rows"]) == len(rows)
    assert sum(data["summary"].values()) == len(rows)
