"""Commands on the models of the mechanism: ``validate``, ``design``, ``instrumentation``,
``kinematics``, ``stiffness``, ``friction``."""

from __future__ import annotations

import math
import textwrap

from prsm_health.actuator.design import VARIANT_PRESETS, preset
from prsm_health.actuator.design_files import design_rows, design_to_toml, load_design
from prsm_health.core.errors import PRSMHealthError
from prsm_health.physics.friction import FrictionParameters, simulate_friction
from prsm_health.physics.kinematics import (
    characteristic_frequencies,
    defect_frequencies,
    speed_ratios,
)
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.recirculating import RecirculatingGeometry, with_explicit_geometry
from prsm_health.physics.stiffness.axial import axial_stiffness
from prsm_health.physics.stiffness.cylinder import ElectricCylinder, cylinder_deformation
from prsm_health.physics.stiffness.gear_mesh import mesh_stiffness
from prsm_health.simulation.instrumentation import list_profiles, load_instrumentation
from prsm_health.validation import _fmt, collect, summary, to_markdown

from .output import print_json, print_table


# ----------------------------------------------------------------------------- validate
def validate(args) -> int:
    rows = collect()
    counts = summary(rows)
    failed = [r for r in rows if r.failed]
    if args.json:
        print_json({"rows": [r.as_dict() for r in rows], "summary": counts})
    elif args.markdown:
        print(to_markdown(rows))
    else:
        _print_validation_text(rows)
        print()
        print("summary: " + ", ".join(f"{n} {v}" for v, n in counts.items()))
    return 1 if failed else 0


def _print_validation_text(rows, width: int = 100) -> None:
    """Each row in at most a few lines of ``width`` columns: where and what, the numbers and the
    verdict, then the note wrapped."""
    indent = " " * 4
    for r in rows:
        err = "–" if r.error is None else f"{100 * r.error:+.2f} %"
        head = f"{r.paper} {r.where}: {r.quantity} [{r.unit}]"
        print(textwrap.fill(head, width, subsequent_indent=indent))
        print(
            f"{indent}paper {_fmt(r.paper_value)}  model {_fmt(r.model_value)}  "
            f"error {err}  → {r.verdict}"
        )
        if r.note:
            print(textwrap.fill(r.note, width, initial_indent=indent, subsequent_indent=indent))
        print()


# ----------------------------------------------------------------------------- design
def design_template(args) -> int:
    start = VARIANT_PRESETS[args.variant or "standard"]
    name = args.preset or start
    design = preset(name)
    if args.variant is not None and design.variant != args.variant:
        raise PRSMHealthError(
            f"--from {name} is a {design.variant} design, not {args.variant}: leave --from out "
            f"(the {args.variant} template starts from {start})"
        )
    if design.variant == "recirculating":
        design = with_explicit_geometry(design)
    print(
        f"# PRSM design file, from preset {name}: edit the values (SI units: m, kg, kg·m²,\n"
        "# Pa, rad), rename it, then `prsm-health design check FILE` and use it with\n"
        "# --design FILE. Optional fields left out take their defaults (docs/formats.md)."
    )
    if design.variant == "recirculating":
        print(
            "# [recirculation]: paper 03's carrier and cam ring, each value the rule's for these\n"
            "# threads; a field left out follows the rule again."
        )
    print()
    print(design_to_toml(design), end="")
    return 0


def design_show(args) -> int:
    design = load_design(args.design)
    if args.json:
        print_json(design.to_dict())
    else:
        ratings = load_ratings(design)
        print_table(
            [_in_degrees(row) for row in design_rows(design)]
            + [
                ("lead (screw and nut, starts × pitch)", design.screw_lead, "m"),
                ("lead angle λ_s (screw)", math.degrees(design.screw_lead_angle), "°"),
                ("lead angle λ_n (nut)", math.degrees(design.nut_lead_angle), "°"),
                ("lead angle λ_r (roller)", math.degrees(design.roller_lead_angle), "°"),
                ("load rating C_a (dynamic, 1e6 rev, 90 %)", ratings.dynamic / 1e3, "kN"),
                ("load rating C_0a (static, 4.2 GPa)", ratings.static / 1e3, "kN"),
            ]
        )
    return 0


def _in_degrees(row: tuple[str, object, str]) -> tuple[str, object, str]:
    """An angle row of the design table in degrees, with the radians the file holds."""
    name, value, unit = row
    if unit != "rad" or not isinstance(value, float):
        return row
    return name, math.degrees(value), f"° ({value:.6g} rad in the file)"


def design_check(args) -> int:
    design = load_design(args.file)
    if design.variant == "recirculating":  # its carrier and cam ring against paper 03
        RecirculatingGeometry.for_design(design)
    print(f"ok: {design.name}")
    return 0


# ----------------------------------------------------------------------------- instrumentation
def instrumentation_list(args) -> int:
    profiles = [load_instrumentation(name) for name in list_profiles()]
    if args.json:
        print_json(
            [
                {"name": p.name, "description": p.description, "channels": list(p.fitted)}
                for p in profiles
            ]
        )
    else:
        print_table([(p.name, p.description, "") for p in profiles])
    return 0


