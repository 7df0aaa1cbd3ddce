"""Regenerate docs/validation.md's generated table from ``prsm-health validate``.

The document has hand-written sections (readings, departures from the papers) and one
generated block between the markers below; only that block is replaced.

    python tools/release/make_validation_doc.py
"""

from __future__ import annotations

import pathlib
import sys

from prsm_health.validation import collect, summary, to_markdown

BEGIN = "<!-- BEGIN GENERATED: prsm-health validate --markdown -->"
END = "<!-- END GENERATED -->"
DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "validation.md"


def main() -> int:
    rows = collect()
    counts = ", ".join(f"{n} {verdict}" for verdict, n in summary(rows).items())
    block = f"{BEGIN}\n\n{to_markdown(rows)}\n\nSummary: {counts}.\n\n{END}"
    text = DOC.read_text()
    if BEGIN not in text or END not in text:
        print(f"error: {DOC} lacks the generated-block markers", file=sys.stderr)
        return 2
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    DOC.write_text(head + block + tail)
    print(f"wrote {DOC} ({len(rows)} rows: {counts})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
