"""Paper 05 (electric cylinder accuracy): every printed number against the SI model.

The paper's Δl(F, x) is printed in metres with F in N and x in mm; its stiffness table in
mm and N/mm. Rows keep the paper's units so the two columns compare directly. The model is
:mod:`prsm_health.physics.stiffness.cylinder` for the paper's parameter table
(:meth:`ElectricCylinder.paper05`), whose module docstring gives the unit readings.

Tolerances of the reproduced rows: the paper evaluates with π ≈ 3.14 (π·d1²/4 and
π(d2'² − d2²)/4 with 3.14 give its 4.915e-12 and 1.365e-9 to the last digit), 0.05 % from π;
0.1 % admits that and its four-digit printing, nothing more.

References
----------
Paper 05 (docs/references.md) — printed Δl(F, x), stiffness
table, contact stiffness examples, influence-coefficient vectors (x = 300 mm, F = 5000 N).
"""

from __future__ import annotations

import math

from prsm_health.physics.stiffness import cylinder as cyl_mod

from . import Row, inconsistent, not_computable, reproduced

PAPER = "05"
#: π ≈ 3.14 in the paper plus four-digit printing (module docstring).
PRINT_TOLERANCE = 1e-3

MM = 1e-3
_BELT_MISSING = (
    "the paper gives r1, r2, F0 only; R_c, R_r, R_p, c, φ (polygon effect) and l8, E3, b, h_s, "
    "h_t (belt stretch) are missing, so Δl8 cannot be evaluated"
)


# ------------------------------------------------------------------ paper's own arithmetic
def _paper_printed_dl(load: float, x_mm: float) -> float:
    """The paper's simplified Δl(F, x) [m], F [N], x [mm], exactly as printed."""
    return (
        2.5038e-7 * load
        + 2.753e-5 * load ** (2 / 3)
        + 6.801e-9 * load
        + 7.4975e-11 * load * x_mm
        + 5.503e-6
    )


def _printed_thread_gammas(cyl) -> tuple[float, float]:
    """Σγ_S/F and Σγ_N/F evaluated literally in SI (F' in N, p = lead) [m²/N]."""
    d = cyl.design
    e, nu = d.screw_material.youngs_modulus, d.screw_material.poisson_ratio
    lam, beta = cyl.lambda_, d.contact_angle
    f_prime = 1.0 / (d.engaged_threads * math.sin(beta) * math.cos(lam))
    s2, p = math.sqrt(2.0), d.screw_lead
    common = (
        (1 - nu**2) * 3 * s2 * f_prime * (4 * math.log(2) - 3) / (16 * e)
        + (1 + nu) * 6 * s2 * f_prime * math.log(2) / (10 * e)
        + (1 - nu**2) * 3 * s2 * f_prime * math.log(3) / (2 * math.pi * e)
    )
    d1, d2, d2o = d.screw_diameter, d.nut_diameter, d.nut_outer_diameter
    g5s = (1 - nu) * s2 * f_prime * d1 / (4 * p * e)
    g5n = ((d2o**2 + d2**2) / (d2o**2 - d2**2) + nu) * 2 * f_prime * d2 / (4 * p * e)
    return common + g5s, common + g5n


def _paper_k_formula(cyl) -> float:
    """The paper's K = (k_S + k_N)·cos λ/(i^(2/3) sin^(5/3) β) with exact Hertz k [m/N^(2/3)]."""
    k = cyl.coefficients
    d = cyl.design
    return (
        (k["contact_screw"] + k["contact_nut"])
        * math.cos(cyl.lambda_)
        / (d.n_rollers ** (2 / 3) * math.sin(d.contact_angle) ** (5 / 3))
    )


def _torsion_coefficient(cyl, lead: float) -> float:
    d = cyl.design
    return 8 * lead**2 / (math.pi**3 * d.screw_diameter**4 * cyl.efficiency * cyl.shear_modulus)


# ------------------------------------------------------------------ rows
def rows() -> list[Row]:
    """One row per number paper 05 prints for its cylinder."""
    cyl = cyl_mod.ElectricCylinder.paper05()
    k = cyl.coefficients
    out: list[Row] = []
    out += _coefficient_rows(cyl, k)
    out += _stiffness_table_rows(cyl)
    out += _contact_stiffness_rows(k)
    out += _influence_rows(cyl, k)
    return out


