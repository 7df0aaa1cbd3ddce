"""The options of ``simulate`` (:mod:`.simulate`)."""

from __future__ import annotations

import argparse

from prsm_health.actuator.design import DEFAULT_PRESET
from prsm_health.actuator.health_check import BUILT_IN as BUILT_IN_CHECKS
from prsm_health.actuator.states import (
    DEFAULT_LOAD,
    DEFAULT_SPEED,
    DRIVES,
    LOADS,
    MOTIONS,
    RAMP_SHAPES,
)
from prsm_health.core.errors import ParameterError
from prsm_health.core.quantities import parse_force

from .live_options import add_live_options
from .options import (
    DESIGN_HELP,
    MODEL_WINDOW,
    PROFILE_HELP,
    SHIPPED_MODEL,
    add_json,
    design,
    finite_float,
    removed_option,
    step,
)

#: The default instrumentation profile (prsm_health.simulation.instrumentation, which imports
#: scipy).
DEFAULT_PROFILE = "flight-ema"
#: How a load may be written on the command line (prsm_health.core.quantities).
FORCE_FORMS = (
    "newtons, a unit ('4.4kN') or a share of the design's rating ('20 %% C_a', '5 %% C_0a')"
)


def force(text: str):
    """``--load``: any form of :mod:`prsm_health.core.quantities` (resolved by the scenario
    against the design's ratings); a bad unit or rating is one line naming the forms."""
    try:
        return parse_force(text, "--load")
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc.allowed}") from None


def force_swing(text: str):
    """``--load-amplitude``: as :func:`force`, and not negative."""
    spec = force(text)
    if spec.value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: a swing must be ≥ 0")
    return spec


def add_simulate_command(command) -> None:
    s = command("simulate", "simulate a PRSM run (paper 01 dynamics) and write it")
    s.add_argument("--design", type=design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    s.add_argument(
        "--health",
        default=None,
        metavar="FILE",
        default_text="no file",
        help="health file (TOML: clearances, preload, lubricant and [[faults]], docs/faults.md); "
        "each health flag below replaces what the file says of the same parameters",
    )
    # The health flags: None where not given, so that only what the user typed is laid over
    # the health file (simulate.health_state); the defaults shown are HealthState's.
    s.add_argument(
        "--clearance",
        type=finite_float,
        default=None,
        default_text="the health file's, else 1e-05",
        help="thread half-clearance b on screw and nut, and the gear backlash unless "
        "--gear-clearance [m]",
    )
    s.add_argument(
        "--gear-clearance",
        type=finite_float,
        default=None,
        default_text="the health file's, else the thread clearance",
        help="gear backlash b_g [m]",
    )
    s.add_argument(
        "--wear-spread",
        type=finite_float,
        default=None,
        default_text="the health file's, else 0",
        help="uneven roller wear [-]",
    )
    s.add_argument(
        "--preload",
        type=finite_float,
        default=None,
        default_text="the health file's, else 0",
        help="installed axial interference on each thread flank [m] (preloaded nut; 0: none)",
    )
    s.add_argument(
        "--friction-scale",
        type=finite_float,
        default=None,
        default_text="the health file's, else 1",
        help="friction multiplier [-]",
    )
    s.add_argument("--speed", type=finite_float, default=DEFAULT_SPEED, help="screw speed [rad/s]")
    s.add_argument(
        "--load",
        type=force,
        default=DEFAULT_LOAD,
        default_text=DEFAULT_LOAD.text(),
        help=f"mean resisting axial load: {FORCE_FORMS} (docs/load-ratings.md)",
    )
    s.add_argument(
        "--profile",
        choices=(*MOTIONS, *BUILT_IN_CHECKS),
        default="constant",
        help="screw motion profile, or a built-in health check (the phases set motion, speed, "
        "load and duration: docs/formats.md)",
    )
    s.add_argument(
        "--check",
        default=None,
        metavar="FILE",
        default_text="none",
        help="a health check of your own: TOML with [check] name and [[check.phases]] "
        "(motion, speed, load, duration, ramp_time, reversal_shape, reversal_period)",
    )
    s.add_argument(
        "--accel-time", type=finite_float, default=0.02, help="speed ramp and load edge [s]"
    )
    s.add_argument("--period", type=finite_float, default=0.1, help="reversing motion period [s]")
    s.add_argument("--load-profile", choices=LOADS, default="constant", help="axial load profile")
    s.add_argument(
        "--load-ramp-time",
        type=finite_float,
        default=None,
        default_text="--accel-time",
        help="duration of each reversal of the reversing load [s]",
    )
    s.add_argument(
        "--load-ramp-shape",
        choices=RAMP_SHAPES,
        default="linear",
        help="reversals of the reversing load: straight ramp or raised cosine",
    )
    s.add_argument(
        "--drive",
        choices=DRIVES,
        default="prescribed",
        help="ideal servo (prescribed motor angle), PI speed loop, or position loop on it",
    )
    s.add_argument(
        "--drive-train",
        default="actuator",
        metavar="NAME_OR_FILE",
        help="motor, coupling, thrust bearing, linkage and payload: 'actuator' (a flight EMA), "
        "'paper01' (rigid screw drive, ideal force on the nut) or a TOML file of DriveTrain "
        "fields (docs/formats.md)",
    )
    s.add_argument(
        "--load-amplitude",
        type=force_swing,
        default=0.0,
        help=f"load swing around --load: {FORCE_FORMS}",
    )
    s.add_argument(
        "--load-frequency", type=finite_float, default=20.0, help="load swing frequency [Hz]"
    )
    s.add_argument("--duration", type=finite_float, default=0.2, help="simulated time [s]")
    s.add_argument(
        "--instrumentation", default=DEFAULT_PROFILE, metavar="PROFILE", help=PROFILE_HELP
    )
    s.add_argument(
        "--sample-rate",
        type=finite_float,
        default=None,
        default_text="the profile's, 20 kHz for the built-ins",
        help="output rate [Hz]",
    )
    s.add_argument(
        "--accel-noise",
        type=removed_option(
            "accelerometer noise comes from the instrumentation profile (--instrumentation); "
            'set it in a profile file: profile = "flight-ema" and '
            "[nut_axial_accel] noise_density_ug = … (docs/instrumentation.md)"
        ),
        help=argparse.SUPPRESS,
    )
    s.add_argument(
        "--contact-law",
        choices=("linear", "hertz"),
        default="hertz",  # every shipped recipe's: a recording at defaults is like their runs
        help="thread flank law: hertz as the recipes and shipped models, linear as paper 01",
    )
    s.add_argument(
        "--max-step",
        type=step,
        default="auto",
        help='largest RK4 step [s], or "auto": 0.6 of the stable step, at most 10 µs',
    )
    s.add_argument("--ideal", action="store_true", help="no manufacturing variation")
    s.add_argument("--seed", type=int, default=0, help="seed of variation, wear and noise")
    s.add_argument(
        "--out",
        default=None,
        default_text="no file",
        help="output file (.parquet or .mcap), required unless --live",
    )
    s.add_argument(
        "--plot",
        default=None,
        default_text="no plot",
        help="write a PNG with time traces and spectra",
    )
    add_json(s, "a summary")
    add_live_options(s, rate_option=True)
    s.add_argument("--model", default=None, default_text=SHIPPED_MODEL, help="--live: model bundle")
    s.add_argument(
        "--window",
        type=finite_float,
        default=None,
        default_text=MODEL_WINDOW,
        help="--live: window length [s]",
    )
    s.add_argument("--no-diagnosis", action="store_true", help="--live: publish the signals only")
    s.set_defaults(handler="simulate:simulate")
