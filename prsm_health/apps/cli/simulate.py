"""``prsm-health simulate``: the command line → a :class:`Scenario` → one run, written and
summarised (or played live to Foxglove)."""

from __future__ import annotations

from pathlib import Path

from prsm_health.actuator.drive_train import load_drive_train
from prsm_health.actuator.health_check import BUILT_IN as BUILT_IN_CHECKS
from prsm_health.actuator.states import HealthState
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.tomlfile import read_toml
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.io.mcap import write_mcap
from prsm_health.io.parquet import write_run_parquet
from prsm_health.physics.kinematics import characteristic_frequencies
from prsm_health.simulation.scenario import Scenario

from ..plots import plot_check, plot_run
from .live import play_live
from .output import print_json, print_table

#: The health flags and the health-table keys they give (``HealthState.from_dict``'s names;
#: ``clearance`` is its shorthand for the screw, nut and gear clearances).
HEALTH_FLAGS = {
    "clearance": "clearance",
    "gear_clearance": "clearance_gear",
    "wear_spread": "wear_spread",
    "friction_scale": "friction_scale",
    "preload": "preload",
}


def health_state(args) -> HealthState:
    """The run's health state: the health file's (``--health``), with the health flags the
    user gave laid over it.

    The flags form a health table of their own, read by the same rules as a health file and
    laid over it by :meth:`HealthState.from_dict` (``base=`` the file's table), so the command
    line and a file cannot disagree: ``--clearance X`` is ``clearance = X``, the screw, nut and
    gear clearances unless ``--gear-clearance`` gives the gear's. A flag replaces what the file
    says of the same parameters — ``--clearance`` every clearance of the file.
    """
    table = read_toml(args.health, "health file") if args.health else {}
    flags = {key: getattr(args, flag) for flag, key in HEALTH_FLAGS.items()}
    flags = {key: value for key, value in flags.items() if value is not None}
    return HealthState.from_dict(flags, "health", base=table)


def _check(args) -> str | None:
    """The health check asked for: ``--check FILE`` or ``--profile <built-in check>``."""
    built_in = args.profile if args.profile in BUILT_IN_CHECKS else None
    if args.check is not None and built_in is not None:
        raise PRSMHealthError(f"give --check or --profile {built_in}, not both")
    if args.check is not None and args.profile != "constant":
        raise PRSMHealthError(f"--check sets the motion: drop --profile {args.profile}")
    return args.check if args.check is not None else built_in


def scenario_from_args(args) -> Scenario:
    """The :class:`Scenario` the command line describes (validated; nothing simulated)."""
    check = _check(args)
    # a check brings its motion, load and duration; the profile's other fields stay as given
    with_check = {} if check is None else {"check": check}
    return Scenario.from_dict(
        {
            "design": args.design,
            "health": health_state(args),
            "profile": with_check
            | {
                "duration": args.duration,
                "motion": "constant" if check is not None else args.profile,
                "speed": args.speed,
                "accel_time": args.accel_time,
                "motion_period": args.period,
                "load_profile": args.load_profile,
                "load": args.load,
                "load_amplitude": args.load_amplitude,
                "load_frequency": args.load_frequency,
                "load_ramp_time": args.load_ramp_time,
                "load_ramp_shape": args.load_ramp_shape,
                "drive": args.drive,
            },
            "drive_train": load_drive_train(args.drive_train),
            "instrumentation": {"profile": args.instrumentation}
            | ({} if args.sample_rate is None else {"sample_rate": args.sample_rate}),
            "options": {
                "max_step": args.max_step,
                "contact_law": args.contact_law,
                "ideal": args.ideal,
            },
            "seed": args.seed,
        }
    )


def _out_path(args) -> Path | None:
    """``--out``, checked before simulating: a bad path fails fast."""
    if args.out is None and not args.live:
        raise PRSMHealthError("--out is required (or --live)")
    if args.live and args.json:
        raise PRSMHealthError("--live plays the run to Foxglove: drop --json")
    if args.out is None:
        return None
    out = Path(args.out)
    if out.suffix not in (".parquet", ".mcap"):
        raise PRSMHealthError(
            f"--out {out}: unsupported extension {out.suffix!r} (use .parquet or .mcap)"
        )
    if not out.parent.exists():
        raise PRSMHealthError(f"--out {out}: directory {out.parent} does not exist")
    return out


def simulate(args) -> int:
    out = _out_path(args)
    # before simulating: a bad model fails fast
    bundle = load_bundle(args.model) if args.live and not args.no_diagnosis else None
    scenario = scenario_from_args(args)
    run = scenario.simulate(progress=not args.json)
    if out is not None and out.suffix == ".mcap":
        write_mcap(run, out)
    elif out is not None:
        write_run_parquet(run, out)
    mesh = characteristic_frequencies(scenario.design, args.speed).gear_mesh
    if args.plot and run.check:  # a check: its phases over time, not one operating point
        plot_check(run, args.plot)
    elif args.plot:
        plot_run(run, args.plot, mesh_frequency=mesh)
    if args.json:
        print_json(
            {
                "out": None if out is None else str(out),
                "instrumentation": scenario.instrumentation.name,
                "channels": list(run.channels),
                "samples": len(run),
                "sample_rate": run.sample_rate,
                "duration": scenario.profile.duration,
                "gear_mesh_frequency": mesh,
                "integration_step": run.scenario["integration_step"],
                "highest_natural_frequency": run.scenario["highest_natural_frequency"],
                "energy": run.energy,
                "check": None if run.check is None else run.check.as_record(),
                "labels": run.labels,
            }
        )
    else:
        print_table(
            [("wrote", str(out), "")] * (out is not None)
            + [
                ("instrumentation", scenario.instrumentation.name, ""),
                ("channels", ", ".join(run.channels), ""),
                ("samples", len(run), f"at {run.sample_rate:g} Hz"),
                # the load as resolved against the design's rating (a share given, or the default)
                ("axial load", run.operating.axial_load, "N, peak" if run.check else "N, mean"),
                ("peak load", 100.0 * run.labels["load_share"], "% of C_a"),
                *[
                    (f"check {run.check.name}", p.name, f"{p.start:.3f}–{p.end:.3f} s")
                    for p in (run.check.phases if run.check is not None else ())
                ],
                ("gear mesh frequency", mesh, "Hz"),
                ("integration step", run.scenario["integration_step"], "s"),
                ("drive energy", run.energy["drive"], "J"),
                ("dissipated energy", run.energy["dissipated"], "J"),
            ]
        )
    if args.live:
        window = args.window or (bundle.window if bundle is not None else 1.0)
        return play_live(run, args, bundle, window, rate=args.rate)
    return 0
