"""The ``prsm-health`` argument parser: every command, its options and their help.

Each command names its handler as ``"module:function"`` of this package (``handler``);
``main`` imports that module only when the command runs, so building the parser — and
``prsm-health --help`` — loads none of pandas, scipy, numba or scikit-learn. The few library
constants the parser would need from heavy modules are mirrored here (a test keeps each equal
to the library's).

Defaults appear in the help in one form, ``(default: X)``, written by
:class:`~.options.HelpFormatter`; an option whose default is None says what applies instead
with ``default_text``.
"""

from __future__ import annotations

import argparse
import re
from datetime import datetime

from prsm_health.actuator.design import DEFAULT_PRESET, PRESETS
from prsm_health.actuator.health_check import BUILT_IN as BUILT_IN_CHECKS
from prsm_health.actuator.states import DEFAULT_LOAD, DRIVES, LOADS, MOTIONS, RAMP_SHAPES
from prsm_health.core.errors import ParameterError
from prsm_health.core.identifiers import ASSET_ID_PATTERN, ASSET_ID_RULE
from prsm_health.core.quantities import parse_force
from prsm_health.core.version import __version__

from .options import (
    HelpFormatter,
    Parser,
    design,
    finite_float,
    port,
    positive_int,
    rate,
    removed_option,
    step,
)

#: ``prognose --method``'s choices (prognostics.METHODS, which imports pandas and scipy).
PROGNOSIS_METHODS = (
    "degradation",
    "similarity",
    "physics",
    "degradation-exponential",
    "degradation-linear",
)
#: The default instrumentation profile (prsm_health.simulation.instrumentation, which imports
#: scipy).
DEFAULT_PROFILE = "flight-ema"
#: ``--live`` defaults and message budget (prsm_health.apps.live, which imports foxglove).
LIVE_HOST, LIVE_PORT, LIVE_MESSAGE_BUDGET = "127.0.0.1", 8765, 20_000

#: ``train --target``: the diagnosis models' targets (prsm_health.training.train), and
#: ``rul``, a prognostics model of a fleet dataset.
TRAIN_TARGETS = ("clearance", "fault", "both", "rul")
#: ``train --cv`` when not given.
DEFAULT_CV = 5
#: The asset histories of ``diagnose --asset`` and ``asset`` when ``--store`` is not given.
DEFAULT_ASSET_STORE = "prsm-assets"

