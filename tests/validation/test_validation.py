"""The validation report: one test per paper number, every row well-formed.

Each row of :func:`prsm_health.validation.collect` is its own test, with an id
``paper<NN>-<where>-<quantity>`` (e.g. ``paper01-3-2-carrier-frequency-f-p-at-100-rad-s``), so a
failure names the paper number it concerns and ``-k`` selects rows (``-k paper04``).
"""

import functools
import json
import re
import unicodedata

import pytest

from prsm_health.apps.cli import main
from prsm_health.validation import (
    NOT_COMPUTABLE,
    NOT_REPRODUCED,
    PAPER_INCONSISTENT,
    REPRODUCED,
    Row,
    collect,
    reproduced,
    to_markdown,
)


@functools.cache
def _rows() -> tuple[Row, ...]:
    """Every row, computed once per test session (collecting runs the models)."""
    return tuple(collect())


# Symbols of the row texts spelt out, so ids stay readable in ASCII ("b = 10 µm" → "b-10-um").
_SPELL = str.maketrans(
    {
        "µ": "u",
        "μ": "u",
        "Δ": "d",
        "δ": "d",
        "α": "alpha",
        "β": "beta",
        "γ": "gamma",
        "η": "eta",
        "θ": "theta",
        "λ": "lambda",
        "π": "pi",
        "ρ": "rho",
        "φ": "phi",
        "ω": "omega",
        "°": "deg",
        "′": "p",
        "·": "-",
    }
)


def _slug(text: str) -> str:
    text = unicodedata.normalize("NFKD", text.translate(_SPELL))
    text = text.encode("ascii", "ignore").decode().lower()
    return re.sub(r"[^a-z0-9]+", "-", text).strip("-")


def _row_ids(rows) -> list[str]:
    """``paper<NN>-<where>-<quantity>`` per row, made unique by a suffix where two coincide."""
    ids, seen = [], {}
    for r in rows:
        base = f"paper{r.paper}-{_slug(r.where)}-{_slug(r.quantity)}"
        seen[base] = seen.get(base, 0) + 1
        ids.append(base if seen[base] == 1 else f"{base}-{seen[base]}")
    return ids


@pytest.fixture(scope="module")
def rows():
    return list(_rows())


@pytest.mark.parametrize("row", _rows(), ids=_row_ids(_rows()))
def test_row(row):
    assert not row.failed, (
        f"paper {row.paper}, {row.where}, {row.quantity}: model {row.model_value} {row.unit} "
        f"vs paper {row.paper_value} {row.unit} (error {row.error}, tolerance {row.tolerance}); "
        f"{row.note}"
    )


def test_row_ids_are_unique_and_readable():
    ids = _row_ids(_rows())
    assert len(set(ids)) == len(ids)
    assert all(re.fullmatch(r"paper\d\d-[a-z0-9-]+", i) for i in ids)


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
