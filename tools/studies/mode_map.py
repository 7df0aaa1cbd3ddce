"""Which bodies own which modes of the full model, and what a condensed fidelity must keep (issue
[5/5] item 2, its groundwork).

    python tools/studies/mode_map.py [--runs 4] [--dampings 0.03 0.1 0.2]

For the first ``--runs`` runs of ``datasets/flight-ema-reference.toml`` (the realistic duty:
loads of 2–40 % C_a, the drive train) at each contact damping ratio, the model is linearised on
its loaded flanks once per run (``simulate.linearised_jacobian``, whose eigenvalues set the RK4
step) and each mode is given to the body family that holds most of its kinetic energy (½·m·v² of each
coordinate's velocity in the eigenvector; a mode with no velocity part is a first-order
traction relaxation). Prints, per damping, one Markdown row per family: its modes' frequency
range, how many lie in the measured band (below 10 kHz, the 20 kHz output's Nyquist), and the
RK4 step the fastest of them allows; then the step the model would allow with the rollers and
the carrier condensed out (their modes gone, every other mode kept), and run 0's undamped modes
below 5 kHz, full, statically condensed (with and without the rollers' inertia carried) and
in a Craig–Bampton basis (the static modes plus the rollers' and carrier's own modes below
CB_CUTOFF).
"""

from __future__ import annotations

import argparse
import math
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import numpy as np

from prsm_health.datasets import Recipe, load_recipe
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import build_model
from prsm_health.simulation.dynamics.simulate import (
    STABILITY_MARGIN,
    linearised_jacobian,
)

ROOT = Path(__file__).resolve().parents[2]
BAND = 10_000.0  # [Hz] the measured band: the 20 kHz output's Nyquist
RK4_LIMIT = 2.785  # |λ|·h on RK4's stability boundary (negative real axis; 2.83 imaginary)
CONDENSED = ("roller", "carrier")  # the families a condensed fidelity solves quasi-statically
CB_CUTOFF = 12_000.0  # [Hz] the condensed bodies' own modes kept in the Craig–Bampton basis


#: Each body family's coordinates and the parameter holding their mass or inertia (the carrier
#: twice: its lateral mass, its rotary inertia).
FAMILIES = (
    ("screw lateral", (L.Q_XS, L.Q_YS), L.P_M_S),
    ("screw torsion", (L.Q_THS,), L.P_J_S),
    ("screw axial", (L.Q_ZS,), L.P_M_S),
    ("nut lateral", (L.Q_XN, L.Q_YN), L.P_M_N),
    ("nut rotation", (L.Q_THN,), L.P_J_N),
    ("nut axial", (L.Q_ZN,), L.P_M_N),
    ("carrier", (L.Q_XP, L.Q_YP), L.P_M_P),
    ("carrier", (L.Q_THP,), L.P_J_P),
    ("motor", (L.Q_THM,), L.P_J_M),
    ("payload", (L.Q_ZL,), L.P_M_L),
)
#: A roller's coordinates (offsets from its first) by family, with their mass or inertia.
ROLLER_FAMILIES = (
    ("roller lateral", (0, 1), L.P_M_C),
    ("roller spin", (2,), L.P_J_C),
    ("roller axial", (3,), L.P_M_C),
)


def coordinate_families(model) -> tuple[list[str], np.ndarray]:
    """The body family and the mass or inertia [kg, kg·m²] of each generalised coordinate."""
    p, nq = model.params, model.n_coordinates
    family, mass = [""] * nq, np.zeros(nq)
    starts = [L.Q_ROLLER0 + L.ROLLER_DOF * i for i in range(model.n_rollers)]
    for table, offsets in ((FAMILIES, [0]), (ROLLER_FAMILIES, starts)):
        for name, coordinates, m in table:
            for q in (o + c for o in offsets for c in coordinates):
                family[q], mass[q] = name, p[m]
    return family, mass


def mode_table(model, jac, free) -> list[tuple[float, float, str]]:
    """(frequency |λ|/2π [Hz], damping ratio, owning family) of each mode of the linearised
    model (``jac`` over the states ``free``, :func:`linearised_jacobian`), fastest first."""
    values, vectors = np.linalg.eig(jac)
    family, mass = coordinate_families(model)
    nq = model.n_coordinates
    modes = []
    for k in np.argsort(-np.abs(values)):
        lam = values[k]
        if lam.imag < 0.0 or abs(lam) < 1.0:  # one of each conjugate pair; rigid-body motion
            continue
        energy = defaultdict(float)
        for col, j in enumerate(free):
            if nq <= j < 2 * nq:
                energy[family[j - nq]] += mass[j - nq] * abs(vectors[col, k]) ** 2
        owner = max(energy, key=energy.get) if energy else "traction relaxation"
        modes.append((abs(lam) / (2 * math.pi), -lam.real / abs(lam), owner))
    return modes