DESIGN_HELP = "preset name (paper01…paper05) or design TOML file"
PROFILE_HELP = (
    "instrumentation profile: a built-in name (prsm-health instrumentation list) or a TOML file"
)
SHIPPED_MODEL = "the shipped model"
MODEL_WINDOW = "the model's window"


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command; ``args.handler`` names the function that runs it."""
    parser = Parser(
        prog="prsm-health",
        description="Planetary roller screw physics, signal generation and diagnostics. "
        "SI units on the command line unless an option says otherwise.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"prsm-health {__version__}")
    command = _maker(parser, "command")
    _add_physics(command)
    _add_simulate(command)
    _add_data(command)
    _add_models(command)
    _add_assets(command)
    _add_prognose(command)
    _add_serve(command)
    return parser


def _maker(parser, dest: str):
    """A maker of ``parser``'s subcommands (``simulate``, ``design template`` …), each with
    the same parser class and help formatter."""
    sub = parser.add_subparsers(dest=dest, required=True, parser_class=Parser)

    def make(name: str, text: str):
        return sub.add_parser(name, help=text, description=text, formatter_class=HelpFormatter)

    return make


def _add_json(p, what: str = "the result") -> None:
    p.add_argument("--json", action="store_true", help=f"print {what} as JSON instead of a table")


# ----------------------------------------------------------------------------- physics
def _add_physics(command) -> None:
    p = command("validate", "compare the models with every number the papers print")
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="print the rows as JSON")
    fmt.add_argument("--markdown", action="store_true", help="print a Markdown table")
    p.set_defaults(handler="physics:validate")

    action = _maker(
        command("design", "design files: a template, a design's fields, a check"), "action"
    )
    t = action("template", "print a commented design TOML file to start from")
    t.add_argument(
        "--from",
        dest="preset",
        default=DEFAULT_PRESET,
        choices=sorted(PRESETS),
        help="preset to copy",
    )
    t.set_defaults(handler="physics:design_template")
    t = action("show", "print every field of a design with its unit")
    t.add_argument("design", help=DESIGN_HELP)
    _add_json(t, "the design's dict form")
    t.set_defaults(handler="physics:design_show")
    t = action("check", "validate a design file: 'ok: NAME', or one error line and exit 2")
    t.add_argument("file", help="design TOML file (or a preset name)")
    t.set_defaults(handler="physics:design_check")

    action = _maker(
        command("instrumentation", "instrumentation profiles: the sensors a run is measured with"),
        "action",
    )
    t = action("list", "the built-in profiles, one line each")
    _add_json(t, "the profiles (name, description, channels)")
    t.set_defaults(handler="physics:instrumentation_list")
    t = action("show", "every sensor of a profile with its parameters and units")
    t.add_argument("profile", help=PROFILE_HELP)
    _add_json(t, "the profile")
    t.set_defaults(handler="physics:instrumentation_show")

    p = command("kinematics", "speed ratios and characteristic frequencies of a design")
    p.add_argument("--design", type=design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    p.add_argument("--speed", type=finite_float, required=True, help="screw speed [rad/s]")
    _add_json(p)
    p.set_defaults(handler="physics:kinematics")

    model = _maker(
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
    _add_json(g)
    g.set_defaults(handler="physics:stiffness_gear")

    a = model("axial", "axial stiffness of the whole PRSM (papers 01, 04)")
    a.add_argument("--design", type=design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    a.add_argument("--load", type=finite_float, required=True, help="axial load [N]")
    _add_json(a)
    a.set_defaults(handler="physics:stiffness_axial")

    c = model("cylinder", "electric-cylinder deformation and stiffness (paper 05)")
    c.add_argument("--load", type=finite_float, required=True, help="axial load [N]")
    c.add_argument("--extension", type=finite_float, required=True, help="rod extension [m]")
    _add_json(c)
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
    _add_json(f)
    f.set_defaults(handler="physics:friction")


# ----------------------------------------------------------------------------- simulate
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


def _add_simulate(command) -> None:
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
    s.add_argument("--speed", type=finite_float, default=100.0, help="screw speed [rad/s]")
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
        "--contact-law", choices=("linear", "hertz"), default="linear", help="thread flank law"
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
    _add_json(s, "a summary")
    _add_live(s, rate_option=True)
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


def _add_live(p, *, rate_option: bool) -> None:
    """The ``--live`` options of ``replay`` and ``simulate`` (docs/live.md)."""
    p.add_argument(
        "--live",
        action="store_true",
        help="play the recording to Foxglove over its WebSocket protocol, with the diagnosis "
        "of each window (docs/live.md)",
    )
    p.add_argument(
        "--host",
        default=LIVE_HOST,
        help="--live: bind address (the protocol has no authentication: keep it local)",
    )
    p.add_argument(
        "--port", type=port, default=LIVE_PORT, help="--live: TCP port (0: any free port)"
    )
    if rate_option:
        p.add_argument("--rate", type=rate, default=1.0, help="--live: real-time factor, or 'max'")
    p.add_argument(
        "--live-decimate",
        type=positive_int,
        default=None,
        metavar="N",
        default_text=f"the smallest N that keeps all topics under {LIVE_MESSAGE_BUDGET} "
        "messages/s: 2 for a 20 kHz recording, 3 with truth",
        help="--live: publish every Nth sample",
    )


# ----------------------------------------------------------------------------- data
def _add_data(command) -> None:
    g = command("generate", "generate a labelled dataset from a recipe (resumable after Ctrl-C)")
    g.add_argument("recipe", help="TOML recipe (see datasets/ and docs/formats.md)")
    g.add_argument(
        "--out",
        required=True,
        help="dataset directory or object-store URL, e.g. s3://bucket/prefix (created; rerun to "
        "resume; credentials and endpoint from the environment, docs/formats.md)",
    )
    g.add_argument(
        "--workers",
        type=int,
        default=None,
        default_text="all cores",
        help="local worker processes",
    )
    g.add_argument(
        "--scheduler",
        default=None,
        default_text="$DASK_SCHEDULER_ADDRESS, else local processes",
        help="Dask scheduler address, e.g. tcp://host:8786",
    )
    g.add_argument(
        "--format", choices=("parquet", "mcap", "both"), default="parquet", help="signal files"
    )
    _add_json(g, "the generation report")
    g.set_defaults(handler="data:generate")

    i = command("import", "turn your rig's recordings and a labels table into a dataset")
    i.add_argument("recordings", nargs="+", help="recordings: .csv, .parquet or .mcap files")
    i.add_argument(
        "--labels",
        required=True,
        help="CSV: a 'recording' column (file names) and label columns (fault_class, clearance [m], …)",
    )
    i.add_argument(
        "--map",
        required=True,
        help="TOML: [columns] channel → file column, [units] column → unit, sample_rate, design",
    )
    i.add_argument("--out", required=True, help="dataset directory to create")
    i.add_argument(
        "--test-fraction",
        type=finite_float,
        default=0.25,
        help="held-out share when the labels have no split column",
    )
    i.add_argument("--seed", type=int, default=0, help="seed of that split")
    i.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    _add_json(i, "the summary")
    i.set_defaults(handler="data:import_recordings")


# ----------------------------------------------------------------------------- models
def _add_models(command) -> None:
    t = command(
        "train",
        "train the clearance estimator and fault classifier on a dataset, or a prognostics "
        "model on a fleet dataset (--target rul)",
    )
    t.add_argument("dataset", help="dataset directory or URL (prsm-health generate)")
    t.add_argument(
        "--out",
        required=True,
        help="model file: .skops (metrics JSON beside it), or .json for --target rul",
    )
    t.add_argument(
        "--target",
        choices=TRAIN_TARGETS,
        default="both",
        help="what to train: the clearance estimator, the fault classifier, both, or the "
        "remaining-useful-life model of a fleet dataset (a [life] recipe's)",
    )
    t.add_argument(
        "--cv",
        type=int,
        default=None,
        default_text=str(DEFAULT_CV),
        help="cross-validation folds on the train split (not with --target rul)",
    )
    t.add_argument(
        "--model",
        default=None,
        metavar="BUNDLE",
        default_text=SHIPPED_MODEL,
        help="--target rul: the diagnosis model (.skops) that reads the fleet's snapshots into "
        "histories; it must be of the fleet's design",
    )
    t.add_argument(
        "--threshold",
        type=finite_float,
        default=None,
        metavar="M",
        default_text="learnt from the training units",
        help="--target rul: failure threshold on the diagnosed clearance [m]",
    )
    _add_json(t, "the metrics")
    t.set_defaults(handler="models:train")

    e = command(
        "evaluate", "score a model on a dataset (generated or imported) through the diagnosis"
    )
    e.add_argument("model", help="model bundle (.skops)")
    e.add_argument("dataset", help="dataset directory or URL")
    e.add_argument(
        "--split", choices=("test", "train", "all"), default="test", help="which runs to score"
    )
    e.add_argument(
        "--plot",
        default=None,
        metavar="DIR",
        default_text="no figures",
        help="write clearance.png, calibration.png and confusion.png into DIR",
    )
    _add_json(e, "the metrics")
    e.set_defaults(handler="models:evaluate")

    d = command("diagnose", "diagnose a recording: clearance with interval, fault class")
    d.add_argument("file", help="recording: .mcap, .parquet (one run) or .csv (docs/formats.md)")
    d.add_argument(
        "--map",
        default=None,
        metavar="MAP.toml",
        default_text="contract column names",
        help="column map of a rig's CSV or Parquet file: columns, units, sample rate, design "
        "(docs/import.md; the same map import reads)",
    )
    d.add_argument("--model", default=None, default_text=SHIPPED_MODEL, help="model bundle")
    d.add_argument(
        "--window",
        type=finite_float,
        default=None,
        default_text=MODEL_WINDOW,
        help="window length [s]",
    )
    d.add_argument(
        "--plot",
        default=None,
        default_text="no plot",
        help="write a PNG of the per-window estimates",
    )
    d.add_argument(
        "--asset",
        type=asset_id,
        default=None,
        metavar="ID",
        default_text="no asset",
        help="the unit the recording belongs to: read it against the unit's own baseline, add "
        "it to the unit's evidence and save its history in --store (docs/diagnostics.md); the "
        "same recording again is counted once",
    )
    _add_store(d)
    label = d.add_mutually_exclusive_group()
    label.add_argument(
        "--healthy",
        action="store_true",
        help="--asset: the recording is known healthy: put it in the unit's baseline",
    )
    label.add_argument(
        "--unhealthy",
        action="store_true",
        help="--asset: the recording is known not healthy: keep it out of the unit's baseline",
    )
    d.add_argument(
        "--operating-hours",
        type=non_negative_float,
        default=None,
        metavar="H",
        default_text="not recorded",
        help="--asset: the unit's operating hours at the recording [h]",
    )
    d.add_argument(
        "--time",
        type=iso_time,
        default=None,
        metavar="ISO",
        default_text="the file's modification time",
        help="--asset: when the recording was made (ISO 8601)",
    )
    _add_json(d, "the Diagnosis contract")
    d.set_defaults(handler="models:diagnose")

    r = command("replay", "stream an MCAP recording window by window through the diagnosis")
    r.add_argument("file", help="MCAP recording")
    r.add_argument(
        "--window",
        type=finite_float,
        default=None,
        default_text=MODEL_WINDOW,
        help="window length [s]",
    )
    # SUPPRESS: the default depends on --live (models.replay reads it with getattr)
    r.add_argument(
        "--rate",
        type=rate,
        default=argparse.SUPPRESS,
        default_text="max; with --live: 1, real time",
        help="real-time factor, or 'max'",
    )
    r.add_argument("--model", default=None, default_text=SHIPPED_MODEL, help="model bundle")
    r.add_argument(
        "--out",
        default=None,
        default_text="no copy",
        help="write a copy of the recording with /prsm/diagnosis messages",
    )
    r.add_argument(
        "--statistics-only", action="store_true", help="window statistics only, no model"
    )
    _add_json(r, "every window")
    _add_live(r, rate_option=False)
    r.set_defaults(handler="models:replay")


# ----------------------------------------------------------------------------- assets
def asset_id(text: str) -> str:
    """``--asset`` and ``asset show``'s ID: safe as a file name and a URL segment."""
    if re.fullmatch(ASSET_ID_PATTERN, text) is None:
        raise argparse.ArgumentTypeError(f"{text!r}: an asset id is {ASSET_ID_RULE}")
    return text


