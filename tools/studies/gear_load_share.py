"""The gears' real load: gear load share across the duty, roller slip, tooth-damage visibility.

With the rollers rolling on both threads (screw and nut tractions) and meshing with the ring
gear, a roller is over-constrained: the mismatch ε between the gear ratio z_ring/z_roller and the
nut–roller rolling ratio (design, roller-radius tolerance, elastic approach under load;
prsm_health.physics.rolling_mismatch.rolling_mismatch_terms) is shared between creep at the
threads and the gear (Jones & Velinsky, J. Mech. Des. 134(6) 061006, 2012). This study measures

1. the gear load share: the ring-gear mesh force of each roller over its axial thread load
   (load / n_rollers), RMS and mean, and the fraction of time each thread traction sits at its
   Coulomb limit (the roller slips), at 5, 20, 40 % of C_a and 30, 100 rad/s, with ideal and
   default manufacturing variation (the elastic mismatch acts in both);
2. tooth-damage visibility: a ring-gear tooth crack and a tooth pit at their default severity vs
   healthy units, at the default duty (20 % C_a, 100 rad/s) and the highest (40 % C_a, 100
   rad/s), 3 seeds each, on the flight-ema measured channels: the time-synchronous average of
   the nut axial acceleration and of the drive torque on the measured motor angle over one
   carrier turn (a ring tooth meets every roller once per carrier turn), scored as the SNR of
   tools/studies/duty_signatures.py, and the energy of that average's carrier-order sidebands
   around the mesh order against healthy units' scatter.

    python tools/studies/gear_load_share.py [--seeds 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace

import numpy as np

from prsm_health.actuator.design import preset
from prsm_health.actuator.states import HealthState, ManufacturingVariation, OperatingProfile
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings
from prsm_health.signals.gear_indicators import time_synchronous_average
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import SimulationOptions, build_model
from prsm_health.simulation.dynamics.simulate import (
    integrate,
    integration_step,
    max_stable_step,
    settled_state,
)
from prsm_health.simulation.scenario import simulate

DESIGN = preset("paper01")
C_A = load_ratings(DESIGN).dynamic
SHARES = (0.05, 0.20, 0.40)
SPEEDS = (30.0, 100.0)
#: the rate the roller forces are read at [Hz] (every step's last right-hand side)
RATE = 20_000.0


def roller_forces(model, duration: float, mismatch: float | None = None) -> dict[str, np.ndarray]:
    """Run ``model`` as :func:`simulate` does (stable step, settling) and read each roller's gear
    mesh force, thread traction forces and their Coulomb limits at :data:`RATE`.

    ``mismatch``: overrides every roller's pitch mismatch ε (the nut-side rolling radius
    r_r/(1 + ε)). Returns arrays (n_samples, n_rollers) and the model used.
    """
    if mismatch is not None:
        rollers = model.rollers.copy()
        rollers[:, L.R_ROLL_N] = DESIGN.roller_diameter / 2 / (1.0 + mismatch)
        rollers[:, L.R_MISMATCH] = mismatch
        model = replace(model, rollers=rollers)
    h_stable, f_max = max_stable_step(model)
    h, factor = integration_step("auto", h_stable, f_max, RATE)
    y = settled_state(model, h, model.options.settle_time)
    n = model.n_rollers
    n_out = int(round(duration * RATE))
    aux = np.zeros(L.n_aux(n))
    out = np.empty((n_out, L.N_AUX_PER_ROLLER, n))
    for k in range(n_out):
        integrate(model, y, h, factor, t0=k * factor * h, record=False, aux=aux)
        out[k] = aux[L.N_AUX :].reshape(L.N_AUX_PER_ROLLER, n)
    return {
        "cap_s": out[:, L.AR_CAP_S],
        "cap_n": out[:, L.AR_CAP_N],
        "gear": out[:, L.AR_GEAR],
        "traction_s": out[:, L.AR_TRACTION_S],
        "traction_n": out[:, L.AR_TRACTION_N],
        "model": model,
    }


def share_stats(forces: dict, load: float) -> dict[str, float]:
    """Gear load share (RMS and |mean| of the mesh force over load/n, averaged over rollers) and
    the fraction of samples at which a traction sits at its Coulomb limit (within 1 %)."""
    model = forces["model"]
    per_roller = load / model.n_rollers
    gear = forces["gear"]
    at_cap = {
        side: float(np.mean(np.abs(forces[f"traction_{side}"]) >= 0.99 * forces[f"cap_{side}"]))
        for side in ("s", "n")
    }
    return {
        "gear_rms_share": float(np.mean(np.sqrt(np.mean(gear**2, axis=0)))) / per_roller,
        "gear_mean_share": float(np.mean(np.abs(np.mean(gear, axis=0)))) / per_roller,
        "gear_signed_share": float(np.mean(gear)) / per_roller,
        "nut_traction_share": float(np.mean(np.abs(np.mean(forces["traction_n"], axis=0))))
        / per_roller,
        "slip_screw": at_cap["s"],
        "slip_nut": at_cap["n"],
        "mismatch_rms": float(np.sqrt(np.mean(model.rollers[:, L.R_MISMATCH] ** 2))),
    }


def share_table(seeds: int, duration: float = 0.1) -> list[dict]:
    rows = []
    for variation_name, variation in (
        ("ideal", ManufacturingVariation.ideal()),
        ("default", ManufacturingVariation()),
    ):
        options = SimulationOptions(variation=variation, max_step="auto")
        for share in SHARES:
            load = share * C_A
            for speed in SPEEDS:
                stats = []
                for seed in range(seeds if variation_name == "default" else 1):
                    profile = OperatingProfile(duration=duration, speed=speed, load=load)
                    model = build_model(DESIGN, HealthState(), profile, options, seed)
                    stats.append(share_stats(roller_forces(model, duration), load))
                rows.append(
                    {
                        "variation": variation_name,
                        "load_share": share,
                        "speed": speed,
                        **{k: [s[k] for s in stats] for k in stats[0]},
                    }
                )
    return rows


def sweep_table(duration: float = 0.1) -> list[dict]:
    """Gear share against an imposed mismatch ε (every roller), 20 % C_a, 100 rad/s, ideal."""
    rows = []
    options = SimulationOptions(variation=ManufacturingVariation.ideal(), max_step="auto")
    load = 0.2 * C_A
    profile = OperatingProfile(duration=duration, speed=100.0, load=load)
    model = build_model(DESIGN, HealthState(), profile, options, 0)
    for eps in (0.0, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2):
        rows.append({"mismatch": eps, **share_stats(roller_forces(model, duration, eps), load)})
    return rows


def sideband_energy(tsa: np.ndarray, mesh_order: int, half_width: int) -> float:
    """Energy of the carrier orders mesh_order ± 1…half_width of one carrier-turn average (the
    sidebands a once-per-pass modulation of the mesh puts around it), over its total energy."""
    spectrum = np.abs(np.fft.rfft(tsa - np.mean(tsa))) ** 2
    orders = np.arange(len(spectrum))
    side = (np.abs(orders - mesh_order) >= 1) & (np.abs(orders - mesh_order) <= half_width)
    return float(np.sum(spectrum[side]) / np.sum(spectrum[1:]))


def tsa_snr(x: np.ndarray, angle: np.ndarray, period: float) -> float:
    """As tools/studies/duty_signatures.py: TSA variance over a K-period noise average's, − 1."""
    tsa, periods = time_synchronous_average(x - np.mean(x), angle, period, 1024)
    k = periods.shape[0]
    noise = np.var(periods - tsa) / k
    return float(np.var(tsa) / noise - 1.0)


