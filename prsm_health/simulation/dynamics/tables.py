"""The kernel's tabulated inputs: geometric error profiles, the Coulomb coefficient over
entrainment speed, and the spall and tooth-damage tables (layout ``ERR_*`` rows, ``P_SPALL_*``).

Each is built once per run by :func:`~prsm_health.simulation.dynamics.model.build_model` from the
design, health state, profile and options; the sources of every profile are in the functions.
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.core.errors import require
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.lubrication import stribeck_curve
from prsm_health.physics.stiffness.damaged_mesh import damaged_mesh

from . import layout as L


def error_terms(design, variation, rng, spalls=()) -> tuple[np.ndarray, float]:
    """Geometric error tables (layout ``ERR_*`` rows) and the cumulative lead slope [-].

    Each kind is a sum of sinusoids of its contact coordinate, tabulated over its period: one
    screw or nut revolution for runout and gear errors, 16 for the lead error and waviness
    along the helix (their wave numbers rounded to multiples of 1/16, so the profile closes).
    """
    v = variation
    r_s, r_n = design.screw_diameter / 2, design.nut_diameter / 2
    draws = rng.standard_normal(2)
    phases = rng.uniform(0.0, 2 * math.pi, 24)
    wavelengths = np.exp(rng.uniform(math.log(0.3e-3), math.log(3e-3), 12))
    turns = 16
    terms: dict[int, list] = {kind: [] for kind in range(L.N_ERROR_KINDS)}
    # periodic lead error: v_2πp peak to peak over harmonics 1–3 of the contact angle
    for k, share in enumerate((0.6, 0.3, 0.1)):
        terms[L.ERR_SCREW_AXIAL].append((k + 1.0, 0.5 * v.lead_error_periodic * share, phases[k]))
    terms[L.ERR_SCREW_RADIAL].append((1.0, v.screw_runout, phases[3]))
    # flank waviness along the contact path, 6 components per flank of equal share
    amp = v.flank_waviness * math.sqrt(2.0 / 6.0)
    for j in range(6):
        for kind, radius, w in ((L.ERR_SCREW_AXIAL, r_s, j), (L.ERR_NUT_AXIAL, r_n, 6 + j)):
            wave = round(radius / wavelengths[w] * turns) / turns
            terms[kind].append((wave, amp, phases[4 + w]))
    if design.gear is not None:
        z = float(design.gear.ring_teeth)
        terms[L.ERR_GEAR] += [
            (1.0, 0.5 * v.gear_pitch_error, phases[16]),
            (z, 0.5 * v.gear_profile_error, phases[17]),
            (2 * z, 0.25 * v.gear_profile_error, phases[18]),
        ]
    periods = {
        L.ERR_SCREW_AXIAL: 2 * math.pi * turns,
        L.ERR_SCREW_RADIAL: 2 * math.pi,
        L.ERR_NUT_AXIAL: 2 * math.pi * turns,
        L.ERR_GEAR: 2 * math.pi,
        L.ERR_UNIT_COSINE: 2 * math.pi,
        L.ERR_SCREW_SPALL: 2 * math.pi,
        L.ERR_NUT_SPALL: 2 * math.pi,
        L.ERR_ROLLER_SPALL: 2 * math.pi,
        # tooth damage and the lubrication regime: filled by their own builders
        L.ERR_RING_TOOTH: 1.0,
        L.ERR_ROLLER_TOOTH: 1.0,
        L.ERR_COULOMB: 1.0,
    }
    terms[L.ERR_UNIT_COSINE].append((1.0, 1.0, math.pi / 2))
    tables = np.zeros((L.N_ERROR_KINDS, L.N_ERROR_POINTS + 1))
    for kind, rows in terms.items():
        u = np.arange(L.N_ERROR_POINTS) * periods[kind] / L.N_ERROR_POINTS
        tables[kind, 0] = 1.0 / periods[kind]  # the kernel multiplies (layout: ERR_*)
        for wave, amplitude, phase in rows:
            tables[kind, 1:] += amplitude * np.sin(wave * u + phase)
    radius = {"screw": r_s, "nut": r_n, "roller": design.roller_diameter / 2}
    kind = {"screw": L.ERR_SCREW_SPALL, "nut": L.ERR_NUT_SPALL, "roller": L.ERR_ROLLER_SPALL}
    u = np.arange(L.N_ERROR_POINTS) * 2 * math.pi / L.N_ERROR_POINTS
    for spall in spalls:
        tables[kind[spall.location], 1:] += spall_profile(u, spall, radius[spall.location])
    lead_slope = 0.5 * v.lead_error_cumulative / 0.3 * float(draws[0])
    return tables, lead_slope


def coulomb_table(errors, design, health, profile, options) -> float:
    """Fill the Coulomb coefficient vs entrainment speed (``ERR_COULOMB``) for the lubrication
    regime; 1.0 when the kernel is to read it, 0.0 for a constant coefficient."""
    if options.lubrication == "constant":
        return 0.0
    # Entrainment speed of the screw–roller contacts: ½|r_s(ω_s − ω_rev) − r_r(ω_c − ω_rev)|,
    # r_s·|ω_s − ω_rev| in pure rolling; tabulated to twice its nominal peak (transients),
    # beyond which the coefficient is flat anyway (full film).
    ratios = speed_ratios(design)
    peak = design.screw_diameter / 2 * abs(1.0 - ratios.carrier) * max(profile.speed, 1.0)
    speeds = np.linspace(0.0, 2.0 * peak, L.N_ERROR_POINTS)
    load = abs(profile.load) + profile.load_amplitude
    curve = stribeck_curve(
        design,
        options.lubricant,
        speeds,
        axial_load=load,
        temperature=profile.temperature,
        degradation=health.lubricant_degradation,
        starvation=health.lubricant_starvation,
    )
    errors[L.ERR_COULOMB, 0] = 1.0 / speeds[-1]
    errors[L.ERR_COULOMB, 1:] = curve.coefficient
    return 1.0


#: Which flank (plus, minus) of the screw–roller and roller–nut engagements carries a positive
#: resisting load (tests/dynamics/test_spalls.py checks it through the signature).
LOADED_FLANK = {"screw": (1.0, 0.0), "nut": (1.0, 0.0)}


def spall_params(p, design, health, profile, options) -> float:
    """Share, axial gate and flanks of the run's spalls (layout ``P_SPALL_*``); 1.0 when there
    is one, else 0.0. One spall per location and run; positions checked against the design."""
    spalls = health.spalls
    if not spalls:
        return 0.0
    engaged = design.engaged_threads * design.pitch
    for location in ("screw", "nut", "roller"):
        here = [s for s in spalls if s.location == location]
        require(
            len(here) <= 1,
            "faults.location",
            location,
            "one spall per location and run at most (the model has one depression per part)",
        )
        for spall in here:
            limit = design.screw_free_length / 2 if location == "screw" else engaged / 2
            what = "the screw's threaded length" if location == "screw" else "the engaged turns"
            require(
                abs(spall.position) <= limit,
                "faults.position",
                spall.position,
                f"must lie within ±{limit:.4g} m ({what}) for a {location} spall",
            )
    p[L.P_SPALL_SHARE] = 1.0 / design.engaged_threads
    p[L.P_SPALL_HALF], p[L.P_SPALL_RAMP] = 0.5 * engaged, design.pitch
    p[L.P_SPALL_Z] = 1e9  # no screw spall: the gate stays shut
    for spall in spalls:
        if spall.location == "roller":
            continue
        plus, minus = LOADED_FLANK[spall.location]
        if spall.flank == "unloaded":
            plus, minus = minus, plus
        elif spall.flank == "both":
            plus = minus = 1.0
        side = "S" if spall.location == "screw" else "N"
        p[getattr(L, f"P_SPALL_PLUS_{side}")] = plus
        p[getattr(L, f"P_SPALL_MINUS_{side}")] = minus
        if spall.location == "screw":
            # the roller threads' axial position relative to the screw, z_c − z_s, starts at 0
            # at the start of settling; the nut has moved on by t = 0
            settled = speed_ratios(design).nut * float(profile.motion_knots()[1, 0])
            p[L.P_SPALL_Z] = spall.position + settled * options.settle_time
    return 1.0


def tooth_tables(errors, rollers, design, health, options) -> float:
    """Fill the mesh-stiffness ratio tables of damaged gear teeth (``ERR_RING_TOOTH``,
    ``ERR_ROLLER_TOOTH``, per-roller ``R_TOOTH``); 1.0 when there is one, else 0.0.

    Each table spans one turn of its gear in mesh cycles (z teeth): the damaged tooth ``k``
    enters contact at phase k and stays for the cycles of :func:`damaged_mesh`."""
    faults = health.of_kind("tooth_crack") + health.of_kind("tooth_pit")
    if not faults:
        return 0.0
    require(design.gear is not None, "faults.kind", faults[0].kind, "needs a design with gears")
    teeth = {"ring_gear": design.gear.ring_teeth, "roller_gear": design.gear.roller_teeth}
    rows = {"ring_gear": L.ERR_RING_TOOTH, "roller_gear": L.ERR_ROLLER_TOOTH}
    damaged_rollers = {f.roller for f in faults if f.location == "roller_gear"}
    require(
        len(damaged_rollers) <= 1,
        "faults.roller",
        sorted(damaged_rollers),
        "gear tooth damage on one roller's gear at most per run",
    )
    for fault in faults:
        z, row = teeth[fault.location], rows[fault.location]
        require(fault.tooth < z, "faults.tooth", fault.tooth, f"must be below the gear's {z} teeth")
        mesh = damaged_mesh(design, fault, fault.location, threaded_tooth=options.threaded_tooth)
        phase = (np.arange(L.N_ERROR_POINTS) * z / L.N_ERROR_POINTS - fault.tooth) % z
        grid = np.arange(mesh.ratio.size) / (mesh.ratio.size / mesh.cycles)
        errors[row, 0] = 1.0 / z
        errors[row, 1:] += np.interp(phase, grid, mesh.ratio - 1.0, right=0.0)
        if fault.location == "roller_gear":
            require(
                fault.roller < design.n_rollers,
                "faults.roller",
                fault.roller,
                f"must be below the design's {design.n_rollers} rollers",
            )
            rollers[fault.roller, L.R_TOOTH] = 1.0
    return 1.0


def spall_profile(u: np.ndarray, spall, radius: float) -> np.ndarray:
    """Depression [m] of a spall along the contact coordinate u [rad] of its part: the contact
    follows it down over the first 30 % of its length, runs on its floor, and is lifted out by
    the exit edge over the last 10 % (Sawalhi & Randall 2008: gradual entry, abrupt exit)."""
    span = spall.length / radius
    x = np.mod(u - spall.angle, 2 * math.pi) / span  # 0…1 across the spall
    entry = np.clip(x / 0.3, 0.0, 1.0)
    exit_ = np.clip((1.0 - x) / 0.1, 0.0, 1.0)
    return spall.depth * np.where(x < 1.0, np.minimum(entry, exit_), 0.0)