def iso_time(text: str) -> str:
    """``--time``: an ISO 8601 date or time, kept as written."""
    try:
        datetime.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not an ISO 8601 date or time (e.g. 2024-05-01T10:30:00+00:00)"
        ) from None
    return text


def non_negative_float(text: str) -> float:
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: use a number >= 0")
    return value


def _add_store(p) -> None:
    p.add_argument(
        "--store",
        default=DEFAULT_ASSET_STORE,
        default_text=f"./{DEFAULT_ASSET_STORE}, in the current directory",
        metavar="DIR",
        help="directory of the asset histories, one JSON file per asset (created)",
    )


def _add_assets(command) -> None:
    action = _maker(
        command("asset", "units recorded with diagnose --asset: baseline, evidence, changes"),
        "action",
    )
    s = action("show", "an asset's baseline, evidence and change statistic over its recordings")
    s.add_argument("asset", type=asset_id, metavar="ID", help="the asset id")
    _add_store(s)
    s.add_argument(
        "--model",
        default=None,
        default_text="none: each indicator's scale from the unit's recordings alone",
        help="model bundle whose baseline indicators and within-unit repeatability the "
        "baseline's scales use, as diagnose --asset uses them (--json shows the scales)",
    )
    _add_json(s, "the asset's history report")
    s.set_defaults(handler="assets:show")
    s = action("list", "the assets in the store")
    _add_store(s)
    _add_json(s, "the asset ids")
    s.set_defaults(handler="assets:list_assets")