def condensed_frequencies(model, jac, free) -> dict[str, np.ndarray]:
    """Undamped natural frequencies [Hz] below 5 kHz: of the full model, and with the rollers
    and the carrier statically condensed (Guyan 1965) — their mass carried into the other
    bodies through the static modes (M_red = TᵀMT, T = [I; −K_cc⁻¹K_ck]) or dropped (M_kk).

    K = −M·∂v̇/∂q from the linearised Jacobian (friction's traction states and all damping
    left out): a check of the mass and stiffness a condensation keeps, not of the dynamics.
    """
    family, mass = coordinate_families(model)
    nq, index = model.n_coordinates, {j: i for i, j in enumerate(free)}
    q = [j for j in free if j < nq and nq + j in index]
    stiffness = -mass[q, None] * jac[np.ix_([index[nq + j] for j in q], [index[j] for j in q])]
    c = np.array([family[j].startswith(CONDENSED) for j in q])
    k_kk, k_kc = stiffness[np.ix_(~c, ~c)], stiffness[np.ix_(~c, c)]
    k_ck, k_cc = stiffness[np.ix_(c, ~c)], stiffness[np.ix_(c, c)]
    static = -np.linalg.solve(k_cc, k_ck)  # the condensed coordinates under unit kept ones
    k_red = k_kk + k_kc @ static
    m_k, m_c = np.diag(mass[q][~c]), np.diag(mass[q][c])

    def below_band(m, k):
        w2 = np.linalg.eigvals(np.linalg.solve(m, k)).real
        f = np.sqrt(np.clip(w2, 0.0, None)) / (2 * math.pi)
        return np.sort(f[(f > 1.0) & (f < 5000.0)])

    # Craig & Bampton (1968): the static modes plus the condensed bodies' own modes with the
    # kept coordinates held (fixed interface) up to CB_CUTOFF, projected as T = [[I, 0], [Ψ, Φ]].
    w2, shapes = np.linalg.eig(np.linalg.solve(m_c, k_cc))
    shapes = shapes[:, np.sqrt(np.abs(w2)) / (2 * math.pi) < CB_CUTOFF].real
    n_k = int((~c).sum())
    basis = np.block([[np.eye(n_k), np.zeros((n_k, shapes.shape[1]))], [static, shapes]])
    order = np.concatenate([np.flatnonzero(~c), np.flatnonzero(c)])
    k_full, m_full = stiffness[np.ix_(order, order)], np.diag(mass[q][order])
    return {
        "full": below_band(np.diag(mass[q]), stiffness),
        "Guyan (inertia carried)": below_band(m_k + static.T @ m_c @ static, k_red),
        "rollers massless": below_band(m_k, k_red),
        f"Craig–Bampton ({shapes.shape[1]} roller/carrier modes < {CB_CUTOFF / 1e3:g} kHz kept)": (
            below_band(basis.T @ m_full @ basis, basis.T @ k_full @ basis)
        ),
    }


def rk4_step(frequency: float) -> float:
    """The RK4 step [µs] a mode of this |λ|/2π allows, with the kernel's stability margin."""
    return 1e6 * STABILITY_MARGIN * RK4_LIMIT / (2 * math.pi * frequency)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=4)
    parser.add_argument("--dampings", type=float, nargs="+", default=[0.03, 0.1, 0.2])
    args = parser.parse_args()
    source = load_recipe(ROOT / "datasets" / "flight-ema-reference.toml").source
    recipe = Recipe.from_dict(dict(source, name="modes", test_fraction=0.0))
    for damping in args.dampings:
        by_family, kept, first = defaultdict(list), [], None
        for spec in recipe.runs()[: args.runs]:
            sc = spec.scenario()  # the recipe draws a damping per run: this study sets it
            options = replace(sc.options, contact_damping_ratio=damping)
            model = build_model(sc.design, sc.health, sc.profile, options, sc.seed, sc.drive_train)
            linearised = model, *linearised_jacobian(model)
            first = first or linearised  # run 0's, for the condensation below
            modes = mode_table(*linearised)
            for frequency, zeta, owner in modes:
                by_family[owner].append((frequency, zeta))
            rest = [f for f, _, owner in modes if not owner.startswith(CONDENSED)]
            kept.append(max(rest))
        print(f"\n### contact damping ratio {damping:g} ({args.runs} runs)\n")
        print(
            "| family | modes per run | frequency range | in band (< 10 kHz) per run | "
            "of them oscillatory (ζ < 0.5) | RK4 step of its fastest |"
        )
        print("|---|---|---|---|---|---|")
        for owner, modes in sorted(by_family.items(), key=lambda kv: -max(f for f, _ in kv[1])):
            freqs, zetas = np.array(modes).T
            in_band = freqs[freqs < BAND]
            ringing = freqs[(freqs < BAND) & (zetas < 0.5)]
            print(
                f"| {owner} | {len(freqs) / args.runs:.1f} | {freqs.min():.0f}–{freqs.max():.0f} Hz | "
                f"{len(in_band) / args.runs:.1f}"
                + (f" ({in_band.min():.0f}–{in_band.max():.0f} Hz)" if len(in_band) else "")
                + f" | {len(ringing) / args.runs:.1f}"
                + (f" ({ringing.min():.0f}–{ringing.max():.0f} Hz)" if len(ringing) else "")
                + f" | {rk4_step(freqs.max()):.2f} µs |"
            )
        fastest = max(kept)
        print(
            f"\nRollers and carrier condensed out: fastest remaining mode {fastest:.0f} Hz "
            f"(over the runs), RK4 step ≤ {rk4_step(fastest):.1f} µs."
        )
        print(f"\nUndamped modes below 5 kHz of run 0, full and condensed (damping {damping:g}):\n")
        try:
            condensed = condensed_frequencies(*first)
        except np.linalg.LinAlgError:  # a condensed coordinate with no stiffness at this point
            condensed = {"condensation": "undefined (K_cc singular in this linearisation)"}
        for name, freqs in condensed.items():
            text = freqs if isinstance(freqs, str) else ", ".join(f"{f:.0f}" for f in freqs) + " Hz"
            print(f"- {name}: {text}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
