"""Load ratings C_a, C_0a of the design presets against the catalogue data we could read.

Recomputes every computed column of docs/load-ratings.md and prints the tables (Markdown) that
page carries between its ``generated`` markers:

1. the presets' ratings by :func:`prsm_health.physics.load_rating.load_ratings` (screw and nut
   sides, the Hertz pressure at C_a, the uniform-sharing C_0a of ISO 76);
2. the catalogue comparison: each row read, with its source, against the computed rating;
3. the fatigue calibration a catalogue C_a would imply (p_ref or N_ref of the wear module's
   law, C_a ∝ N_ref^⅓ and C_a ∝ p_ref³ at fixed geometry);
4. the loads the source papers put on their own units, as a share of the computed ratings and
   as the Hertz pressure they produce at the most loaded thread contact.

Only numbers read in a named document appear in ``CATALOGUE``; docs/load-ratings.md lists the
catalogues that were searched for and could not be read (no row is guessed).

    python tools/studies/load_rating_catalogue.py
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from prsm_health.actuator.design import PRESETS, preset
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.stiffness.thread_geometry import normal_load, thread_contacts
from prsm_health.physics.stiffness.thread_load import thread_load_distribution
from prsm_health.physics.wear import WearParameters

#: Catalogue data read in a named document, per design. ``quantity`` says which rating the
#: source states ("C_a", "C_0a", or "max" when the source does not say which).
CATALOGUE = (
    {
        "design": "paper03",
        "source": (
            "paper 03 §4.3, quoting ROLLVIS SA, Satellite roller screws catalogue 2019 "
            "(paper 03 ref. [30])"
        ),
        "row": "RPRSM of paper 03's size (d_s ≈ 32 mm, pitch 1 mm, 12 grooved rollers)",
        "quantity": "max",
        "value": 60e3,
        "note": "'the maximum load that RPRSM of this size can withstand is 60 kN'",
    },
)

#: Loads the source papers apply to their own units [N] (test or simulation), with where.
PAPER_LOADS = (
    ("paper03", 60e3, "paper 03 §4.3: 20, 40 and 60 kN on the nut (simulation)"),
    (
        "paper04",
        70e3,
        "paper 04, test-rig validation: quasi-static axial load 0 to 70 kN (experiment)",
    ),
    ("paper05", 5e3, "paper 05: influence coefficients at F = 5000 N"),
)


def ratings_row(name: str, fatigue: WearParameters | None = None) -> dict:
    """Computed ratings of one preset [N, Pa] and its geometry."""
    d = preset(name)
    r = load_ratings(d, fatigue=fatigue)
    return {
        "design": name,
        "d_s": d.screw_diameter,
        "lead": d.screw_lead,
        "starts": d.screw_starts,
        "rollers": d.n_rollers,
        "threads": d.engaged_threads,
        "d_r": d.roller_diameter,
        "C_a": r.dynamic,
        "C_0a": r.static,
        "C_0a_uniform": min(s.static_uniform for s in r.per_side.values()),
        "C_screw": r.per_side["screw"].dynamic,
        "C_nut": r.per_side["nut"].dynamic,
        "p_at_C_a": max(s.pressure_at_dynamic for s in r.per_side.values()),
    }


def peak_pressure(name: str, force: float) -> float:
    """Hertz pressure [Pa] of the most loaded thread contact at axial load ``force`` [N].

    Rollers share evenly; threads share by the compatibility model of ``thread_load`` (the
    same sharing as C_0a).
    """
    d = preset(name)
    dist = thread_load_distribution(d, force / d.n_rollers)
    contacts = dict(zip(("screw", "nut"), thread_contacts(d)))
    peaks = []
    for side in ("screw", "nut"):
        q = float(np.max(getattr(dist, side))) * float(normal_load(d, 1.0, side))
        peaks.append(float(contacts[side].max_pressure(q)))
    return max(peaks)


def calibration_for(computed_ca: float, target_ca: float, params: WearParameters) -> dict:
    """The p_ref or N_ref (each alone) that turns ``computed_ca`` into ``target_ca``.

    At fixed geometry C_a ∝ N_ref^⅓·p_ref³ (load_rating module docstring), so a factor k on
    C_a needs N_ref·k³ at the same p_ref, or p_ref·k^⅓ at the same N_ref.
    """
    k = target_ca / computed_ca
    return {
        "factor": k,
        "fatigue_cycles": params.fatigue_cycles * k**3,
        "fatigue_pressure": params.fatigue_pressure * k ** (1.0 / 3.0),
    }


def _kn(x: float) -> str:
    return f"{x / 1e3:.1f}"


def presets_table() -> str:
    lines = [
        "| design | d_s [mm] | lead [mm] | starts | rollers | engaged threads | C_a [kN] "
        "| C_0a [kN] | C_0a uniform [kN] | C screw / nut [kN] | p₀ at C_a [GPa] |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in PRESETS:
        r = ratings_row(name)
        lines.append(
            f"| {name} | {r['d_s'] * 1e3:.1f} | {r['lead'] * 1e3:.2f} | {r['starts']} "
            f"| {r['rollers']} | {r['threads']} | {_kn(r['C_a'])} | {_kn(r['C_0a'])} "
            f"| {_kn(r['C_0a_uniform'])} | {_kn(r['C_screw'])} / {_kn(r['C_nut'])} "
            f"| {r['p_at_C_a'] / 1e9:.2f} |"
        )
    return "\n".join(lines)


def catalogue_table() -> str:
    lines = [
        "| design | catalogue row (source) | stated | value [kN] | computed C_a [kN] "
        "| computed C_0a [kN] | C_a / value | C_0a / value |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in CATALOGUE:
        r = ratings_row(row["design"])
        v = row["value"]
        lines.append(
            f"| {row['design']} | {row['row']} ({row['source']}) | {row['quantity']} "
            f"| {_kn(v)} | {_kn(r['C_a'])} | {_kn(r['C_0a'])} | {r['C_a'] / v:.2f} "
            f"| {r['C_0a'] / v:.2f} |"
        )
    return "\n".join(lines)


def calibration_table() -> str:
    params = WearParameters()
    lines = [
        "| design | if the value were C_a: factor on C_a | N_ref at p_ref = 4.2 GPa "
        "| p_ref at N_ref = 4e6 |",
        "|---|---|---|---|",
    ]
    for row in CATALOGUE:
        r = ratings_row(row["design"])
        c = calibration_for(r["C_a"], row["value"], params)
        lines.append(
            f"| {row['design']} | {c['factor']:.2f} | {c['fatigue_cycles']:.3g} "
            f"| {c['fatigue_pressure'] / 1e9:.2f} GPa |"
        )
    return "\n".join(lines)


def paper_loads_table() -> str:
    lines = [
        "| design | load [kN] | where | load / C_a | load / C_0a | p₀ at the most loaded "
        "contact [GPa] |",
        "|---|---|---|---|---|---|",
    ]
    for name, force, where in PAPER_LOADS:
        r = ratings_row(name)
        lines.append(
            f"| {name} | {_kn(force)} | {where} | {force / r['C_a']:.2f} "
            f"| {force / r['C_0a']:.2f} | {peak_pressure(name, force) / 1e9:.2f} |"
        )
    return "\n".join(lines)


def check_scaling(name: str = "paper01") -> float:
    """C_a ratio for N_ref × 8 (must be 2: C_a ∝ N_ref^⅓); a guard on the calibration law."""
    base = load_ratings(preset(name)).dynamic
    params = replace(WearParameters(), fatigue_cycles=8 * WearParameters().fatigue_cycles)
    return load_ratings(preset(name), fatigue=params).dynamic / base


def report() -> str:
    """The Markdown block docs/load-ratings.md carries between its generated markers."""
    assert math.isclose(check_scaling(), 2.0, rel_tol=1e-9)
    return "\n\n".join(
        [
            "**Computed ratings of the presets** (`load_ratings`, default fatigue law "
            "p_ref = 4.2 GPa, N_ref = 4·10⁶)\n\n" + presets_table(),
            "**Catalogue comparison** (rows read; ratio = computed / catalogue)\n\n"
            + catalogue_table(),
            "**Calibration the row would imply if its value were C_a**\n\n" + calibration_table(),
            "**Loads the source papers put on their own units**\n\n" + paper_loads_table(),
        ]
    )


if __name__ == "__main__":
    print(report())