def _coefficient_rows(cyl, k) -> list[Row]:
    where = "Δl(F, x), printed coefficients"
    b = cyl.bearing
    l1_mm = b.roller_length / MM
    catalogue = 1.0 / (
        cyl_mod.BEARING_CONSTANT
        * b.n_rollers**0.9
        * l1_mm**0.8
        * math.sin(b.contact_angle) ** 1.9
        * b.preload**0.1
    )
    palmgren = 1.0 / (0.45 * 2 * cyl_mod.PALMGREN_LINE_CONTACT)
    paper_k = _paper_k_formula(cyl)
    lit_s, lit_n = _printed_thread_gammas(cyl)
    d = cyl.design
    t5 = _torsion_coefficient(cyl, 5 * MM)
    t6 = _torsion_coefficient(cyl, 6 * MM)
    linear_sum = 1.597e-13 + 1.106e-12 + 1.365e-9 + 5.115e-9
    return [
        inconsistent(
            PAPER,
            where,
            "Δl1/F, support bearings",
            "m/N",
            2.5038e-7,
            k["bearing"],
            f"digits reproduced exactly: the formula gives {catalogue:.5g} with F, F_a0 in N and "
            f"l1 in mm, but in µm, not mm: its constant is Palmgren's line contact "
            f"(3.84e-5 mm per raceway, two raceways, preloaded pair → 1/(0.45·7.68e-5 mm) = "
            f"{palmgren:.0f}/mm = {palmgren / 1e3:.2f}/µm ≈ 29.011). Read as mm, the pair would "
            f"deflect 1.5 mm at its own 6 kN preload, where Palmgren gives ≈ 3.3 µm. "
            f"Model (µm → m): {k['bearing']:.4e} m/N, 1000× stiffer",
        ),
        inconsistent(
            PAPER,
            where,
            "Δl2/F^(2/3), roller contact",
            "m/N^(2/3)",
            2.753e-5,
            k["contact"],
            f"the paper's own K formula with exact Hertz in SI gives {paper_k:.4e} "
            f"({2.753e-5 / paper_k:.1f}× smaller than printed; 200 = (10³)^(2/3)·2, e.g. a "
            f"modulus in GPa against lengths in mm plus an unexplained factor 2 — reading E in "
            f"MPa with curvature in 1/m gives ≈ 1.4e-3, not 2.75e-5). Its k_S, k_N also print "
            f"(Σρ)^(−1/3), dimensionally wrong (Hertz: +1/3). Model is "
            f"{k['contact'] / paper_k - 1:+.2%} from the paper's K formula: it projects δ by "
            f"virtual work, u = δ/(sin β cos λ), where the paper writes δ·cos λ/sin β (cos²λ), "
            f"and keeps the cos^(−2/3)λ of Q that the paper's K drops",
        ),
        inconsistent(
            PAPER,
            where,
            "Δl3/F, screw thread",
            "m/N",
            1.597e-13,
            k["screw_thread"],
            f"as printed γ ∝ F'/E has units m², not m: literal SI evaluation gives "
            f"{lit_s:.3e} m²/N; per unit circumference (÷π·d1) with p = lead "
            f"{lit_s / (math.pi * d.screw_diameter):.3e} m/N; no unit reading gives 1.597e-13 "
            f"(≈ literal/10 within 5 %, unexplained). Model: Yamamoto line load "
            f"F/(i1·π·d1), P = pitch {d.pitch / MM:g} mm",
        ),
        inconsistent(
            PAPER,
            where,
            "Δl4/F, nut thread",
            "m/N",
            1.106e-12,
            k["nut_thread"],
            f"as printed γ has units m²: literal SI {lit_n:.3e} m²/N; per π·d2 with p = lead "
            f"{lit_n / (math.pi * d.nut_diameter):.3e} m/N; none gives 1.106e-12. The printed "
            f"γ5N has 2F' where Yamamoto (and the paper's γ5S) give √2F'. Model: Yamamoto line "
            f"load F/(i1·π·d2), P = pitch, √2",
        ),
        reproduced(
            PAPER,
            where,
            "Δl5/F, nut body",
            "m/N",
            1.365e-9,
            k["nut_body"],
            PRINT_TOLERANCE,
            "F·l5/(E2·π(d2'² − d2²)/4), l5 = 600 mm; paper uses π ≈ 3.14 (→ 1.3649e-9)",
        ),
        reproduced(
            PAPER,
            where,
            "Δl6/(F·x), screw axial",
            "m/(N·mm)",
            4.915e-12,
            k["screw_axial"] * MM,
            PRINT_TOLERANCE,
            "x/(E1·π·d1²/4) with x in mm; paper uses π ≈ 3.14 (→ 4.9151e-12)",
        ),
        inconsistent(
            PAPER,
            where,
            "Δl7/(F·x), screw torsion",
            "m/(N·mm)",
            7.006e-11,
            k["screw_torsion"] * MM,
            f"8p²/(π³d1⁴ηG) is {t5:.4e} per metre of x with the printed lead p = 5 mm and "
            f"{t6:.4e} with p = 6 mm ({7.006e-11 / t6 - 1:+.2%}): the printed value is the "
            f"p = 6 mm coefficient per metre, yet the paper multiplies it by x in mm (next to "
            f"the per-mm screw-axial term), 1000·(6/5)² = {1000 * (6 / 5) ** 2:.0f}× too large",
        ),
        not_computable(PAPER, where, "Δl8/F, belt stretch", "m/N", 5.115e-9, None, _BELT_MISSING),
        not_computable(
            PAPER,
            where,
            "Δl8 at F = 0, belt polygon + pretension",
            "m",
            5.503e-6,
            None,
            _BELT_MISSING,
        ),
        inconsistent(
            PAPER,
            "Δl(F, x), simplified",
            "sum of linear terms Δl3…Δl5, Δl8",
            "m/N",
            6.801e-9,
            k["screw_thread"] + k["nut_thread"] + k["nut_body"],
            f"its own addends 1.597e-13 + 1.106e-12 + 1.365e-9 + 5.115e-9 sum to "
            f"{linear_sum:.4e}, not 6.801e-9. Model value: Δl3 + Δl4 + Δl5 (belt not computable)",
        ),
        inconsistent(
            PAPER,
            "Δl(F, x), simplified",
            "sum of F·x terms Δl6 + Δl7",
            "m/(N·mm)",
            7.4975e-11,
            (k["screw_axial"] + k["screw_torsion"]) * MM,
            "the addition 4.915e-12 + 7.006e-11 is right, but the torsion addend is the p = 6 mm "
            "per-metre coefficient (see Δl7 row)",
        ),
    ]