def instrumentation_show(args) -> int:
    info = load_instrumentation(args.profile).describe()
    if args.json:
        print_json(info)
        return 0
    rows = [
        ("name", info["name"], ""),
        ("description", info["description"], ""),
        ("sample_rate", info["sample_rate"], "Hz"),
    ]
    for channel, sensor in info["sensors"].items():
        rows.append((channel, f"{sensor['kind']}, reads {sensor['reads']}", ""))
        rows += [(f"  {p['name']}", _listed(p["value"]), p["unit"]) for p in sensor["parameters"]]
    print_table(rows)
    return 0


def _listed(value):
    """A parameter for the table: lists comma-separated, floats to 6 significant digits."""
    if isinstance(value, list):
        return "[" + ", ".join(f"{v:.6g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return value


# ----------------------------------------------------------------------------- kinematics
def kinematics(args) -> int:
    design = args.design
    ratios = speed_ratios(design)
    freqs = characteristic_frequencies(design, args.speed)
    out = {
        "design": design.name,
        "variant": design.variant,
        "screw_speed": args.speed,
        "ratios": {
            "carrier": ratios.carrier,
            "roller_spin": ratios.roller_spin,
            "roller_spin_relative": ratios.roller_spin_relative,
        },
        "effective_lead": ratios.effective_lead,
        "nut_speed": ratios.nut * args.speed,
        "frequencies": freqs.as_dict(),
        "defect_frequencies": defect_frequencies(design, args.speed),
    }
    ratings = load_ratings(design)
    out["load_ratings"] = {"dynamic": ratings.dynamic, "static": ratings.static}
    if args.json:
        print_json(out)
        return 0
    rows = [
        ("design", f"{design.name} ({design.variant})", ""),
        ("carrier / screw speed", ratios.carrier, ""),
        ("roller spin / screw speed", ratios.roller_spin, ""),
        ("effective lead", ratios.effective_lead, "m"),
        ("nut speed", out["nut_speed"], "m/s"),
    ]
    rows += [(f"f_{k}", v if v is not None else "–", "Hz") for k, v in out["frequencies"].items()]
    rows += [(f"defect {k}", v, "Hz") for k, v in out["defect_frequencies"].items()]
    print_table(rows)
    return 0


# ----------------------------------------------------------------------------- stiffness
def stiffness_gear(args) -> int:
    result = mesh_stiffness(
        args.z1,
        args.z2,
        args.module,
        math.radians(args.pressure_angle),
        args.face_width,
        internal=args.internal,
        bore_diameter=args.bore_diameter,
        youngs_modulus=args.youngs_modulus,
        poisson_ratio=args.poisson,
        threaded_tooth=args.threaded_tooth,
    )
    out = {
        "contact_ratio": float(result.contact_ratio),
        "k_min": float(result.k_min),
        "k_max": float(result.k_max),
        "k_mean": float(result.k_mean),
    }
    if args.json:
        print_json(out)
    else:
        print_table(
            [
                ("contact ratio", out["contact_ratio"], ""),
                ("k_min", out["k_min"], "N/m"),
                ("k_max", out["k_max"], "N/m"),
                ("k_mean", out["k_mean"], "N/m"),
            ]
        )
    return 0


def stiffness_axial(args) -> int:
    design = args.design
    result = axial_stiffness(design, args.load)
    out = {
        "design": design.name,
        "load": args.load,
        "deformation": float(result.deformation),
        "secant_stiffness": float(result.secant_stiffness),
        "tangent_stiffness": float(result.tangent_stiffness),
    }
    if args.json:
        print_json(out)
    else:
        print_table(
            [
                ("design", design.name, ""),
                ("axial load", args.load, "N"),
                ("deformation", out["deformation"], "m"),
                ("secant stiffness F/δ", out["secant_stiffness"], "N/m"),
                ("tangent stiffness dF/dδ", out["tangent_stiffness"], "N/m"),
            ]
        )
    return 0


def stiffness_cylinder(args) -> int:
    result = cylinder_deformation(ElectricCylinder.paper05(), args.load, args.extension)
    components = {k: float(v) for k, v in result.components.items()}
    out = {
        "load": args.load,
        "extension": args.extension,
        "components": components,
        "total": float(result.total),
        "stiffness": float(result.stiffness),
    }
    if args.json:
        print_json(out)
    else:
        rows = [(f"Δl {name}", value, "m") for name, value in components.items()]
        rows += [("Δl total", out["total"], "m"), ("stiffness F/Δl", out["stiffness"], "N/m")]
        print_table(rows)
    return 0


# ----------------------------------------------------------------------------- friction
def friction(args) -> int:
    if args.design:
        params = FrictionParameters.from_design(args.design, friction_scale=args.friction_scale)
    else:
        params = FrictionParameters(friction_scale=args.friction_scale)
    result = simulate_friction(params, args.load, args.speed, args.accel_time, args.duration)
    out = {
        "source": args.design.name if args.design else "paper02 table",
        "load": args.load,
        "speed": args.speed,
        "accel_time": args.accel_time,
    }
    out.update(result.summary())
    if args.json:
        print_json(out)
    else:
        print_table(
            [
                ("parameters", out["source"], ""),
                ("peak friction torque", result.peak_friction_torque, "N·m"),
                ("steady friction torque", result.steady_friction_torque, "N·m"),
                ("minimum efficiency", result.min_efficiency, ""),
                ("overall efficiency", result.overall_efficiency, ""),
                ("steady efficiency", result.steady_efficiency, ""),
            ]
        )
    return 0