def visibility_table(seeds: int, duration: float = 1.0) -> list[dict]:
    ratios = speed_ratios(DESIGN)
    carrier_turn = 2 * math.pi / abs(ratios.carrier)  # of the motor (= screw) angle
    z = DESIGN.gear.ring_teeth
    cases = {
        "healthy": (),
        "ring tooth crack": ({"kind": "tooth_crack", "location": "ring_gear"},),
        "ring tooth pit": ({"kind": "tooth_pit", "location": "ring_gear"},),
    }
    rows = []
    for duty, share in (("default 20 % C_a", 0.2), ("highest 40 % C_a", 0.4)):
        for case, faults in cases.items():
            values: dict[str, list] = {}
            for seed in range(seeds):
                run = simulate(
                    DESIGN,
                    HealthState(faults=faults),
                    OperatingProfile(duration=duration, speed=100.0, load=share * C_A),
                    "flight-ema",
                    seed=400 + seed,
                )
                angle = run["motor_angle"] if "motor_angle" in run.channels else run["screw_angle"]
                for name in ("nut_axial_accel", "drive_torque"):
                    x = run[name]
                    tsa, _ = time_synchronous_average(x - np.mean(x), angle, carrier_turn, 4096)
                    values.setdefault(f"snr_{name}", []).append(tsa_snr(x, angle, carrier_turn))
                    values.setdefault(f"sb_{name}", []).append(sideband_energy(tsa, z, 14))
            rows.append({"duty": duty, "case": case, **values})
    # z-score of each faulty unit's indicator against the healthy units' mean and scatter
    for row in rows:
        healthy = next(r for r in rows if r["duty"] == row["duty"] and r["case"] == "healthy")
        for key in [k for k in row if k.startswith(("snr_", "sb_"))]:
            ref = np.asarray(healthy[key])
            spread = max(float(np.std(ref, ddof=1)), 1e-12)
            row[f"z_{key}"] = [float((v - np.mean(ref)) / spread) for v in row[key]]
    return rows


