"""What a quasi-static roller would lose (issue [5/5] item 2): the fidelity acceptance check of a
full model whose rollers are lighter, against the unchanged full model.

    python tools/studies/light_rollers.py [--scale 0.1] [--seeds 3] [--workers 2]

A condensed fidelity solves the rollers quasi-statically: no roller inertia, so none of the 4–6
roller modes that ring inside the measured band (tools/studies/mode_map.py: lateral 4.2–9.6 kHz,
axial 7.0–9.6 kHz). Scaling the rollers' mass and inertia by ``--scale`` moves those modes up by
1/√scale (0.1: ×3.2, out of the band) while everything else stays: the acceptance check of that
candidate (its step chosen as usual, so ≈ 0.4 µs) measures how much the measured signals owe to
the in-band roller modes, i.e. whether the condensed model needs them retained. Contact damping
0.03 only: the rollers' contact-damped modes (c/m) rise as 1/scale, and at 0.1 or 0.2 their
step would be ten times smaller again.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace

from prsm_health.actuator.design_files import load_design
from prsm_health.validation import fidelity


def light_design(scale: float):
    """paper01 with its rollers' mass and inertia scaled by ``scale``."""
    design = load_design("paper01")
    masses = replace(
        design.masses,
        roller_mass=design.masses.roller_mass * scale,
        roller_inertia=design.masses.roller_inertia * scale,
    )
    return replace(design, masses=masses)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--scale", type=float, default=0.1)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--duration", type=float, default=0.5)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    t0 = time.perf_counter()
    rows = fidelity.acceptance(
        {"max_step": "auto"},
        seeds=args.seeds,
        duration=args.duration,
        dampings=(0.03,),
        workers=args.workers,
        candidate_design=light_design(args.scale),
    )
    print(
        f"rollers' mass and inertia × {args.scale:g} against the full model at 0.5 µs; "
        f"{args.seeds} seeds × {args.duration:g} s; {time.perf_counter() - t0:.0f} s\n"
    )
    print(fidelity.markdown_table(rows))
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
