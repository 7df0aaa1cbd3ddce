"""How the commands print: JSON, aligned tables, and the few number formats the tables share.

Every table of the CLI goes through :func:`print_table`, so a share reads the same everywhere
("in 100 % of windows"), and a missing metric the same ("–").
"""

from __future__ import annotations

from prsm_health.core.jsonable import dumps


def print_json(obj) -> None:
    """``obj`` as indented JSON (numpy scalars and arrays included)."""
    print(dumps(obj, indent=2))


def print_table(rows: list[tuple[str, object, str]]) -> None:
    """Rows of (name, value, unit) in two aligned columns; floats to 6 significant digits."""
    width = max(len(name) for name, _, _ in rows)
    for name, value, unit in rows:
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{name:<{width}}  {text} {unit}".rstrip())


def um(value) -> str:
    """A length [m] in µm, 5 wide with one decimal; '–' where there is none (None)."""
    return "  –" if value is None else f"{1e6 * value:5.1f}"


def scaled(value, factor: float = 1.0):
    """A metric for the table; '–' where it could not be computed (None)."""
    return "–" if value is None else factor * value


def share(value, of: str) -> str:
    """A fraction [0, 1] as a percentage of what it counts: ``in 75 % of windows``; '–' for
    None. A bool (one window's observability) is 0 % or 100 %."""
    if value is None:
        return "–"
    return f"in {100 * float(value):.3g} % of {of}"


def hours(value: float) -> str:
    """Hours for the summary: whole hours from 100 h, else 3 significant digits."""
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.3g}"


def print_columns(header: tuple[str, ...], rows: list[tuple]) -> None:
    """A table of several columns under ``header``, each column as wide as its widest cell;
    floats to 4 significant digits, None as '–'."""

    def cell(value) -> str:
        if value is None:
            return "–"
        return f"{value:.4g}" if isinstance(value, float) else str(value)

    cells = [tuple(header)] + [tuple(cell(v) for v in row) for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    for r in cells:
        print("  ".join(f"{c:<{w}}" for c, w in zip(r, widths)).rstrip())
