"""Command line: ``prsm-health <command>``.

The CLI only parses arguments, calls the library and formats results; SI units on the command
line except where an option name says otherwise (``--pressure-angle DEG``). A user error prints
one line ``error: …`` to stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import math
import sys

from prsm_health import __version__
from prsm_health.core.errors import PRSMHealthError


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit 2."""

    def error(self, message):  # noqa: D401 - argparse API
        raise _UsageError(message)


class _UsageError(Exception):
    pass


def _print_json(obj) -> None:
    from prsm_health.core.jsonable import dumps

    print(dumps(obj, indent=2))


def _print_table(rows: list[tuple[str, object, str]]) -> None:
    width = max(len(name) for name, _, _ in rows)
    for name, value, unit in rows:
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{name:<{width}}  {text} {unit}".rstrip())


# ----------------------------------------------------------------------------- validate
def _cmd_validate(args) -> int:
    from prsm_health.validation import collect, summary, to_markdown

    rows = collect()
    counts = summary(rows)
    failed = [r for r in rows if r.failed]
    if args.json:
        _print_json({"rows": [r.as_dict() for r in rows], "summary": counts})
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
    import textwrap

    from prsm_health.validation import _fmt

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


# ----------------------------------------------------------------------------- kinematics
def _cmd_kinematics(args) -> int:
    from prsm_health.physics.kinematics import (
        characteristic_frequencies,
        defect_frequencies,
        speed_ratios,
    )

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
    if args.json:
        _print_json(out)
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
    _print_table(rows)
    return 0


# ----------------------------------------------------------------------------- stiffness
def _cmd_stiffness_gear(args) -> int:
    from prsm_health.physics.stiffness.gear_mesh import mesh_stiffness

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
        _print_json(out)
    else:
        _print_table(
            [
                ("contact ratio", out["contact_ratio"], ""),
                ("k_min", out["k_min"], "N/m"),
                ("k_max", out["k_max"], "N/m"),
                ("k_mean", out["k_mean"], "N/m"),
            ]
        )
    return 0


def _cmd_stiffness_axial(args) -> int:
    from prsm_health.physics.stiffness.thread import axial_stiffness

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
        _print_json(out)
    else:
        _print_table(
            [
                ("design", design.name, ""),
                ("axial load", args.load, "N"),
                ("deformation", out["deformation"], "m"),
                ("secant stiffness F/δ", out["secant_stiffness"], "N/m"),
                ("tangent stiffness dF/dδ", out["tangent_stiffness"], "N/m"),
            ]
        )
    return 0


def _cmd_stiffness_cylinder(args) -> int:
    from prsm_health.physics.stiffness.cylinder import ElectricCylinder, cylinder_deformation

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
        _print_json(out)
    else:
        rows = [(f"Δl {name}", value, "m") for name, value in components.items()]
        rows += [("Δl total", out["total"], "m"), ("stiffness F/Δl", out["stiffness"], "N/m")]
        _print_table(rows)
    return 0


# ----------------------------------------------------------------------------- friction
def _cmd_friction(args) -> int:
    from prsm_health.physics.friction import FrictionParameters, simulate_friction

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
        _print_json(out)
    else:
        _print_table(
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


# ----------------------------------------------------------------------------- design
def _cmd_design_template(args) -> int:
    from prsm_health.actuator.design import preset
    from prsm_health.actuator.design_files import design_to_toml

    print(
        f"# PRSM design file, from preset {args.preset}: edit the values (SI units: m, kg, kg·m²,\n"
        "# Pa, rad), rename it, then `prsm-health design check FILE` and use it with\n"
        "# --design FILE. Optional fields left out take their defaults (docs/formats.md).\n"
    )
    print(design_to_toml(preset(args.preset)), end="")
    return 0


def _cmd_design_show(args) -> int:
    from prsm_health.actuator.design_files import design_rows, load_design

    design = load_design(args.design)
    if args.json:
        _print_json(design.to_dict())
    else:
        _print_table(design_rows(design))
    return 0


def _cmd_design_check(args) -> int:
    from prsm_health.actuator.design_files import load_design

    design = load_design(args.file)
    print(f"ok: {design.name}")
    return 0


# ----------------------------------------------------------------------------- generate
def _cmd_generate(args) -> int:
    from prsm_health.datasets import dataset_throughput, generate, load_recipe

    recipe = load_recipe(args.recipe)
    try:
        report = generate(
            recipe,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            formats=args.format,
            progress=not args.json,
        )
    except KeyboardInterrupt:
        print(
            f"interrupted: completed batches are kept in {args.out}; run the same command to resume",
            file=sys.stderr,
        )
        return 130
    if args.json:
        _print_json(
            {
                "out": str(report.out),
                "runs": report.total_runs,
                "generated": report.generated_runs,
                "resumed": report.resumed_runs,
                "seconds": report.seconds,
                "runs_per_minute": report.runs_per_minute,
            }
        )
    else:
        print(f"{recipe.name}: {dataset_throughput(report)} → {report.out}")
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.training import training_problems

    for text in training_problems(Dataset(report.out).runs):
        print(f"warning: this dataset cannot train a model as is ({text})", file=sys.stderr)
    return 0


# ----------------------------------------------------------------------------- replay
def _rate(text: str) -> float | None:
    if text == "max":
        return None
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"{text!r}: use a positive real-time factor or 'max'")
    return value


