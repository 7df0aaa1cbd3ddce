"""Validation report: the model against every number the papers print.

One module per paper (``paper01.py`` …) exposes ``rows() -> list[Row]``. A row either
*expects to reproduce* the paper value within a stated tolerance — and then fails loudly if it
does not — or records why the paper number cannot be matched: the paper contradicts itself
("paper inconsistent") or lacks the inputs ("not computable"). ``prsm-health validate`` prints
the report; ``tools/release/make_validation_doc.py`` writes docs/validation.md from it.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import asdict, dataclass

REPRODUCED = "reproduced"
NOT_REPRODUCED = "NOT REPRODUCED"
PAPER_INCONSISTENT = "paper inconsistent"
NOT_COMPUTABLE = "not computable"

#: Modules contributing rows, in report order.
PAPER_MODULES = ("paper01", "paper02", "paper03", "paper04", "paper05")


@dataclass(frozen=True)
class Row:
    """One paper number compared with the model.

    Parameters
    ----------
    paper : str
        Paper file stem, e.g. ``"01"``.
    where : str
        Table, equation or section, e.g. ``"Table 2, 10 kN"`` or ``"eq. (14)"``.
    quantity : str
        What is compared.
    unit : str
        Unit of both values as printed (the report may show non-SI units for readability).
    paper_value : float or None
    model_value : float or None
    verdict : str
        One of reproduced / NOT REPRODUCED / paper inconsistent / not computable.
    tolerance : float or None
        Relative tolerance used to judge a reproduction.
    note : str
        Reading, reason, or justification of the tolerance.
    """

    paper: str
    where: str
    quantity: str
    unit: str
    paper_value: float | None
    model_value: float | None
    verdict: str
    tolerance: float | None = None
    note: str = ""

    @property
    def error(self) -> float | None:
        """Relative error (model − paper)/|paper|, or None when either value is missing."""
        if self.paper_value is None or self.model_value is None or self.paper_value == 0:
            return None
        return (self.model_value - self.paper_value) / abs(self.paper_value)

    @property
    def failed(self) -> bool:
        return self.verdict == NOT_REPRODUCED

    def as_dict(self) -> dict:
        d = asdict(self)
        d["error"] = self.error
        return d


def reproduced(paper, where, quantity, unit, paper_value, model_value, tolerance, note="") -> Row:
    """A row that must match the paper within ``tolerance`` (relative); justify it in ``note``."""
    err = abs(model_value - paper_value) / abs(paper_value)
    ok = math.isfinite(err) and err <= tolerance
    verdict = REPRODUCED if ok else NOT_REPRODUCED
    return Row(paper, where, quantity, unit, paper_value, model_value, verdict, tolerance, note)


def inconsistent(paper, where, quantity, unit, paper_value, model_value, note) -> Row:
    """A paper number that contradicts the paper's own formulas or physics; say why."""
    if not note:
        raise ValueError("an inconsistent row needs its reason")
    return Row(
        paper, where, quantity, unit, paper_value, model_value, PAPER_INCONSISTENT, None, note
    )


def not_computable(paper, where, quantity, unit, paper_value, model_value, note) -> Row:
    """A paper number whose inputs the paper does not give; say what is missing."""
    if not note:
        raise ValueError("a not-computable row needs its reason")
    return Row(paper, where, quantity, unit, paper_value, model_value, NOT_COMPUTABLE, None, note)


def collect() -> list[Row]:
    """All rows of all papers, in report order."""
    out: list[Row] = []
    for name in PAPER_MODULES:
        module = importlib.import_module(f"{__name__}.{name}")
        out.extend(module.rows())
    return out


def _fmt(value: float | None) -> str:
    if value is None:
        return "–"
    if value == 0:
        return "0"
    magnitude = abs(value)
    if 1e-3 <= magnitude < 1e5:
        return f"{value:.4g}"
    return f"{value:.4e}"


def to_markdown(rows: list[Row]) -> str:
    """The report as a Markdown table (one row per paper number)."""
    lines = [
        "| paper | where | quantity | unit | paper | model | error | verdict | note |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        err = "–" if r.error is None else f"{100 * r.error:+.2f} %"
        note = r.note.replace("|", "\\|")
        lines.append(
            f"| {r.paper} | {r.where} | {r.quantity} | {r.unit} | {_fmt(r.paper_value)} | "
            f"{_fmt(r.model_value)} | {err} | {r.verdict} | {note} |"
        )
    return "\n".join(lines)


def summary(rows: list[Row]) -> dict[str, int]:
    """Count of rows per verdict."""
    counts: dict[str, int] = {}
    for r in rows:
        counts[r.verdict] = counts.get(r.verdict, 0) + 1
    return counts
