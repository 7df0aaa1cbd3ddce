"""Fingerprint what users see, to show a refactor changed nothing that was not meant to change.

Runs the installed ``prsm-health`` command (so it works on any layout of the package) and
prints one SHA-256 digest per behaviour:

- ``validate``: ``prsm-health validate --json`` (the papers-vs-model report);
- ``simulate_parquet`` / ``simulate_mcap``: a seeded ``simulate`` written to Parquet and to
  MCAP, digested by content (every column's values, units and labels; every MCAP message's
  topic, log time and data, metadata and attachments), not by file bytes, which carry the
  writer library's version;
- ``diagnose_shipped``: the shipped model's ``diagnose --json`` of that MCAP recording.

Usage::

    python tools/release/behaviour_fingerprint.py --out before.json      # on the old commit
    python tools/release/behaviour_fingerprint.py --compare before.json  # on the new one

``--compare`` exits 1 and names each behaviour whose digest differs. Digests are exact: compare
runs made on one machine with one set of library versions (a seeded run is reproducible there,
not across CPUs; docs/formats.md → Reproducibility).
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


def _cli() -> list[str]:
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


def _parquet_chunks(path: Path):
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = table.schema.metadata or {}
    for key in sorted(meta):
        if key not in (b"pandas",):
            yield key + b"=" + meta[key]
    for name in table.column_names:
        yield name
        yield table.column(name).combine_chunks().to_numpy(zero_copy_only=False).tobytes()


def _mcap_chunks(path: Path):
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        reader = make_reader(f)
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            yield channel.topic
            yield message.log_time
            yield message.data
        for record in reader.iter_metadata():
            yield record.name
            yield json.dumps(record.metadata, sort_keys=True)
        for attachment in reader.iter_attachments():
            yield attachment.name
            yield attachment.data


def fingerprint() -> dict[str, str]:
    out = {"validate": _digest([_run(["validate", "--json"])])}
    with tempfile.TemporaryDirectory() as tmp:
        parquet, mcap = Path(tmp, "run.parquet"), Path(tmp, "run.mcap")
        _run([*SIMULATE, "--out", str(parquet)])
        _run([*SIMULATE, "--out", str(mcap)])
        out["simulate_parquet"] = _digest(_parquet_chunks(parquet))
        out["simulate_mcap"] = _digest(_mcap_chunks(mcap))
        out["diagnose_shipped"] = _digest([_run(["diagnose", str(mcap), "--json"])])
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, help="write the fingerprint to this JSON file")
    parser.add_argument("--compare", type=Path, help="compare with a fingerprint written before")
    args = parser.parse_args()
    now = fingerprint()
    print(json.dumps(now, indent=2))
    if args.out:
        args.out.write_text(json.dumps(now, indent=2) + "\n")
    if args.compare:
        before = json.loads(args.compare.read_text())
        changed = [k for k in sorted(set(before) | set(now)) if before.get(k) != now.get(k)]
        for key in changed:
            print(f"changed: {key}")
        print("identical" if not changed else f"{len(changed)} behaviour(s) changed")
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