def _cmd_replay(args) -> int:
    from prsm_health.diagnostics.diagnosis import load_bundle, replay

    if args.live and (args.out or args.json):
        raise PRSMHealthError("--live plays the recording to Foxglove: drop --out and --json")
    bundle = None if args.statistics_only else load_bundle(args.model)
    window = args.window or (bundle.window if bundle else 1.0)
    if args.live:
        return _live(args.file, args, bundle, window, rate=getattr(args, "rate", 1.0))
    steps = []
    rate = getattr(args, "rate", None)
    for step in replay(args.file, bundle, window=window, rate=rate, out=args.out):
        steps.append(step.to_json())
        if not args.json:
            print(_replay_line(steps[-1]))
    if args.json:
        _print_json({"file": args.file, "window": window, "windows": steps, "out": args.out})
    elif not steps:
        print("no complete window in the recording")
    elif args.out and bundle is not None:
        print(f"wrote {args.out} with {len(steps)} /prsm/diagnosis messages")
    return 0


def _replay_line(entry) -> str:
    head = f"window {entry['index']:4d}  {entry['start']:8.3f}–{entry['end']:8.3f} s  "
    if "diagnosis" in entry:
        d = entry["diagnosis"]
        c = d["clearance"]
        return (
            head
            + f"{d['fault_class']:<12} clearance {_um(c['estimate'])} µm [{_um(c['lower'])}, {_um(c['upper'])}]"
        )
    ax = entry["statistics"].get("nut_axial_accel", {})
    return (
        head
        + f"axial rms {ax.get('rms', float('nan')):.4g} m/s²  peak {ax.get('peak', float('nan')):.4g} m/s²"
    )


def _um(value) -> str:
    return "  –" if value is None else f"{1e6 * value:5.1f}"


# ----------------------------------------------------------------------------- live view
def _live(source, args, bundle, window: float, *, rate: float | None) -> int:
    """``replay --live`` and ``simulate --live``: play ``source`` (a file or a Run) to Foxglove
    until its end, then keep the server up until Ctrl-C (exit 0)."""
    import signal

    from .live import LivePlayer

    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(
            f"warning: --host {args.host}: the Foxglove WebSocket protocol has no "
            "authentication; anyone who reaches this address sees the recording",
            file=sys.stderr,
        )
    live = None
    try:
        live = LivePlayer(
            source,
            window=window,
            diagnose=_window_diagnoser(bundle) if bundle is not None else None,
            host=args.host,
            port=args.port,
            rate=rate,
            decimate=args.live_decimate,
        )
        print(
            f"live: open {live.url} in Foxglove (Open connection → Foxglove WebSocket); "
            "playing starts when it subscribes; Ctrl-C stops",
            flush=True,
        )
        if bundle is not None and not live.diagnosing:
            print(
                f"warning: no complete {window:g} s window in the recording: "
                "no diagnosis is published",
                file=sys.stderr,
            )
        live.wait_for_client()
        stats = live.play()
        pace = "as fast as possible" if rate is None else f"at {rate:g}× real time"
        print(
            f"played {stats.samples} samples ({stats.log_span:.3f} s of log time) {pace} "
            f"in {stats.wall_time:.3f} s, every {live.decimate}. sample published, "
            f"{stats.diagnoses} diagnoses; the server stays up until Ctrl-C",
            flush=True,
        )
        live.hold()
    except KeyboardInterrupt:
        # A second Ctrl-C must not interrupt the shutdown with a traceback.
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            if live is not None:
                live.close()
            print("stopped", file=sys.stderr)
        finally:
            signal.signal(signal.SIGINT, previous)
    finally:
        if live is not None:
            live.close()
    return 0


def _window_diagnoser(bundle):
    """Window → its Diagnosis JSON object (what ``replay --out`` writes on /prsm/diagnosis)."""
    from prsm_health.core.run import Run
    from prsm_health.diagnostics.diagnosis import diagnose_window

    def diagnose(w) -> dict:
        return diagnose_window(Run(w.time, w.channels, w.sample_rate, w.labels), bundle).to_json()

    return diagnose


# ----------------------------------------------------------------------------- serve
def _cmd_serve(args) -> int:
    from .service import ServiceLimits, serve

    overrides = {"max_window_seconds": args.max_window}
    if args.workers is not None:  # 0 or negative: ServiceLimits refuses it by name
        overrides["workers"] = args.workers
    if args.processes is not None:
        overrides["processes"] = args.processes
    try:
        serve(
            args.host,
            args.port,
            args.model,
            args.db,
            args.token,
            limits=ServiceLimits(**overrides),
            log_level=args.log_level,
            prognostics_model_path=args.prognostics_model,
        )
    except KeyboardInterrupt:  # Ctrl-C: uvicorn has shut down gracefully and said so
        return 0
    return 0