_TABLE = (  # x [mm], F [N], Δl [mm], k [N/mm] as printed
    (0, 500, 0.0138, 36231),
    (0, 1000, 0.0276, 36231),
    (300, 500, 0.0139, 35971),
    (300, 1000, 0.0278, 35971),
    (600, 500, 0.0140, 35714),
    (600, 1000, 0.0280, 35714),
)


def _stiffness_table_rows(cyl) -> list[Row]:
    out = []
    for x_mm, load, dl_mm, k_paper in _TABLE:
        own_dl = _paper_printed_dl(load, x_mm)  # m
        own_k = load / (own_dl / MM)  # N/mm
        model_dl = float(cyl_mod.total_deformation(cyl, load, x_mm * MM))
        model_k = float(cyl_mod.stiffness(cyl, load, x_mm * MM)) * MM
        out.append(
            inconsistent(
                PAPER,
                "stiffness table",
                f"k at x = {x_mm} mm, F = {load} N",
                "N/mm",
                k_paper,
                model_k,
                f"table Δl = {dl_mm} mm is linear in F (k independent of F, impossible with an "
                f"F^(2/3) term); the paper's own Δl(F, x) gives {own_dl / MM:.4g} mm, k = "
                f"{own_k:.4g} N/mm: the table is {k_paper / own_k:.0f}× stiffer than its own "
                f"function ({own_k / k_paper - 1:+.1%}). Model Δl = {model_dl / MM:.4g} mm; its "
                f"nearness to the table is coincidence (the table has no F dependence)",
            )
        )
    return out


def _contact_stiffness_rows(k) -> list[Row]:
    where = "contact stiffness k_c = F/Δl2"
    coefficient = 1.0 / k["contact"]  # N/(m·N^(1/3))

    def model_kc(load):
        return load ** (1 / 3) / k["contact"] * MM  # N/mm

    out = [
        inconsistent(
            PAPER,
            where,
            "k_c/F^(1/3) = 1/K",
            "N/(m·N^(1/3))",
            3.633e4,
            coefficient,
            "1/2.753e-5 = 3.632e4 is right arithmetic, but K is wrong (contact-coefficient row)",
        )
    ]
    for load, printed in ((500, 29000.0), (1000, 36330.0)):
        own = 3.633e4 * load ** (1 / 3) * MM  # its own law, F [N], k [N/m] → N/mm
        out.append(
            inconsistent(
                PAPER,
                where,
                f"k_c at F = {load} N",
                "N/mm",
                printed,
                model_kc(load),
                f"its own 3.633e4·F^(1/3) [N/m] gives {own:.4g} N/mm; the printed value is "
                f"3.633e4·(F/1 kN)^(1/3) = {3.633e4 * (load / 1000) ** (1 / 3):.4g} labelled "
                f"N/mm. Model with correct Hertz",
            )
        )
    return out


