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

from prsm_health.validation import fidelity


def _light_scenario(scale: float):
    """fidelity._scenario with the rollers' mass and inertia scaled when asked by the option."""
    plain = fidelity._scenario

    def scenario(case, options):
        options = dict(options)
        factor = options.pop("roller_mass_scale", None)
        sc = plain(case, options)
        if factor is None:
            return sc
        masses = sc.design.masses
        light = replace(
            sc.design,
            masses=replace(
                masses,
                roller_mass=masses.roller_mass * factor,
                roller_inertia=masses.roller_inertia * factor,
            ),
        )
        return replace(sc, design=light)

    return scenario


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--scale", type=float, default=0.1)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--duration", type=float, default=0.5)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    # set before the worker processes fork, so they measure the light candidate too
    fidelity._scenario = _light_scenario(args.scale)
    t0 = time.perf_counter()
    rows = fidelity.acceptance(
        {"max_step": "auto", "roller_mass_scale": args.scale},
        seeds=args.seeds,
        duration=args.duration,
        dampings=(0.03,),
        workers=args.workers,
    )
    print(
        f"rollers' mass and inertia × {args.scale:g} against the full model at 0.5 µs; "
        f"{args.seeds} seeds × {args.duration:g} s; {time.perf_counter() - t0:.0f} s\n"
    )
    print(fidelity.markdown_table(rows))
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