# ----------------------------------------------------------------------------- diagnose / train
def _cmd_diagnose(args) -> int:
    from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
    from prsm_health.io import read_recording

    bundle = load_bundle(args.model)
    result = diagnose(read_recording(args.file), bundle, window=args.window)
    if args.plot:
        from .plots import plot_diagnosis

        plot_diagnosis(result, args.plot)
    if args.json:
        _print_json(result.to_json())
        return 0
    c = result.clearance
    rows = [
        ("file", args.file, ""),
        ("fault class", result.fault_class, ""),
        ("class set", ", ".join(result.class_set), "  not ruled out (90 %)"),
        (
            "clearance",
            f"{_um(c['estimate'])} [{_um(c['lower'])}, {_um(c['upper'])}]",
            "µm (90 % interval)",
        ),
    ]
    rows += [(f"P({k})", v, "") for k, v in result.class_probabilities.items()]
    rows += [
        ("clearance observable", result.observability.get("clearance"), "share of windows"),
        ("class observable", result.observability.get("fault"), "share of windows"),
        ("out-of-distribution score", result.ood_score, "> 1.5: unlike the training set"),
        ("windows", len(result.windows), ""),
        ("model", f"{result.model['name']} v{result.model['version']}", ""),
    ]
    rows += [("warning", text, "") for text in result.warnings]
    _print_table(rows)
    return 0


def _cmd_import(args) -> int:
    from prsm_health.datasets.importer import import_recordings

    summary = import_recordings(
        args.recordings,
        args.labels,
        args.map,
        args.out,
        test_fraction=args.test_fraction,
        seed=args.seed,
        overwrite=args.overwrite,
    )
    if args.json:
        _print_json(summary)
        return 0
    _print_table(
        [
            ("dataset", summary["out"], ""),
            ("runs", f"{summary['runs']} ({summary['train']} train, {summary['test']} test)", ""),
            ("channels", ", ".join(summary["channels"]), ""),
            ("sample rate", summary["sample_rate"], "Hz"),
            ("classes", ", ".join(summary["classes"]) or "–", ""),
        ]
    )
    return 0


def _cmd_evaluate(args) -> int:
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.diagnosis import load_bundle
    from prsm_health.diagnostics.evaluation import evaluate_model

    bundle = load_bundle(args.model)
    dataset = Dataset(args.dataset)
    report, records = evaluate_model(bundle, dataset, split=args.split, progress=not args.json)
    if args.plot:
        from .plots import plot_evaluation

        report["figures"] = [str(p) for p in plot_evaluation(report, records, args.plot)]
    if args.json:
        _print_json(report)
        return 0
    rows = [
        ("model", f"{report['model']['name']} v{report['model']['version']}", ""),
        ("dataset", f"{report['dataset']} ({report['split']}: {report['runs']} runs)", ""),
    ]
    if "clearance" in report:
        c = report["clearance"]
        rows += [
            ("clearance MAE", _scaled(c["mae"], 1e6), "µm"),
            ("clearance 90 % interval coverage", _scaled(c["coverage"]), ""),
            ("clearance mean interval width", _scaled(c["mean_width"], 1e6), "µm"),
            ("clearance observable", _scaled(c["observable_fraction"]), "of runs"),
        ]
    if "fault" in report:
        f = report["fault"]
        rows += [
            ("fault macro-F1", _scaled(f["macro_f1"]), "cannot_tell counted as a miss"),
            ("fault macro-F1, runs given a class", _scaled(f["macro_f1_told"]), ""),
            ("cannot_tell", _scaled(f["cannot_tell_fraction"]), "of runs"),
        ]
        rows += [(f"F1({k})", v, "") for k, v in f["f1_by_class"].items()]
    rows.append(("out of distribution", _scaled(report["ood"]["flagged_fraction"]), "of runs"))
    rows += [("figure", p, "") for p in report.get("figures", [])]
    _print_table(rows)
    return 0


def _cmd_train(args) -> int:
    from prsm_health.diagnostics.training import train

    metrics = train(args.dataset, args.out, target=args.target, cv=args.cv, progress=not args.json)
    if args.json:
        _print_json(metrics)
        return 0
    rows = [("model", metrics["model"]["path"], ""), ("metrics", metrics["metrics_path"], "")]
    for key, label in (("clearance_cv", "clearance CV"), ("clearance_test", "clearance held-out")):
        if metrics.get(key):
            m = metrics[key]
            rows.append((f"{label} MAE", _scaled(m.get("mae"), 1e6), "µm"))
            rows.append(
                (f"{label} 90 % interval coverage", _scaled(m.get("interval_coverage")), "")
            )
            rows.append(
                (f"{label} mean interval width", _scaled(m.get("mean_interval_width"), 1e6), "µm")
            )
    for key, label in (("fault_cv", "fault CV"), ("fault_test", "fault held-out")):
        if metrics.get(key):
            rows.append((f"{label} macro-F1", _scaled(metrics[key].get("macro_f1")), ""))
    _print_table(rows)
    for text in metrics.get("warnings", []):
        print(f"warning: {text}", file=sys.stderr)
    return 0


def _scaled(value, factor: float = 1.0):
    """A metric for the table; '–' where it could not be computed (None)."""
    return "–" if value is None else factor * value


# ----------------------------------------------------------------------------- prognose
#: The methods ``prognose --method`` offers (those of prsm_health.prognostics.rul.METHODS; kept
#: here so that building the parser does not import pandas and scipy).
PROGNOSIS_METHODS = ("degradation", "similarity", "degradation-exponential", "degradation-linear")