# ----------------------------------------------------------------------------- prognose
def _add_prognose(command) -> None:
    g = command(
        "prognose",
        "remaining useful life from a history of diagnoses, or of a fleet dataset's unit",
    )
    g.add_argument(
        "source",
        metavar="HISTORY_OR_DATASET",
        help="history table (.csv or .parquet: age_hours, clearance, clearance_lower, "
        "clearance_upper [h, m]; optional design, fault_class, unit_id), or a fleet dataset "
        "directory or URL (prsm-health generate on a recipe with [life]) with --unit",
    )
    g.add_argument(
        "--unit",
        type=int,
        default=None,
        metavar="ID",
        default_text="none",
        help="fleet dataset: the unit's unit_id, required with a fleet dataset",
    )
    g.add_argument(
        "--until-age",
        type=finite_float,
        default=None,
        metavar="H",
        default_text="every snapshot",
        help="fleet dataset: only the snapshots at ages <= H [h] (what was known then)",
    )
    g.add_argument(
        "--model",
        default=None,
        default_text="the shipped models/prognostics.json",
        help="prognostics model JSON",
    )
    g.add_argument(
        "--diagnosis-model",
        default=None,
        metavar="D",
        default_text=SHIPPED_MODEL,
        help="fleet dataset: model bundle that diagnoses the snapshots",
    )
    g.add_argument(
        "--method",
        choices=PROGNOSIS_METHODS,
        default=None,
        default_text="the model's default method",
        help="degradation (the form chosen at fit time), similarity, physics (the ageing model "
        "and a particle filter, models fitted on a fleet dataset), or a forced degradation form",
    )
    _add_json(g, "the prognosis")
    g.set_defaults(handler="prognose:prognose")


