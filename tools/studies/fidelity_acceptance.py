"""The acceptance check of a simulation fidelity (issue [5/5] item 3): a candidate's runs against
the full model's at a 0.5 µs step, case by case (prsm_health.validation.fidelity says what is
compared and why).

    python tools/studies/fidelity_acceptance.py [--candidate max_step=auto] [--seeds 3]
        [--duration 0.5] [--dampings 0.03 0.1 0.2] [--workers 2]

``--candidate`` takes SimulationOptions fields as key=value (numbers parsed), e.g.
``max_step=5e-6`` or ``max_step=auto``. Prints one Markdown table (a row per duty, contact
damping and criterion) and exits 1 when a criterion fails.
"""

from __future__ import annotations

import argparse
import sys
import time

from prsm_health.validation.fidelity import DAMPINGS, DUTIES, acceptance, markdown_table


def _value(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--candidate", nargs="+", default=["max_step=auto"])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--duration", type=float, default=0.5)
    parser.add_argument("--dampings", type=float, nargs="+", default=list(DAMPINGS))
    parser.add_argument("--duties", nargs="+", default=list(DUTIES), choices=list(DUTIES))
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    candidate = dict(item.split("=", 1) for item in args.candidate)
    candidate = {k: _value(v) for k, v in candidate.items()}
    t0 = time.perf_counter()
    rows = acceptance(
        candidate,
        seeds=args.seeds,
        duration=args.duration,
        dampings=tuple(args.dampings),
        duties=tuple(args.duties),
        workers=args.workers,
    )
    print(
        f"candidate {candidate} against the full model at 0.5 µs; {args.seeds} seeds × "
        f"{args.duration:g} s per case; {time.perf_counter() - t0:.0f} s on {args.workers} "
        "workers\n"
    )
    print(markdown_table(rows))
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
