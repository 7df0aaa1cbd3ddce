"""Benchmark: vectorised potential-energy mesh stiffness vs a scalar scipy.quad baseline.

The baseline is what a user would write from the papers: for every contact position along
the path of contact, integrate each energy term (bending, shear, axial compression of the
pinion fillet, the pinion involute and the ring tooth) with ``scipy.integrate.quad``, add the
closed-form Hertz and fillet-foundation terms, and superimpose the pairs. It uses the same
tooth geometry as :mod:`prsm_health.physics.stiffness.gear_mesh`, so the comparison isolates the
integration strategy; the script also prints the largest relative difference of the two
single-pair curves (a check of the fixed Gauss–Legendre panels against adaptive quadrature).

Usage::

    .venv/bin/python tools/bench/bench_gear_mesh.py [--design paper01] [--n-points 400]
        [--baseline-points 400] [--repeat 20]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from prsm_health.actuator.design import preset
from prsm_health.physics.stiffness import gear_mesh as gm


def _scalar_terms(tooth, t_c: float) -> float:
    """Bending + shear + axial + foundation compliance of one tooth, one contact, by quad."""
    y_c, h_c, _ = (float(v) for v in tooth.involute(t_c))
    zeta_c = (tooth.y_root - y_c) if tooth.internal else (y_c - tooth.y_root)
    a1 = float(tooth.load_angle(t_c))
    c1, s1 = math.cos(a1), math.sin(a1)
    E, G = tooth.E, tooth.G

    def section_involute(t):
        y, h, dy = (float(v) for v in tooth.involute(t))
        zeta = (tooth.y_root - y) if tooth.internal else (y - tooth.y_root)
        w = float(tooth.width(tooth.radius(t)))
        return zeta, h, w, dy

    def section_fillet(g):
        y, h, dy, r = (float(v) for v in tooth.fillet(g))
        return y - tooth.y_root, h, float(tooth.width(r)), -dy

    def terms(section):
        def bending(q):
            zeta, h, w, dz = section(q)
            arm = (zeta_c - zeta) * c1 - h_c * s1
            return arm * arm * 12.0 / (E * w * (2 * h) ** 3) * dz

        def shear(q):
            zeta, h, w, dz = section(q)
            return 1.2 * c1 * c1 / (G * 2 * h * w) * dz

        def axial(q):
            zeta, h, w, dz = section(q)
            return s1 * s1 / (E * 2 * h * w) * dz

        return bending, shear, axial

    total = 0.0
    if tooth.internal:
        for f in terms(section_involute):
            total += quad(f, t_c, tooth.t_root, limit=200)[0]
    else:
        kinks_t = [tooth.t_of_radius(r) for r in tooth.width.kinks if r > tooth.rb]
        pts = [t for t in kinks_t if tooth.t_usable < t < t_c] or None
        for f in terms(section_involute):
            total += quad(f, tooth.t_usable, t_c, points=pts, limit=200)[0]
        # The width law's kinks inside the fillet, found on the fillet curve, so that quad
        # does not have to resolve a corner it cannot see.
        r_top = float(tooth.fillet(tooth.g_junction)[3])
        g_pts = [
            brentq(lambda g, rk=rk: float(tooth.fillet(g)[3]) - rk, tooth.g_junction, math.pi / 2)
            for rk in tooth.width.kinks
            if tooth.rf < rk < r_top
        ] or None
        for f in terms(section_fillet):
            total += quad(f, tooth.g_junction, math.pi / 2, points=g_pts, limit=200)[0]
    # Sainsot fillet foundation, closed form.
    if tooth.internal:
        u_f = tooth.rf - (y_c + h_c * math.tan(a1))
    else:
        u_f = (y_c - h_c * math.tan(a1)) - tooth.rf
    lf, mf, pf, qf = tooth.sainsot
    ratio = u_f / tooth.S_f
    total += (
        c1
        * c1
        / (E * tooth.width_root)
        * (lf * ratio**2 + mf * ratio + pf * (1 + qf * math.tan(a1) ** 2))
    )
    return total


def baseline(design, ms_reference, *, threaded: bool, n_points: int) -> np.ndarray:
    """Mesh stiffness over one cycle, scalar loop over contact positions."""
    pinion, ring = gm.design_teeth(design, threaded)  # as design_mesh_stiffness builds them
    width1 = pinion.width
    roller, nut = design.roller_material, design.nut_material
    # Contact positions on the baseline's own phase grid, read off the reference path.
    p_b = ms_reference.base_pitch
    s0 = pinion.rb * math.sqrt((ms_reference.pinion_radius[0] / pinion.rb) ** 2 - 1)
    offset = (ring.rp - pinion.rp) * math.sin(design.gear.pressure_angle)
    n_samples = int(math.floor(ms_reference.contact_ratio * n_points + 1e-9)) + 1
    single = np.empty(n_samples)
    for j in range(n_samples):
        s = s0 + j / n_points * p_b
        t1, t2 = s / pinion.rb, (s + offset) / ring.rb
        r1 = pinion.rb * math.sqrt(1 + t1 * t1)
        kh = float(
            gm.hertz_compliance(
                float(width1(r1)),
                roller.youngs_modulus,
                roller.poisson_ratio,
                nut.youngs_modulus,
                nut.poisson_ratio,
            )
        )
        single[j] = 1.0 / (kh + _scalar_terms(pinion, t1) + _scalar_terms(ring, t2))
    total = np.zeros(n_points)
    for j in range(n_samples):
        total[j % n_points] += single[j]
    return total, single


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--design", default="paper01")
    ap.add_argument("--n-points", type=int, default=400)
    ap.add_argument(
        "--baseline-points",
        type=int,
        default=400,
        help="phase samples for the scalar baseline (fewer = faster)",
    )
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--standard", action="store_true", help="standard instead of threaded tooth")
    args = ap.parse_args(argv)
    design = preset(args.design)
    threaded = not args.standard

    gm.design_mesh_stiffness(design, threaded_tooth=threaded, n_points=args.n_points)  # warm
    t0 = time.perf_counter()
    for _ in range(args.repeat):
        ms = gm.design_mesh_stiffness(design, threaded_tooth=threaded, n_points=args.n_points)
    t_vec = (time.perf_counter() - t0) / args.repeat

    t0 = time.perf_counter()
    k_base, single_base = baseline(design, ms, threaded=threaded, n_points=args.baseline_points)
    t_base = time.perf_counter() - t0

    # Accuracy: compare on the baseline grid (a sub-grid of the vectorised one when the
    # vectorised grid is a multiple of it).
    ms_b = gm.design_mesh_stiffness(design, threaded_tooth=threaded, n_points=args.baseline_points)
    rel = np.max(np.abs(single_base - ms_b.single_pair) / ms_b.single_pair)

    per_vec = t_vec / ms.single_pair.size
    per_base = t_base / single_base.size
    print(
        f"design {args.design}, {'threaded' if threaded else 'standard'} roller tooth, "
        f"contact ratio {ms.contact_ratio:.4f}"
    )
    print(
        f"vectorised (Gauss–Legendre panels): {t_vec * 1e3:8.2f} ms per mesh cycle "
        f"({args.n_points} phases, {ms.single_pair.size} contact positions)"
    )
    print(
        f"scalar baseline (scipy quad)     : {t_base * 1e3:8.2f} ms per mesh cycle "
        f"({args.baseline_points} phases, {single_base.size} contact positions)"
    )
    print(f"speed-up per contact position    : {per_base / per_vec:8.1f}x")
    if args.baseline_points == args.n_points:
        print(f"speed-up per mesh cycle          : {t_base / t_vec:8.1f}x")
    print(f"max relative difference of the single-pair stiffness: {rel:.2e}")
    print(
        f"k_min {ms.k_min:.4e}  k_max {ms.k_max:.4e}  k_mean {ms.k_mean:.4e} N/m "
        f"(baseline mean {k_base.mean():.4e})"
    )


if __name__ == "__main__":
    main()
