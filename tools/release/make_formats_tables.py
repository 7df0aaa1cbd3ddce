"""Print the channel tables of docs/formats.md from the channel contract (prsm_health.core.channels).

The tables in docs/formats.md are this script's output pasted between its markers; rerun it
after changing :data:`prsm_health.core.channels.CHANNELS` or :data:`~prsm_health.core.channels.TRUTH_CHANNELS`
and paste again, or check that the doc is current (a test does):

    python tools/release/make_formats_tables.py            # print the Markdown tables
    python tools/release/make_formats_tables.py --check    # exit 1 if docs/formats.md differs
"""

from __future__ import annotations

import pathlib
import sys

from prsm_health.core.channels import CHANNELS, TRUTH_CHANNELS, UNITS, truth_column

BEGIN = "<!-- BEGIN GENERATED: tools/release/make_formats_tables.py -->"
END = "<!-- END GENERATED -->"
DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "formats.md"


def channel_table() -> str:
    """The measured channels (``time`` first), then the truth signals, as Markdown tables in
    contract order."""
    lines = [
        "| measured channel | unit | sensor | MCAP topic / field | meaning |",
        "|---|---|---|---|---|",
        f"| `time` | {UNITS['time']} | data logger clock | message `log_time` "
        "(ns from run start) | sample time from run start |",
    ]
    for c in CHANNELS:
        lines.append(
            f"| `{c.name}` | {c.unit} | {c.sensor} | `{c.topic}` / `{c.field}` | {c.meaning} |"
        )
    lines += [
        "",
        "| truth signal | Parquet/CSV column | unit | its sensor reading, or why no sensor gives it | meaning |",
        "|---|---|---|---|---|",
    ]
    for c in TRUTH_CHANNELS:
        lines.append(
            f"| `{c.name}` | `{truth_column(c.name)}` | {c.unit} | {c.sensor} | {c.meaning} |"
        )
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    table = channel_table()
    if "--check" not in argv:
        print(table)
        return 0
    text = DOC.read_text()
    if BEGIN not in text or END not in text:
        print(f"error: {DOC} lacks the generated-block markers", file=sys.stderr)
        return 2
    current = text.split(BEGIN, 1)[1].split(END, 1)[0].strip()
    if current != table:
        print(f"{DOC}: channel tables are stale; paste the output of {__file__}", file=sys.stderr)
        return 1
    print(f"{DOC}: channel tables are current")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
