"""Fingerprint what users see, to show a refactor changed nothing that was not meant to change.

Runs the ``prsm-health`` command line (so it works on any layout of the package) and
records, per behaviour and per part of it, a SHA-256 digest — and for the JSON parts the
values, so that a change can be shown key by key:

- ``validate``: ``prsm-health validate --json`` (the papers-vs-model report);
- ``simulate_parquet.*`` / ``simulate_mcap.*``: a seeded ``simulate`` written to Parquet and to
  MCAP, by content: the signal columns / messages (values, log times), the units, the labels,
  the scenario — not by file bytes, which carry the writer library's version;
- ``diagnose_shipped.*``: the shipped model's ``diagnose --json`` of that MCAP recording: its
  numbers (clearance, class, probabilities, indicators, OOD score, observability), its model
  reference, its warnings.

Usage::

    # on the old commit, e.g. a worktree in /tmp/old (run from outside the new checkout):
    PYTHONPATH=/tmp/old python tools/release/behaviour_fingerprint.py \
        --command "python -m prsm_health.cli" --out before.json
    python tools/release/behaviour_fingerprint.py --compare before.json   # on the new one

``--compare`` prints each part that differs (for a JSON part, the keys added, removed and
changed) and exits 1 if any did. Digests are exact: compare runs made on one machine with one
set of library versions (a seeded run is reproducible there, not across CPUs;
docs/formats.md → Reproducibility).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SIMULATE = [
    "simulate", "--clearance", "18e-6", "--speed", "90", "--load", "2000",
    "--load-profile", "reversing", "--load-amplitude", "1500", "--load-frequency", "8",
    "--duration", "0.6", "--seed", "11",
]  # fmt: skip


COMMAND: list[str] = []


def _cli() -> list[str]:
    if COMMAND:
        return [sys.executable if word == "python" else word for word in COMMAND]
    found = shutil.which("prsm-health") or str(Path(sys.executable).with_name("prsm-health"))
    return [found]


def _run(args: list[str]) -> str:
    done = subprocess.run(_cli() + args, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"prsm-health {' '.join(args)} failed: {done.stderr.strip()}")
    return done.stdout


def _digest(chunks) -> str:
    h = hashlib.sha256()
    for chunk in chunks:
        h.update(chunk if isinstance(chunk, bytes) else str(chunk).encode())
    return h.hexdigest()


def _parquet_parts(path: Path) -> dict:
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = table.schema.metadata or {}
    columns = []
    for name in table.column_names:
        columns += [name, table.column(name).combine_chunks().to_numpy(zero_copy_only=False)]
    parts = {"columns": _digest(c.tobytes() if hasattr(c, "tobytes") else c for c in columns)}
    keys = ("units", "labels", "operating", "scenario")
    for key in (f"prsm_health.{k}".encode() for k in keys):
        parts[key.decode().removeprefix("prsm_health.")] = json.loads(meta.get(key, b"null"))
    return parts


def _mcap_parts(path: Path) -> dict:
    from mcap.reader import make_reader

    messages, metadata, attachments = [], {}, {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            messages += [channel.topic, message.log_time, message.data]
        for record in reader.iter_metadata():
            metadata[record.name] = dict(record.metadata)
        for attachment in reader.iter_attachments():
            attachments[attachment.name] = _digest([attachment.data])
    return {"messages": _digest(messages), "metadata": metadata, "attachments": attachments}


def _diagnosis_parts(text: str) -> dict:
    answer = json.loads(text)
    numbers = {
        k: answer.get(k)
        for k in (
            "clearance",
            "fault_class",
            "class_probabilities",
            "class_set",
            "indicators",
            "ood_score",
            "observability",
        )
    }
    return {"numbers": numbers, "model": answer.get("model"), "warnings": answer.get("warnings")}


def fingerprint() -> dict:
    out = {"validate": _digest([_run(["validate", "--json"])])}
    with tempfile.TemporaryDirectory() as tmp:
        parquet, mcap = Path(tmp, "run.parquet"), Path(tmp, "run.mcap")
        _run([*SIMULATE, "--out", str(parquet)])
        _run([*SIMULATE, "--out", str(mcap)])
        for name, parts in (
            ("simulate_parquet", _parquet_parts(parquet)),
            ("simulate_mcap", _mcap_parts(mcap)),
            ("diagnose_shipped", _diagnosis_parts(_run(["diagnose", str(mcap), "--json"]))),
        ):
            out.update({f"{name}.{part}": value for part, value in parts.items()})
    return out


def _differences(before, now, where: str = "") -> list[str]:
    """Key-level differences of two JSON values: added, removed, changed."""
    if isinstance(before, dict) and isinstance(now, dict):
        lines = []
        for key in sorted(set(before) | set(now), key=str):
            at = f"{where}.{key}" if where else str(key)
            if key not in before:
                lines.append(f"  added {at} = {json.dumps(now[key])[:120]}")
            elif key not in now:
                lines.append(f"  removed {at}")
            else:
                lines += _differences(before[key], now[key], at)
        return lines
    if before != now:
        return [f"  changed {where}: {json.dumps(before)[:120]} -> {json.dumps(now)[:120]}"]
    return []


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, help="write the fingerprint to this JSON file")
    parser.add_argument("--compare", type=Path, help="compare with a fingerprint written before")
    parser.add_argument(
        "--command",
        default="prsm-health",
        help="how to run the command line, e.g. 'python -m prsm_health.cli' for an old checkout "
        "on PYTHONPATH (default: prsm-health)",
    )
    args = parser.parse_args()
    if args.command != "prsm-health":
        COMMAND[:] = args.command.split()
    now = fingerprint()
    if not args.compare:
        print(json.dumps(now, indent=2))
    if args.out:
        args.out.write_text(json.dumps(now, indent=2) + "\n")
    if args.compare:
        before = json.loads(args.compare.read_text())
        changed = [k for k in sorted(set(before) | set(now)) if before.get(k) != now.get(k)]
        for key in sorted(set(before) | set(now)):
            if key not in changed:
                print(f"identical: {key}")
        for key in changed:
            print(f"changed: {key}")
            print("\n".join(_differences(before.get(key), now.get(key))))
        print("identical" if not changed else f"{len(changed)} part(s) changed")
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