def _fmt(values, digits=3) -> str:
    values = np.asarray(values, float)
    if values.size == 1:
        return f"{values[0]:.{digits}g}"
    return (
        f"{np.median(values):.{digits}g} ({np.min(values):.{digits}g}–{np.max(values):.{digits}g})"
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--skip-visibility", action="store_true")
    parser.add_argument("--json", help="write the tables as JSON")
    args = parser.parse_args(argv)
    print(f"paper01: C_a = {C_A:.0f} N; gear share = mesh force / (load / n_rollers)")
    tables = {"sweep": sweep_table(), "share": share_table(args.seeds)}
    print("\nImposed mismatch ε on every roller (20 % C_a, 100 rad/s, ideal variation):")
    print(
        "| ε | gear RMS share | gear mean share (signed) | nut traction share "
        "| time at μN: screw / nut |"
    )
    print("|---|---|---|---|---|")
    for r in tables["sweep"]:
        print(
            f"| {r['mismatch']:.0e} | {r['gear_rms_share']:.3g} | {r['gear_signed_share']:+.3g} | "
            f"{r['nut_traction_share']:.3g} | {r['slip_screw']:.2f} / {r['slip_nut']:.2f} |"
        )
    print("\nAcross the duty (median (min–max) over seeds; ideal: one unit, ε = elastic only):")
    print(
        "| variation | load | speed [rad/s] | ε RMS | gear RMS share | gear mean share "
        "| time at μN: screw | nut |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in tables["share"]:
        print(
            f"| {r['variation']} | {r['load_share']:.0%} C_a | {r['speed']:.0f} | "
            f"{_fmt(r['mismatch_rms'], 2)} | {_fmt(r['gear_rms_share'])} | "
            f"{_fmt(r['gear_mean_share'])} | {_fmt(r['slip_screw'], 2)} | "
            f"{_fmt(r['slip_nut'], 2)} |"
        )
    if not args.skip_visibility:
        tables["visibility"] = visibility_table(args.seeds)
        print(
            "\nRing-tooth damage at default severity, flight-ema, 100 rad/s; TSA over a carrier "
            "turn on the motor angle; z = (value − healthy mean) / healthy σ:"
        )
        print(
            "| duty | unit | TSA SNR nut axial | z | mesh sidebands nut axial | z "
            "| TSA SNR drive torque | z | mesh sidebands torque | z |"
        )
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in tables["visibility"]:
            cells = []
            for ch in ("nut_axial_accel", "drive_torque"):
                for kind in ("snr", "sb"):
                    cells += [_fmt(r[f"{kind}_{ch}"]), _fmt(r[f"z_{kind}_{ch}"], 2)]
            print(f"| {r['duty']} | {r['case']} | " + " | ".join(cells) + " |")
    if args.json:
        for table in tables.values():
            for row in table:
                row.pop("model", None)
        with open(args.json, "w") as f:
            json.dump(tables, f, indent=1)


if __name__ == "__main__":
    main()