def _is_dataset(source: str) -> bool:
    """A fleet dataset (a directory, or an object-store URL) rather than a history file."""
    from pathlib import Path

    return "://" in source or Path(source).is_dir()


def _cmd_prognose(args) -> int:
    from prsm_health.prognostics import load_prognostics_model, prognose, read_history

    fleet = _is_dataset(args.source)
    if not fleet:
        for option, value in (
            ("--unit", args.unit),
            ("--until-age", args.until_age),
            ("--diagnosis-model", args.diagnosis_model),
        ):
            if value is not None:
                raise PRSMHealthError(
                    f"{option} applies to a fleet dataset; {args.source} is a history file"
                )
    elif args.unit is None:
        raise PRSMHealthError(
            f"{args.source} is a fleet dataset: choose the unit to prognose with --unit ID"
        )
    model = load_prognostics_model(args.model)  # before the diagnoses: a bad file fails fast
    true_rul = None
    if fleet:
        from prsm_health.diagnostics.diagnosis import load_bundle
        from prsm_health.prognostics import fleet_histories

        # the shipped model is loaded by fleet_histories, after its checks of the unit and age
        bundle = None if args.diagnosis_model is None else load_bundle(args.diagnosis_model)
        history = fleet_histories(
            args.source,
            bundle,
            units=[args.unit],
            until_age=args.until_age,
            progress=not args.json and sys.stderr.isatty(),  # a person is watching
        )
        true_rul = float(history["rul_hours"].iloc[-1])
    else:
        history = read_history(args.source)
    prognosis = prognose(history, model, args.method)
    if args.json:
        _print_json(prognosis.as_dict())
        return 0
    _print_table(_prognosis_rows(args, prognosis, history, true_rul))
    return 0


def _hours(value: float) -> str:
    """Hours for the summary: whole hours from 100 h, else 3 significant digits."""
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.3g}"


def _prognosis_rows(args, prognosis, history, true_rul) -> list:
    rul, hi, m = prognosis.rul_hours, prognosis.health_indicator, prognosis.model
    latest = history.iloc[-1]  # the latest diagnosis, with its own (maybe uneven) interval
    ages = hi["ages_hours"]
    source = f"{args.source}, unit {args.unit}" if args.unit is not None else args.source
    rows = [
        ("history", source, ""),
        ("diagnoses", f"{len(ages)} from {_hours(ages[0])} to {_hours(ages[-1])}", "h"),
        (
            "RUL",
            f"{_hours(rul['estimate'])} [{_hours(rul['lower'])}, {_hours(rul['upper'])}]",
            "h (median, 90 % interval)",
        ),
    ]
    if true_rul is not None:
        rows.append(("true RUL", _hours(true_rul), "h (the simulator's truth, dataset labels)"))
    rows += [
        (
            "clearance now",
            f"{_um(hi['current']).strip()} [{_um(float(latest['clearance_lower'])).strip()}, "
            f"{_um(float(latest['clearance_upper'])).strip()}]",
            "µm (90 % interval)",
        ),
        ("failure threshold", _um(hi["threshold"]).strip(), "µm"),
        ("method", m["name"], ""),
        ("model", f"{m['design']}, {m['units_trained']} training units, v{m['version']}", ""),
    ]
    rows += [("warning", text, "") for text in prognosis.warnings]
    return rows