def _influence_rows(cyl, k) -> list[Row]:
    where_f = "∂Δl_i/∂F at x = 300 mm, F = 5000 N"
    where_x = "∂Δl_i/∂x at x = 300 mm, F = 5000 N"
    load, x = 5000.0, 300 * MM
    ic = cyl_mod.influence_coefficients(cyl, load, x)
    d = {name: float(v) for name, v in ic.load.items()}
    dx = {name: float(v) * MM for name, v in ic.extension.items()}  # m per mm of x
    true_root = 5000.0 ** (-1 / 3)
    return [
        inconsistent(
            PAPER,
            where_f,
            "∂Δl1/∂F",
            "m/N",
            2.5038e-7,
            d["bearing"],
            "bearing formula read in mm instead of µm (Δl1 coefficient row)",
        ),
        inconsistent(
            PAPER,
            where_f,
            "∂Δl2/∂F coefficient (2/3)·K",
            "m/N^(2/3)",
            1.835e-5,
            2 / 3 * k["contact"],
            "(2/3)·2.753e-5 is right arithmetic; K is wrong (contact row)",
        ),
        inconsistent(
            PAPER,
            where_f,
            "5000^(−1/3)",
            "N^(−1/3)",
            0.5848,
            true_root,
            f"5000^(−1/3) = {true_root:.5f}: the printed 0.5848 is 10× too large",
        ),
        inconsistent(
            PAPER,
            where_f,
            "∂Δl2/∂F",
            "m/N",
            1.073e-5,
            d["contact"],
            f"1.835e-5 × 0.5848 is right arithmetic on two wrong factors (K 200× too large, "
            f"5000^(−1/3) 10×); with the printed K and the true 5000^(−1/3) it would be "
            f"{1.835e-5 * true_root:.4e}",
        ),
        inconsistent(
            PAPER,
            where_f,
            "∂Δl3/∂F",
            "m/N",
            1.597e-13,
            d["screw_thread"],
            "thread terms as printed are not lengths (Δl3 coefficient row)",
        ),
        inconsistent(
            PAPER,
            where_f,
            "∂Δl4/∂F",
            "m/N",
            1.106e-12,
            d["nut_thread"],
            "thread terms as printed are not lengths (Δl4 coefficient row)",
        ),
        reproduced(
            PAPER,
            where_f,
            "∂Δl5/∂F",
            "m/N",
            1.365e-9,
            d["nut_body"],
            PRINT_TOLERANCE,
            "nut body, π ≈ 3.14 in the paper",
        ),
        reproduced(
            PAPER,
            where_f,
            "∂Δl6/∂F",
            "m/N",
            1.4745e-9,
            d["screw_axial"],
            PRINT_TOLERANCE,
            "4.915e-12 × 300 mm; model x/(E1·π·d1²/4) at x = 0.3 m; π ≈ 3.14 in the paper",
        ),
        inconsistent(
            PAPER,
            where_f,
            "∂Δl7/∂F",
            "m/N",
            2.1018e-8,
            d["screw_torsion"],
            "7.006e-11 (p = 6 mm, per metre of x) × 300 (x in mm): 1000·(6/5)² too large",
        ),
        not_computable(PAPER, where_f, "∂Δl8/∂F", "m/N", 5.115e-9, None, _BELT_MISSING),
        reproduced(
            PAPER,
            where_x,
            "∂Δl6/∂x",
            "m/mm",
            2.4575e-8,
            dx["screw_axial"],
            PRINT_TOLERANCE,
            "4.915e-12 × 5000 N per mm of x; π ≈ 3.14 in the paper",
        ),
        inconsistent(
            PAPER,
            where_x,
            "∂Δl7/∂x",
            "m/mm",
            3.503e-7,
            dx["screw_torsion"],
            "7.006e-11 × 5000: the p = 6 mm per-metre torsion coefficient used per mm",
        ),
    ]