# ----------------------------------------------------------------------------- serve
def _add_serve(command) -> None:
    v = command("serve", "HTTP diagnostics service with asset health history (docs/service.md)")
    v.add_argument("--host", default="127.0.0.1", help="bind address (non-loopback needs a token)")
    v.add_argument("--port", type=int, default=8000, help="TCP port")
    v.add_argument("--model", default=None, default_text=SHIPPED_MODEL, help="model bundle")
    v.add_argument(
        "--prognostics-model",
        default=None,
        metavar="FILE",
        default_text="the shipped models/prognostics.json if present, else that endpoint "
        "answers 503",
        help="prognostics model for GET /v1/assets/{id}/prognosis",
    )
    v.add_argument(
        "--db",
        default=None,
        default_text="$PRSM_HEALTH_DB, else $XDG_DATA_HOME (~/.local/share)/prsm-health/"
        "history.sqlite",
        help="SQLite history database (docs/service.md)",
    )
    v.add_argument("--token", default=None, default_text="$PRSM_HEALTH_TOKEN", help="bearer token")
    v.add_argument(
        "--workers",
        type=int,
        default=None,
        default_text="half the cores, at least 1",
        help="diagnoses computed at once",
    )
    v.add_argument(
        "--processes",
        type=int,
        default=None,
        default_text="0",
        help="diagnosis processes, each with the model loaded once, or 0: threads",
    )
    v.add_argument(
        "--max-window", type=finite_float, default=2.0, help="longest JSON recording [s]"
    )
    v.add_argument(
        "--log-level",
        default="info",
        choices=("critical", "error", "warning", "info", "debug"),
        help="server log level",
    )
    v.set_defaults(handler="serve:serve")
