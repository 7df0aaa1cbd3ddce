"""How often the rollers' contacts change state within a condensed step, and how much of the
measured vibration happens then (issue [5/5] item 2: may a condensed model hold the contact
states for a whole step?).

    python tools/studies/contact_switching.py [--duration 0.2] [--dampings 0.03 0.1]

``condensed_budget.py`` finds that at the default contact damping a condensation can reach 4×
only if its work is done once per step (≈ 25 µs), not per RK4 stage — e.g. the rollers
linearised about the step's start, their contact states held through it. This measures what
holding them would miss. The full model runs the acceptance check's cases
(``prsm_health.validation.fidelity``: the steady stroke at 20 % C_a and the ±25 % C_a load
reversals; seed 0; after the run's own settling) at its default step; after every step each
roller's contact state is read from the right-hand side's auxiliary outputs: screw thread
loaded or not, nut thread loaded or not, gear on its drive flank, coast flank or in its backlash.
Then, for condensed steps H = 25, 16.7 and 12.5 µs (windows of the run's time), prints the share
of windows in which any roller's state changes, the switches per second, and the share of the
nut's true axial acceleration energy (its mean removed) that falls in those windows — what a
condensed model would have to hand to a finer solver.
"""

from __future__ import annotations

import argparse

import numpy as np

from prsm_health.simulation.dynamics import _kernels
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import build_model
from prsm_health.simulation.dynamics.simulate import (
    integrate,
    integration_step,
    max_stable_step,
    settled_state,
)
from prsm_health.validation.fidelity import DUTIES, Case, case_scenario

SAMPLE_RATE = 20_000.0  # [Hz] the default instrumentation's output
CONDENSED_STEPS = (25e-6, 1 / 60_000.0, 12.5e-6)  # [s] H = 1/(m·20 kHz), m = 2, 3, 4


def contact_states(model, y, t, aux, dy) -> np.ndarray:
    """Each roller's state (n_rollers,) as one integer: screw loaded (1), nut loaded (2), gear
    on its drive (4) or coast (8) flank — at state ``y`` and time ``t``."""
    _kernels.rhs(
        t, y, model.params, model.rollers, model.mesh_table, model.motion, model.load_knots,
        model.errors, dy, aux,
    )  # fmt: skip
    n = model.n_rollers
    cap_s, cap_n, gear = (aux[L.N_AUX + k * n : L.N_AUX + (k + 1) * n] for k in
                          (L.AR_CAP_S, L.AR_CAP_N, L.AR_GEAR))  # fmt: skip
    return (cap_s > 0.0) * 1 + (cap_n > 0.0) * 2 + (gear > 0.0) * 4 + (gear < 0.0) * 8


def trace(duty: str, damping: float, duration: float):
    """(time [s], contact states (steps, n_rollers), nut axial acceleration) of one case."""
    s = case_scenario(Case(duty, damping, 0, duration), {})
    model = build_model(s.design, s.health, s.profile, s.options, s.seed, s.drive_train)
    h_stable, f_max = max_stable_step(model)
    h, _ = integration_step("auto", h_stable, f_max, SAMPLE_RATE)
    y = settled_state(model, h, s.options.settle_time)
    n_steps = int(round(duration / h))
    aux = np.zeros(L.n_aux(model.n_rollers))
    dy = np.empty(model.n_state)
    states = np.empty((n_steps, model.n_rollers), dtype=np.int8)
    accel = np.empty(n_steps)
    for k in range(n_steps):
        t = k * h
        states[k] = contact_states(model, y, t, aux, dy)
        accel[k] = dy[model.n_coordinates + L.Q_ZN]
        integrate(model, y, h, 1, t0=t, record=False)  # raises on a non-finite state
    return np.arange(n_steps) * h, states, accel, h


KINDS = ((1, "screw thread loaded"), (2, "nut thread loaded"), (4, "gear on its drive flank"),
         (8, "gear on its coast flank"))  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--duration", type=float, default=0.2, help="simulated s per case")
    parser.add_argument("--dampings", type=float, nargs="+", default=[0.03, 0.1])
    args = parser.parse_args()
    traces = {
        (duty, damping): trace(duty, damping, args.duration)
        for duty in DUTIES
        for damping in args.dampings
    }
    head = " | ".join(f"H = {1e6 * H:.1f} µs" for H in CONDENSED_STEPS)
    print(f"{args.duration:g} s per case. Per condensed step H: the windows in which a roller's")
    print("contact state changes, and the share of the nut acceleration's energy in them\n")
    print(f"| duty | contact damping | full step | switches per s | {head} |")
    print("|---|---|---|---|" + "---|" * len(CONDENSED_STEPS))
    for (duty, damping), (time, states, accel, h) in traces.items():
        changed = np.any(states[1:] != states[:-1], axis=1)  # between step k and k + 1
        switches = int(np.sum(states[1:] != states[:-1]))
        energy = (accel - accel.mean()) ** 2
        cells = []
        for H in CONDENSED_STEPS:
            window = (time / H).astype(int)
            hit = np.zeros(window[-1] + 1, dtype=bool)
            hit[window[1:][changed]] = True  # a change lies in the window of its later step
            share = energy[hit[window]].sum() / energy.sum()
            cells.append(f"{100 * hit.mean():.1f} % of windows, {100 * share:.0f} % of energy")
        print(
            f"| {duty} | {damping:g} | {1e6 * h:.2f} µs | {switches / args.duration:.0f} | "
            + " | ".join(cells)
            + " |"
        )
    print("\nWhich contacts switch: changes per second (all rollers), and the time share each")
    print("roller spends in the state (lowest–highest roller)\n")
    print("| duty | contact damping | " + " | ".join(name for _, name in KINDS) + " |")
    print("|---|---|" + "---|" * len(KINDS))
    for (duty, damping), (_, states, _, _) in traces.items():
        cells = []
        for bit, _ in KINDS:
            on = (states & bit) > 0
            rate = np.sum(on[1:] != on[:-1]) / args.duration
            share = on.mean(axis=0)
            cells.append(f"{rate:.0f}/s, {100 * share.min():.0f}–{100 * share.max():.0f} %")
        print(f"| {duty} | {damping:g} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
