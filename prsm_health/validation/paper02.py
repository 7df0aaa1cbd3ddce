"""Paper 02 rows: friction torque and efficiency table, under the model's stated reading.

Reference: paper 02 (docs/references.md), results table and text. Reading:
Coulomb friction and M_fs3 summed over all n_R·n_t contacts, zero contact offset angles, the
screw ramped linearly to 1 rad/s over t_acc, efficiencies over [0, t_acc + 0.1 s]
(prsm_health/physics/friction.py).
"""

from __future__ import annotations

from prsm_health.physics.friction import FrictionParameters, simulate_friction

from . import Row, inconsistent, reproduced

#: (F_out [N], t_acc [s]) → (peak torque, steady torque [N·m], η_min, η_overall [%]) as printed.
TABLE = {
    (500.0, 0.02): (0.15, 0.08, 78.5, 85.2),
    (1000.0, 0.02): (0.25, 0.12, 76.8, 87.1),
    (3000.0, 0.02): (0.55, 0.25, 74.3, 89.5),
    (5000.0, 0.02): (0.85, 0.40, 72.1, 91.0),
    (1000.0, 0.01): (0.40, 0.12, 70.5, 88.9),
    (1000.0, 0.03): (0.20, 0.12, 79.2, 87.5),
    (1000.0, 0.06): (0.15, 0.12, 84.1, 86.8),
    (1000.0, 0.09): (0.13, 0.12, 87.8, 86.2),
}

_PEAK_REASON = (
    "with the table's μ1 = 0.01 N·s/m and μ2·F_n far above the torque needed to spin the rollers "
    "up, the rollers keep rolling and the transient adds < 2 % to the steady torque; a 1.1–3.3× "
    "peak needs sliding the model as parameterised cannot produce"
)


def rows() -> list[Row]:
    params = FrictionParameters.paper02()
    out: list[Row] = []
    for (load, t_acc), (peak, steady, eta_min, eta_all) in TABLE.items():
        r = simulate_friction(params, load, 1.0, t_acc)
        where = f"table, {load:.0f} N, t_acc {t_acc:g} s"
        out.append(
            inconsistent(
                "02",
                where,
                "peak friction torque",
                "N·m",
                peak,
                r.peak_friction_torque,
                _PEAK_REASON,
            )
        )
        if load == 1000.0:
            out.append(
                reproduced(
                    "02",
                    where,
                    "steady friction torque",
                    "N·m",
                    steady,
                    r.steady_friction_torque,
                    0.10,
                    "F(μ2 p_s + μ3)/(cos ψ cos β), all contacts; the issue's 10 % band for this "
                    "reading (the paper prints 2 digits)",
                )
            )
        else:
            out.append(
                inconsistent(
                    "02",
                    where,
                    "steady friction torque",
                    "N·m",
                    steady,
                    r.steady_friction_torque,
                    "the model as written is proportional to F at steady speed (every friction "
                    "term ∝ F_n); the table is affine in F (≈ 0.045 N·m + 0.071 N·m/kN), which "
                    "needs a load-independent loss the model does not have",
                )
            )
        p_s = params.lead_per_radian
        cap = load * p_s / (load * p_s + peak)
        paper_steady_eta = load * p_s / (load * p_s + steady)
        if eta_min / 100 > cap:
            reason = (
                f"exceeds the cap F·p_s/(F·p_s + T_peak) = {100 * cap:.1f} % set by the paper's "
                "own peak torque"
            )
        else:
            reason = (
                "follows from the paper's peak torque, which its model cannot produce (row above)"
            )
        out.append(
            inconsistent(
                "02",
                where,
                "minimum instantaneous efficiency",
                "%",
                eta_min,
                100 * r.min_efficiency,
                reason,
            )
        )
        if eta_all / 100 > paper_steady_eta:
            reason = (
                f"above the paper's own steady efficiency F·p_s/(F·p_s + T_steady) = "
                f"{100 * paper_steady_eta:.1f} %: impossible, start-up only adds losses"
            )
        else:
            reason = (
                "the model's steady efficiency is 87.4 % at every load (no load-independent "
                "loss), so the overall efficiency cannot rise with load as printed"
            )
        out.append(
            inconsistent(
                "02", where, "overall efficiency", "%", eta_all, 100 * r.overall_efficiency, reason
            )
        )
    short = simulate_friction(params, 1000.0, 1.0, 0.01).peak_friction_torque
    long = simulate_friction(params, 1000.0, 1.0, 0.09).peak_friction_torque
    out.append(
        inconsistent(
            "02",
            "text",
            "peak torque ratio t_acc 0.01 s / 0.09 s",
            "-",
            2.0,
            short / long,
            "the paper's own table gives 0.40/0.13 = 3.1, not 2; the model keeps the direction "
            "(shorter ramp → higher peak) with a small effect (peak row reason)",
        )
    )
    return out
