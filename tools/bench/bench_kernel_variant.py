"""A change to the dynamics kernel, measured before it is made: the package's kernel against an
edited copy of it, in one process, in paired rounds (issue [5/5] item 1's A/B measurements).

    python tools/bench/bench_kernel_variant.py --copy-to build/k_variant.py
    # edit build/k_variant.py, then
    python tools/bench/bench_kernel_variant.py build/k_variant.py [--rounds 5] [--baseline OTHER.py]

``--copy-to`` writes a copy of ``prsm_health/simulation/dynamics/_kernels.py`` that imports
the layout absolutely and compiles without numba's cache (so it never mixes with the package's).
A variant may read a model built otherwise by defining ``prepare(model) -> model`` (e.g. another
table length).

Each round runs ``integrate`` on 0.1 s (h = 5 µs, every step recorded) of each of the first three
runs of ``datasets/flight-ema-reference.toml`` (1 s each) with the baseline (the package, or
``--baseline``), then with the variant; a round's ratio cancels this machine's drift between
minutes, so the median of the rounds' ratios is the figure to read. Also prints the largest
difference of the nut acceleration between the two over the rounds, in its standard deviations:
0 means the same bits (an impact-dominated run diverges after any change of the last bits, so
anything else says only that the bits changed).
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from pathlib import Path

import numpy as np

from prsm_health.datasets import Recipe, load_recipe
from prsm_health.simulation.dynamics import _kernels
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import build_model, initial_state

ROOT = Path(__file__).resolve().parents[2]
STEP, N_STEPS = 5e-6, 20_000


def write_copy(path: Path) -> None:
    """A copy of the package's kernel module to edit: absolute layout import, no numba cache."""
    source = Path(_kernels.__file__).read_text()
    source = source.replace(
        "from . import layout as L", "from prsm_health.simulation.dynamics import layout as L"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(source.replace("cache=True", "cache=False"))


def load(path: str):
    spec = importlib.util.spec_from_file_location(Path(path).stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def models() -> list:
    source = load_recipe(ROOT / "datasets" / "flight-ema-reference.toml").source
    recipe = Recipe.from_dict(dict(source, name="kernel-variant", duration=1.0, test_fraction=0.0))
    scenarios = [spec.scenario() for spec in recipe.runs()[:3]]
    return [
        build_model(s.design, s.health, s.profile, s.options, s.seed, s.drive_train)
        for s in scenarios
    ]


def run(kernel, model) -> tuple[float, np.ndarray]:
    """Wall time of ``integrate`` on ``model`` with ``kernel``, and its record."""
    model = getattr(kernel, "prepare", lambda m: m)(model)
    y = initial_state(model)
    work = [np.empty(model.n_state) for _ in range(5)]
    aux = np.zeros(L.n_aux(model.n_rollers))
    out = np.empty((N_STEPS, L.N_CHANNELS))
    t0 = time.perf_counter()
    kernel.integrate(
        y, 0.0, STEP, N_STEPS, 1, model.params, model.rollers, model.mesh_table, model.motion,
        model.load_knots, model.errors, out, *work, aux,
    )  # fmt: skip
    return time.perf_counter() - t0, out


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("variant", nargs="?", help="the edited copy of _kernels.py")
    parser.add_argument("--copy-to", help="write a copy of the package's kernel here and stop")
    parser.add_argument("--baseline", help="another copy to compare against (default: package)")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    if args.copy_to:
        write_copy(Path(args.copy_to))
        print(f"wrote {args.copy_to}: edit it, then pass it as the variant")
        return 0
    if not args.variant:
        parser.error("give the variant (or --copy-to)")
    baseline = load(args.baseline) if args.baseline else _kernels
    variant = load(args.variant)
    cases = models()
    for kernel in (baseline, variant):  # compiled before the timing
        run(kernel, cases[0])
    ratios, differences = [], []
    for r in range(args.rounds):
        t_base = t_variant = 0.0
        for model in cases:
            a, out_a = run(baseline, model)
            b, out_b = run(variant, model)
            t_base, t_variant = t_base + a, t_variant + b
            accel_a, accel_b = out_a[:, L.C_NUT_AXIAL_ACCEL], out_b[:, L.C_NUT_AXIAL_ACCEL]
            differences.append(np.max(np.abs(accel_a - accel_b)) / np.std(accel_a))
        ratios.append(t_base / t_variant)
        print(f"round {r}: baseline {t_base:.3f} s, variant {t_variant:.3f} s, {ratios[-1]:.3f}×")
    print(
        f"variant speed-up, median of {args.rounds} rounds: {np.median(ratios):.3f}× "
        f"({min(ratios):.3f}–{max(ratios):.3f}); largest nut-acceleration difference "
        f"{max(differences):.3g} standard deviations"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
