"""The options of the physics commands (:mod:`.physics`): validate, design, instrumentation,
kinematics, stiffness, friction."""

from __future__ import annotations

from prsm_health.actuator.design import DEFAULT_PRESET, PRESETS, VARIANT_PRESETS
from prsm_health.actuator.states import DEFAULT_SPEED

from .options import (
    DESIGN_HELP,
    PROFILE_HELP,
    add_json,
    command_maker,
    design,
    finite_float,
)


def add_physics_commands(command) -> None:
    p = command("validate", "compare the models with every number the papers print")
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="print the rows as JSON")
    fmt.add_argument("--markdown", action="store_true", help="print a Markdown table")
    p.set_defaults(handler="physics:validate")

    action = command_maker(
        command("design", "design files: a template, a design's fields, a check"), "action"
    )
    t = action("template", "print a commented design TOML file to start from")
    t.add_argument(
        "--from",
        dest="preset",
        default=None,
        default_text=f"{VARIANT_PRESETS['standard']}; {VARIANT_PRESETS['recirculating']} with "
        "--variant recirculating",
        choices=sorted(PRESETS),
        help="preset to copy",
    )
    t.add_argument(
        "--variant",
        choices=("standard", "recirculating"),
        default=None,
        default_text="the preset's",
        help="recirculating: a paper-03 design with its cam-ring geometry written out",
    )
    t.set_defaults(handler="physics:design_template")
    t = action("show", "print every field of a design with its unit")
    t.add_argument("design", help=DESIGN_HELP)
    add_json(t, "the design's dict form")
    t.set_defaults(handler="physics:design_show")
    t = action("check", "validate a design file: 'ok: NAME', or one error line and exit 2")
    t.add_argument("file", help="design TOML file (or a preset name)")
    t.set_defaults(handler="physics:design_check")

    action = command_maker(
        command("instrumentation", "instrumentation profiles: the sensors a run is measured with"),
        "action",
    )
    t = action("list", "the built-in profiles, one line each")
    add_json(t, "the profiles (name, description, channels)")
    t.set_defaults(handler="physics:instrumentation_list")
    t = action("show", "every sensor of a profile with its parameters and units")
    t.add_argument("profile", help=PROFILE_HELP)
    add_json(t, "the profile")
    t.set_defaults(handler="physics:instrumentation_show")

    p = command("kinematics", "speed ratios and characteristic frequencies of a design")
    p.add_argument("--design", type=design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    p.add_argument(
        "--speed",
        type=finite_float,
        default=DEFAULT_SPEED,
        help="screw speed [rad/s] (as simulate)",
    )
    add_json(p)
    p.set_defaults(handler="physics:kinematics")

    model = command_maker(
        command("stiffness", "static stiffness models: gear mesh, axial, electric cylinder"),
        "model",
    )
    g = model("gear", "time-varying gear mesh stiffness (potential energy method, paper 01)")
    g.add_argument("--z1", type=int, required=True, help="pinion (roller gear) teeth")
    g.add_argument("--z2", type=int, required=True, help="gear (ring gear) teeth")
    g.add_argument("--module", type=finite_float, required=True, help="module [m]")
    g.add_argument("--pressure-angle", type=finite_float, default=20.0, metavar="DEG", help="[deg]")
    g.add_argument("--face-width", type=finite_float, required=True, help="face width [m]")
    g.add_argument("--bore-diameter", type=finite_float, default=0.0, help="pinion bore [m]")
    g.add_argument("--internal", action="store_true", help="z2 is an internal ring gear")
    g.add_argument("--youngs-modulus", type=finite_float, default=2.1e11, metavar="PA", help="[Pa]")
    g.add_argument("--poisson", type=finite_float, default=0.3, metavar="V", help="[-]")
    g.add_argument("--threaded-tooth", action="store_true", help="PRSM threaded roller tooth")
    add_json(g)
    g.set_defaults(handler="physics:stiffness_gear")

    a = model("axial", "axial stiffness of the whole PRSM (papers 01, 04)")
    a.add_argument("--design", type=design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    a.add_argument("--load", type=finite_float, required=True, help="axial load [N]")
    add_json(a)
    a.set_defaults(handler="physics:stiffness_axial")

    c = model("cylinder", "electric-cylinder deformation and stiffness (paper 05)")
    c.add_argument("--load", type=finite_float, required=True, help="axial load [N]")
    c.add_argument("--extension", type=finite_float, required=True, help="rod extension [m]")
    add_json(c)
    c.set_defaults(handler="physics:stiffness_cylinder")

    f = command("friction", "friction torque and efficiency at start-up (paper 02)")
    f.add_argument("--load", type=finite_float, required=True, help="output axial force [N]")
    f.add_argument("--speed", type=finite_float, default=1.0, help="final screw speed [rad/s]")
    f.add_argument("--accel-time", type=finite_float, default=0.02, help="ramp time [s]")
    f.add_argument(
        "--duration",
        type=finite_float,
        default=None,
        default_text="--accel-time + 0.1 s",
        help="simulated time [s]",
    )
    f.add_argument("--friction-scale", type=finite_float, default=1.0, help="lubricant state [-]")
    f.add_argument(
        "--design",
        type=design,
        default=None,
        default_text="paper 02's friction table",
        help=DESIGN_HELP,
    )
    add_json(f)
    f.set_defaults(handler="physics:friction")