# ----------------------------------------------------------------------------- simulate
def _cmd_simulate(args) -> int:
    from pathlib import Path

    from prsm_health.actuator.drive_train import load_drive_train
    from prsm_health.core.tomlfile import read_toml
    from prsm_health.physics.kinematics import characteristic_frequencies
    from prsm_health.simulation.scenario import Scenario

    if args.out is None and not args.live:
        raise PRSMHealthError("--out is required (or --live)")
    if args.live and args.json:
        raise PRSMHealthError("--live plays the run to Foxglove: drop --json")
    out = Path(args.out) if args.out is not None else None
    if out is not None and out.suffix not in (".parquet", ".mcap"):
        raise PRSMHealthError(
            f"--out {out}: unsupported extension {out.suffix!r} (use .parquet or .mcap)"
        )
    if out is not None and not out.parent.exists():
        raise PRSMHealthError(f"--out {out}: directory {out.parent} does not exist")
    bundle = None
    if args.live and not args.no_diagnosis:
        from prsm_health.diagnostics.diagnosis import load_bundle

        bundle = load_bundle(args.model)  # before simulating: a bad model fails fast
    # a health file gives the base state; the flags given on the command line override it
    health = read_toml(args.health, "health file") if args.health else {}
    if args.clearance is not None:
        health.update(dict.fromkeys(("clearance_screw", "clearance_nut"), args.clearance))
        health.setdefault("clearance_gear", args.clearance)
    flags = {
        "clearance_gear": args.gear_clearance,
        "wear_spread": args.wear_spread,
        "friction_scale": args.friction_scale,
        "preload": args.preload,
    }
    health.update({k: v for k, v in flags.items() if v is not None})
    scenario = Scenario.from_dict(
        {
            "design": args.design,
            "health": health,
            "profile": {
                "duration": args.duration,
                "motion": args.profile,
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
    run = scenario.simulate(progress=not args.json)
    design, profile = scenario.design, scenario.profile
    if out is not None and out.suffix == ".mcap":
        from prsm_health.io.mcap import write_mcap

        write_mcap(run, out)
    elif out is not None:
        from prsm_health.io.parquet import write_run_parquet

        write_run_parquet(run, out)
    mesh = characteristic_frequencies(design, args.speed).gear_mesh
    if args.plot:
        from .plots import plot_run

        plot_run(run, args.plot, mesh_frequency=mesh)
    summary = {
        "out": None if out is None else str(out),
        "instrumentation": scenario.instrumentation.name,
        "channels": list(run.channels),
        "samples": len(run),
        "sample_rate": run.sample_rate,
        "duration": profile.duration,
        "gear_mesh_frequency": mesh,
        "integration_step": run.scenario["integration_step"],
        "highest_natural_frequency": run.scenario["highest_natural_frequency"],
        "energy": run.energy,
        "labels": run.labels,
    }
    if args.json:
        _print_json(summary)
    else:
        _print_table(
            [("wrote", str(out), "")] * (out is not None)
            + [
                ("instrumentation", scenario.instrumentation.name, ""),
                ("channels", ", ".join(run.channels), ""),
                ("samples", len(run), f"at {run.sample_rate:g} Hz"),
                ("gear mesh frequency", mesh, "Hz"),
                ("integration step", run.scenario["integration_step"], "s"),
                ("drive energy", run.energy["drive"], "J"),
                ("dissipated energy", run.energy["dissipated"], "J"),
            ]
        )
    if args.live:
        window = args.window or (bundle.window if bundle is not None else 1.0)
        return _live(run, args, bundle, window, rate=args.rate)
    return 0


# ----------------------------------------------------------------------------- instrumentation
def _cmd_instrumentation_list(args) -> int:
    from prsm_health.simulation.instrumentation import list_profiles, load_instrumentation

    profiles = [load_instrumentation(name) for name in list_profiles()]
    if args.json:
        _print_json(
            [
                {"name": p.name, "description": p.description, "channels": list(p.fitted)}
                for p in profiles
            ]
        )
    else:
        _print_table([(p.name, p.description, "") for p in profiles])
    return 0


def _cmd_instrumentation_show(args) -> int:
    from prsm_health.simulation.instrumentation import load_instrumentation

    info = load_instrumentation(args.profile).describe()
    if args.json:
        _print_json(info)
        return 0
    rows = [
        ("name", info["name"], ""),
        ("description", info["description"], ""),
        ("sample_rate", info["sample_rate"], "Hz"),
    ]
    for channel, sensor in info["sensors"].items():
        rows.append((channel, f"{sensor['kind']}, reads {sensor['reads']}", ""))
        rows += [(f"  {p['name']}", _listed(p["value"]), p["unit"]) for p in sensor["parameters"]]
    _print_table(rows)
    return 0


def _listed(value):
    """A parameter for the table: lists comma-separated, floats to 6 significant digits."""
    if isinstance(value, list):
        return "[" + ", ".join(f"{v:.6g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return value


# ----------------------------------------------------------------------------- parser
def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def _step(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        return _finite_float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither a step in seconds nor 'auto'"
        ) from None


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Help with every option's default; an option without one says in its help what applies."""

    def _get_help_string(self, action):
        if action.default is None or action.default is False or action.required:
            return action.help
        return super()._get_help_string(action)


DESIGN_HELP = "preset name (paper01…paper05) or design TOML file"


def _design(text: str):
    """``--design``: a preset name or a design file, loaded here so errors name the option."""
    from prsm_health.actuator.design_files import load_design

    try:
        return load_design(text)
    except PRSMHealthError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


PROFILE_HELP = (
    "instrumentation profile: a built-in name (prsm-health instrumentation list) or a TOML file"
)


def _removed_option(replacement: str):
    """The type of an option that no longer exists: using it is a one-line error saying what
    replaced it."""

    def reject(text: str):
        raise argparse.ArgumentTypeError(f"this option was removed: {replacement}")

    return reject


def _add_json(p, what: str = "the result") -> None:
    p.add_argument("--json", action="store_true", help=f"print {what} as JSON instead of a table")


def build_parser() -> argparse.ArgumentParser:
    from prsm_health.actuator.design import DEFAULT_PRESET, PRESETS

    parser = _Parser(
        prog="prsm-health",
        description="Planetary roller screw physics, signal generation and diagnostics. "
        "SI units on the command line unless an option says otherwise.",
        formatter_class=_HelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"prsm-health {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def command(name: str, text: str):
        return sub.add_parser(name, help=text, description=text, formatter_class=_HelpFormatter)

    designs = sorted(PRESETS)
    p = command("validate", "compare the models with every number the papers print")
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="print the rows as JSON")
    fmt.add_argument("--markdown", action="store_true", help="print a Markdown table")
    p.set_defaults(func=_cmd_validate)

    p = command("design", "design files: a template, a design's fields, a check")
    design = _actions(p)

    t = design("template", "print a commented design TOML file to start from")
    t.add_argument(
        "--from", dest="preset", default=DEFAULT_PRESET, choices=designs, help="preset to copy"
    )
    t.set_defaults(func=_cmd_design_template)
    t = design("show", "print every field of a design with its unit")
    t.add_argument("design", help=DESIGN_HELP)
    _add_json(t, "the design's dict form")
    t.set_defaults(func=_cmd_design_show)
    t = design("check", "validate a design file: 'ok: NAME', or one error line and exit 2")
    t.add_argument("file", help="design TOML file (or a preset name)")
    t.set_defaults(func=_cmd_design_check)

    p = command("instrumentation", "instrumentation profiles: the sensors a run is measured with")
    instrumentation = _actions(p)

    t = instrumentation("list", "the built-in profiles, one line each")
    _add_json(t, "the profiles (name, description, channels)")
    t.set_defaults(func=_cmd_instrumentation_list)
    t = instrumentation("show", "every sensor of a profile with its parameters and units")
    t.add_argument("profile", help=PROFILE_HELP)
    _add_json(t, "the profile")
    t.set_defaults(func=_cmd_instrumentation_show)

    p = command("kinematics", "speed ratios and characteristic frequencies of a design")
    p.add_argument("--design", type=_design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    p.add_argument("--speed", type=_finite_float, required=True, help="screw speed [rad/s]")
    _add_json(p)
    p.set_defaults(func=_cmd_kinematics)

    p = command("stiffness", "static stiffness models: gear mesh, axial, electric cylinder")
    ssub = p.add_subparsers(dest="model", required=True, parser_class=_Parser)

    def stiffness(name: str, text: str):
        return ssub.add_parser(name, help=text, description=text, formatter_class=_HelpFormatter)

    g = stiffness("gear", "time-varying gear mesh stiffness (potential energy method, paper 01)")
    g.add_argument("--z1", type=int, required=True, help="pinion (roller gear) teeth")
    g.add_argument("--z2", type=int, required=True, help="gear (ring gear) teeth")
    g.add_argument("--module", type=_finite_float, required=True, help="module [m]")
    g.add_argument(
        "--pressure-angle", type=_finite_float, default=20.0, metavar="DEG", help="[deg]"
    )
    g.add_argument("--face-width", type=_finite_float, required=True, help="face width [m]")
    g.add_argument("--bore-diameter", type=_finite_float, default=0.0, help="pinion bore [m]")
    g.add_argument("--internal", action="store_true", help="z2 is an internal ring gear")
    g.add_argument(
        "--youngs-modulus", type=_finite_float, default=2.1e11, metavar="PA", help="[Pa]"
    )
    g.add_argument("--poisson", type=_finite_float, default=0.3, metavar="V", help="[-]")
    g.add_argument("--threaded-tooth", action="store_true", help="PRSM threaded roller tooth")
    _add_json(g)
    g.set_defaults(func=_cmd_stiffness_gear)

    a = stiffness("axial", "axial stiffness of the whole PRSM (papers 01, 04)")
    a.add_argument("--design", type=_design, default=DEFAULT_PRESET, help=DESIGN_HELP)
    a.add_argument("--load", type=_finite_float, required=True, help="axial load [N]")
    _add_json(a)
    a.set_defaults(func=_cmd_stiffness_axial)

    c = stiffness("cylinder", "electric-cylinder deformation and stiffness (paper 05)")
    c.add_argument("--load", type=_finite_float, required=True, help="axial load [N]")
    c.add_argument("--extension", type=_finite_float, required=True, help="rod extension [m]")
    _add_json(c)
    c.set_defaults(func=_cmd_stiffness_cylinder)

    _add_simulate_parser(command, DEFAULT_PRESET)

    g = command("generate", "generate a labelled dataset from a recipe (resumable after Ctrl-C)")
    g.add_argument("recipe", help="TOML recipe (see datasets/ and docs/formats.md)")
    g.add_argument(
        "--out",
        required=True,
        help="dataset directory or object-store URL, e.g. s3://bucket/prefix (created; rerun to "
        "resume; credentials and endpoint from the environment, docs/formats.md)",
    )
    g.add_argument(
        "--workers", type=int, default=None, help="local worker processes (None: all cores)"
    )
    g.add_argument(
        "--scheduler",
        default=None,
        help="Dask scheduler address, e.g. tcp://host:8786 (None: $DASK_SCHEDULER_ADDRESS, "
        "else local processes)",
    )
    g.add_argument(
        "--format", choices=("parquet", "mcap", "both"), default="parquet", help="signal files"
    )
    _add_json(g, "the generation report")
    g.set_defaults(func=_cmd_generate)

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
        type=_finite_float,
        default=0.25,
        help="held-out share when the labels have no split column",
    )
    i.add_argument("--seed", type=int, default=0, help="seed of that split")
    i.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    _add_json(i, "the summary")
    i.set_defaults(func=_cmd_import)

    t = command("train", "train the clearance estimator and fault classifier on a dataset")
    t.add_argument("dataset", help="dataset directory or URL (prsm-health generate)")
    t.add_argument(
        "--out", required=True, help="model file, must end in .skops; metrics JSON beside it"
    )
    t.add_argument(
        "--target",
        choices=("clearance", "fault", "both"),
        default="both",
        help="what to train: the clearance estimator, the fault classifier or both",
    )
    t.add_argument("--cv", type=int, default=5, help="cross-validation folds on the train split")
    _add_json(t, "the metrics")
    t.set_defaults(func=_cmd_train)

    d = command("diagnose", "diagnose a recording: clearance with interval, fault class")
    d.add_argument("file", help="recording: .mcap, .parquet (one run) or .csv (docs/formats.md)")
    d.add_argument("--model", default=None, help="model bundle (None: the shipped model)")
    d.add_argument(
        "--window", type=_finite_float, default=None, help="window length [s] (None: the model's)"
    )
    d.add_argument("--plot", default=None, help="write a PNG of the per-window estimates")
    _add_json(d, "the Diagnosis contract")
    d.set_defaults(func=_cmd_diagnose)

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
        "--unit", type=int, default=None, metavar="ID", help="fleet dataset: the unit's unit_id"
    )
    g.add_argument(
        "--until-age",
        type=_finite_float,
        default=None,
        metavar="H",
        help="fleet dataset: only the snapshots at ages <= H [h] (what was known then)",
    )
    g.add_argument(
        "--model", default=None, help="prognostics model JSON (None: models/prognostics.json)"
    )
    g.add_argument(
        "--diagnosis-model",
        default=None,
        metavar="D",
        help="fleet dataset: model bundle that diagnoses the snapshots (None: the shipped model)",
    )
    g.add_argument(
        "--method",
        choices=PROGNOSIS_METHODS,
        default=None,
        help="degradation (the form chosen at fit time), similarity, or a forced degradation "
        "form (None: the model's default)",
    )
    _add_json(g, "the prognosis")
    g.set_defaults(func=_cmd_prognose)

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
        help="write clearance.png, calibration.png and confusion.png into DIR",
    )
    _add_json(e, "the metrics")
    e.set_defaults(func=_cmd_evaluate)

    r = command("replay", "stream an MCAP recording window by window through the diagnosis")
    r.add_argument("file", help="MCAP recording")
    r.add_argument(
        "--window", type=_finite_float, default=None, help="window length [s] (None: the model's)"
    )
    r.add_argument(
        "--rate",
        type=_rate,
        default=argparse.SUPPRESS,
        help="real-time factor, or 'max' (default: max; with --live: 1, real time)",
    )
    r.add_argument("--model", default=None, help="model bundle (None: the shipped model)")
    r.add_argument(
        "--out", default=None, help="write a copy of the recording with /prsm/diagnosis messages"
    )
    r.add_argument(
        "--statistics-only", action="store_true", help="window statistics only, no model"
    )
    _add_json(r, "every window")
    _add_live(r, rate=False)
    r.set_defaults(func=_cmd_replay)

    v = command("serve", "HTTP diagnostics service with asset health history (docs/service.md)")
    v.add_argument("--host", default="127.0.0.1", help="bind address (non-loopback needs a token)")
    v.add_argument("--port", type=int, default=8000, help="TCP port")
    v.add_argument("--model", default=None, help="model bundle (None: the shipped model)")
    v.add_argument(
        "--prognostics-model",
        default=None,
        metavar="FILE",
        help="prognostics model for GET /v1/assets/{id}/prognosis (None: the shipped "
        "models/prognostics.json if present, else that endpoint answers 503)",
    )
    v.add_argument("--db", default=None, help="SQLite history database (None: see docs/service.md)")
    v.add_argument("--token", default=None, help="bearer token (None: $PRSM_HEALTH_TOKEN)")
    v.add_argument(
        "--workers", type=int, default=None, help="diagnoses computed at once (None: cores)"
    )
    v.add_argument(
        "--processes",
        type=int,
        default=None,
        help="diagnosis processes, each with the model loaded once (None or 0: threads)",
    )
    v.add_argument(
        "--max-window", type=_finite_float, default=2.0, help="longest JSON recording [s]"
    )
    v.add_argument(
        "--log-level",
        default="info",
        choices=("critical", "error", "warning", "info", "debug"),
        help="server log level",
    )
    v.set_defaults(func=_cmd_serve)

    f = command("friction", "friction torque and efficiency at start-up (paper 02)")
    f.add_argument("--load", type=_finite_float, required=True, help="output axial force [N]")
    f.add_argument("--speed", type=_finite_float, default=1.0, help="final screw speed [rad/s]")
    f.add_argument("--accel-time", type=_finite_float, default=0.02, help="ramp time [s]")
    f.add_argument(
        "--duration", type=_finite_float, default=None, help="[s] (None: accel-time + 0.1 s)"
    )
    f.add_argument("--friction-scale", type=_finite_float, default=1.0, help="lubricant state [-]")
    f.add_argument(
        "--design", type=_design, default=None, help=f"{DESIGN_HELP} (None: paper 02's table)"
    )
    _add_json(f)
    f.set_defaults(func=_cmd_friction)
    return parser


def _port(text: str) -> int:
    value = int(text)
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r}: use a TCP port 0…65535 (0: any free port)")
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: use an integer >= 1")
    return value


def _add_live(p, *, rate: bool) -> None:
    """The ``--live`` options of ``replay`` and ``simulate`` (docs/live.md)."""
    from .live import DEFAULT_HOST, DEFAULT_PORT, MESSAGE_BUDGET

    p.add_argument(
        "--live",
        action="store_true",
        help="play the recording to Foxglove over its WebSocket protocol, with the diagnosis "
        "of each window (docs/live.md)",
    )
    p.add_argument(
        "--host",
        default=DEFAULT_HOST,
        help="--live: bind address (the protocol has no authentication: keep it local)",
    )
    p.add_argument(
        "--port", type=_port, default=DEFAULT_PORT, help="--live: TCP port (0: any free port)"
    )
    if rate:
        p.add_argument("--rate", type=_rate, default=1.0, help="--live: real-time factor, or 'max'")
    p.add_argument(
        "--live-decimate",
        type=_positive_int,
        default=None,
        metavar="N",
        help=f"--live: publish every Nth sample (None: the smallest N that keeps all topics "
        f"under {MESSAGE_BUDGET} messages/s — 2 for a 20 kHz recording, 3 with truth)",
    )


def _actions(parser):
    """A maker of ``parser``'s sub-actions (``design template``, ``instrumentation show`` …)."""
    sub = parser.add_subparsers(dest="action", required=True, parser_class=_Parser)

    def action(name: str, text: str):
        return sub.add_parser(name, help=text, description=text, formatter_class=_HelpFormatter)

    return action


def _add_simulate_parser(command, default_preset) -> None:
    from prsm_health.actuator.states import DRIVES, LOADS, MOTIONS, RAMP_SHAPES
    from prsm_health.simulation.instrumentation import DEFAULT_PROFILE

    s = command("simulate", "simulate a PRSM run (paper 01 dynamics) and write it")
    s.add_argument("--design", type=_design, default=default_preset, help=DESIGN_HELP)
    s.add_argument(
        "--health",
        default=None,
        metavar="FILE",
        help="health file (TOML: clearances, preload, lubricant and [[faults]], docs/faults.md); "
        "the health flags below override its values",
    )
    s.add_argument(
        "--clearance",
        type=_finite_float,
        default=None,
        help="thread (and gear) half-clearance b [m] (default 10e-6)",
    )
    s.add_argument(
        "--gear-clearance",
        type=_finite_float,
        default=None,
        help="gear backlash b_g [m] (default: the thread clearance)",
    )
    s.add_argument(
        "--wear-spread", type=_finite_float, default=None, help="uneven roller wear [-] (0)"
    )
    s.add_argument(
        "--preload",
        type=_finite_float,
        default=None,
        help="installed axial interference on each thread flank [m] (preloaded nut; 0: none)",
    )
    s.add_argument(
        "--friction-scale", type=_finite_float, default=None, help="friction multiplier [-] (1)"
    )
    s.add_argument("--speed", type=_finite_float, default=100.0, help="screw speed [rad/s]")
    s.add_argument("--load", type=_finite_float, default=100.0, help="resisting axial load [N]")
    s.add_argument("--profile", choices=MOTIONS, default="constant", help="screw motion profile")
    s.add_argument(
        "--accel-time", type=_finite_float, default=0.02, help="speed ramp and load edge [s]"
    )
    s.add_argument("--period", type=_finite_float, default=0.1, help="reversing motion period [s]")
    s.add_argument("--load-profile", choices=LOADS, default="constant", help="axial load profile")
    s.add_argument(
        "--load-ramp-time",
        type=_finite_float,
        default=None,
        help="duration of each reversal of the reversing load [s] (None: --accel-time)",
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
        "--load-amplitude", type=_finite_float, default=0.0, help="load swing around --load [N]"
    )
    s.add_argument(
        "--load-frequency", type=_finite_float, default=20.0, help="load swing frequency [Hz]"
    )
    s.add_argument("--duration", type=_finite_float, default=0.2, help="simulated time [s]")
    s.add_argument(
        "--instrumentation", default=DEFAULT_PROFILE, metavar="PROFILE", help=PROFILE_HELP
    )
    s.add_argument(
        "--sample-rate",
        type=_finite_float,
        default=None,
        help="output rate [Hz] (None: the profile's, 20 kHz for the built-ins)",
    )
    s.add_argument(
        "--accel-noise",
        type=_removed_option(
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
        type=_step,
        default=5e-6,
        help='largest RK4 step [s], or "auto": 0.6 of the stable step, at most 10 µs',
    )
    s.add_argument("--ideal", action="store_true", help="no manufacturing variation")
    s.add_argument("--seed", type=int, default=0, help="seed of variation, wear and noise")
    s.add_argument(
        "--out", default=None, help="output file (.parquet or .mcap); required unless --live"
    )
    s.add_argument("--plot", default=None, help="write a PNG with time traces and spectra")
    _add_json(s, "a summary")
    _add_live(s, rate=True)
    s.add_argument("--model", default=None, help="--live: model bundle (None: the shipped model)")
    s.add_argument(
        "--window",
        type=_finite_float,
        default=None,
        help="--live: window length [s] (None: the model's)",
    )
    s.add_argument("--no-diagnosis", action="store_true", help="--live: publish the signals only")
    s.set_defaults(func=_cmd_simulate)


def _warning_line(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``prsm-health`` console script."""
    import warnings

    parser = build_parser()
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _warning_line  # one line per warning, no source excerpt
            args = parser.parse_args(argv)
            return args.func(args)
    except _UsageError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except PRSMHealthError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into head & co.: stop quietly
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
