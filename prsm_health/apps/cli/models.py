"""Commands on diagnosis models: ``train``, ``evaluate``, ``diagnose``, ``replay``."""

from __future__ import annotations

import sys
from datetime import datetime, timezone
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.identifiers import content_id
from prsm_health.datasets import Dataset
from prsm_health.diagnostics.diagnosis import diagnose as diagnose_recording
from prsm_health.diagnostics.diagnosis import load_bundle, ood_verdict
from prsm_health.diagnostics.diagnosis import replay as replay_windows
from prsm_health.diagnostics.not_observable import not_observable_text
from prsm_health.io import read_recording
from prsm_health.monitoring import FileAssetStore, commission, diagnose_asset
from prsm_health.training.check_part import is_check_dataset, train_check_part
from prsm_health.training.check_training import CHECK_CV
from prsm_health.training.evaluation import evaluate_model
from prsm_health.training.train import train as train_model

from ..check_plot import plot_check_result
from ..plots import plot_diagnosis, plot_evaluation
from .live import play_live
from .models_options import DEFAULT_CV
from .output import print_json, print_table, scaled, share, um
from .prognose import check_train_options, train_prognostics

# What each fault macro-F1 counts (prsm_health.training.evaluation.fault_report and
# training._class_metrics), so that the tables of train and evaluate cannot be misread.
F1_CANNOT_TELL_MISS = "fault macro-F1 (cannot_tell counted as a miss)"
F1_NAMED = "fault macro-F1 (on the runs given a class)"
F1_CLASSIFIER = "macro-F1 (the classifier alone: no cannot_tell)"


# ----------------------------------------------------------------------------- train
def train(args) -> int:
    check_train_options(args)
    if args.target == "rul":
        return train_prognostics(args)
    if is_check_dataset(Dataset(args.dataset)):
        return train_check(args)
    for option, value in (("--baseline", args.baseline), ("--window-model", args.window_model)):
        if value is not None:
            raise PRSMHealthError(
                f"{option} is for a dataset of health checks; the runs of {args.dataset} are none"
            )
    cv = DEFAULT_CV if args.cv is None else args.cv
    metrics = train_model(args.dataset, args.out, target=args.target, cv=cv, progress=not args.json)
    if args.json:
        print_json(metrics)
        return 0
    print_table(training_rows(metrics))
    for text in metrics.get("warnings", []):
        print(f"warning: {text}", file=sys.stderr)
    return 0


def train_check(args) -> int:
    """``train CHECKS --baseline BASELINE``: the check part of a bundle for the checks' design."""
    if args.target in ("clearance", "fault"):
        raise PRSMHealthError(
            f"--target {args.target}: a dataset of health checks trains the check part, "
            "clearance and class together: leave --target out"
        )
    result = train_check_part(
        args.dataset,
        args.baseline,
        args.out,
        window_model=args.window_model,
        cv=CHECK_CV if args.cv is None else args.cv,
        progress=not args.json,
    )
    if args.json:
        print_json(result)
        return 0
    print_table(check_training_rows(result))
    for text in result["warnings"]:
        print(f"warning: {text}", file=sys.stderr)
    return 0


def check_training_rows(result: dict) -> list:
    """The table of ``train`` on health checks: where the bundle and its check part went, the
    cross-validated (by unit) and held-out metrics."""
    model, m = result["model"], result["check"]
    rows = [
        ("model", model["path"], f"({model['kind']})"),
        ("check part", model["check_part"], ""),
        ("metrics", result["metrics_path"], ""),
        ("design", model["design"], ""),
        ("checks", f"{m['runs']['train']} train, {m['runs']['test']} held out", ""),
        ("baseline checks", m["baseline_runs"], ""),
    ]
    cv = m.get("clearance_cv") or {}
    rows.append(("clearance CV MAE (by unit)", scaled(cv.get("mae"), 1e6), "µm"))
    rows.append(
        ("clearance CV 90 % interval coverage", share(cv.get("interval_coverage"), "checks"), "")
    )
    for key, label in (("fault_cv", "alone"), ("fault_relative_cv", "against the baseline")):
        rows.append((f"class CV macro-F1, {label}", scaled((m.get(key) or {}).get("macro_f1")), ""))
    held = m.get("held_out") or {}
    if held:
        rows.append(("held-out clearance MAE", scaled(held["clearance_mae"], 1e6), "µm"))
        rows.append(("held-out macro-F1, alone", scaled(held["macro_f1_alone"]), ""))
        rows.append(
            (
                "held-out macro-F1, against the baseline",
                scaled(held["macro_f1_against_baseline"]),
                "",
            )
        )
    for kind, how in (("commissioned", "commissioned"), ("nominal", "not commissioned")):
        g = m.get("gauge", {}).get(kind)
        if g and g.get("held_out_error_sd") is not None:
            error = f"{1e6 * g['held_out_error_mean']:+.2f} ± {1e6 * g['held_out_error_sd']:.2f}"
            covered = share(g["held_out_coverage"], "checks")
            rows.append((f"measured clearance, {how}", error, f"µm held out; interval {covered}"))
    return rows


def training_rows(metrics: dict) -> list:
    """The table of ``train``: where the model went, its cross-validated and held-out
    metrics."""
    rows = [("model", metrics["model"]["path"], ""), ("metrics", metrics["metrics_path"], "")]
    for key, label in (("clearance_cv", "clearance CV"), ("clearance_test", "clearance held-out")):
        if metrics.get(key):
            m = metrics[key]
            rows.append((f"{label} MAE", scaled(m.get("mae"), 1e6), "µm"))
            rows.append(
                (f"{label} 90 % interval coverage", share(m.get("interval_coverage"), "runs"), "")
            )
            rows.append(
                (f"{label} mean interval width", scaled(m.get("mean_interval_width"), 1e6), "µm")
            )
    for key, label in (("fault_cv", "fault CV"), ("fault_test", "fault held-out")):
        if metrics.get(key):
            rows.append(
                (f"{label} {F1_CLASSIFIER}", scaled(metrics[key].get("macro_f1_classifier")), "")
            )
    shipped = (metrics.get("fault_model") or {}).get("candidate")
    for name, cv in (metrics.get("fault_candidates") or {}).items():  # the same folds each
        label = f"fault CV macro-F1, {cv['model']}"
        rows.append((label, scaled(cv.get("macro_f1")), "shipped" if name == shipped else ""))
    return rows


# ----------------------------------------------------------------------------- evaluate
def evaluate(args) -> int:
    bundle = load_bundle(args.model)
    dataset = Dataset(args.dataset)
    report, records = evaluate_model(bundle, dataset, split=args.split, progress=not args.json)
    if args.plot:
        report["figures"] = [str(p) for p in plot_evaluation(report, records, args.plot)]
    if args.json:
        print_json(report)
        return 0
    print_table(evaluation_rows(report))
    return 0


def evaluation_rows(report: dict) -> list:
    """The table of ``evaluate``: the model, the dataset, and the metrics of the report."""
    rows = [
        ("model", f"{report['model']['name']} v{report['model']['version']}", ""),
        ("dataset", f"{report['dataset']} ({report['split']}: {report['runs']} runs)", ""),
    ]
    if "clearance" in report:
        c = report["clearance"]
        rows += [
            ("clearance MAE", scaled(c["mae"], 1e6), "µm"),
            ("clearance 90 % interval coverage", share(c["coverage"], "runs"), ""),
            ("clearance mean interval width", scaled(c["mean_width"], 1e6), "µm"),
            ("clearance observable", share(c["observable_fraction"], "runs"), ""),
        ]
    if "fault" in report:
        f = report["fault"]
        rows += [
            (F1_CANNOT_TELL_MISS, scaled(f["macro_f1_all"]), ""),
            (F1_NAMED, scaled(f["macro_f1_named"]), ""),
            ("cannot_tell", share(f["cannot_tell_fraction"], "runs"), ""),
        ]
        rows += [(f"F1({k})", v, "") for k, v in f["f1_by_class"].items()]
    rows.append(("out of distribution", share(report["ood"]["flagged_fraction"], "runs"), ""))
    rows += [("figure", p, "") for p in report.get("figures", [])]
    return rows


# ----------------------------------------------------------------------------- diagnose
def diagnose(args) -> int:
    _check_asset_options(args)
    bundle = load_bundle(args.model)
    run = read_recording(args.file, column_map=args.map)
    if args.asset is None:
        result = diagnose_recording(run, bundle, window=args.window)
    else:
        store = FileAssetStore(args.store)
        if args.as_built_clearance is not None:
            commission(store, args.asset, args.as_built_clearance)
        result = diagnose_asset(
            run,
            bundle,
            store,
            args.asset,
            content_id(args.file, args.map),
            healthy=True if args.healthy else (False if args.unhealthy else None),
            operating_hours=args.operating_hours,
            time=args.time if args.time is not None else _modified(args.file),
            window=args.window,
            source="file",
            filename=Path(args.file).name,
        )
    if args.plot and result.check_phases:  # a check read phase by phase: no windows to draw
        plot_check_result(run, result, args.plot, design=bundle.design)
    elif args.plot:
        plot_diagnosis(result, args.plot)
    if args.json:
        print_json(result.to_json())
        return 0
    print_table(diagnosis_rows(args.file, result))
    return 0


def _check_asset_options(args) -> None:
    """The options that describe the recording's asset need ``--asset``."""
    if getattr(args, "asset", None) is not None:
        return
    given = [
        option
        for option, value in (
            ("--healthy", getattr(args, "healthy", False)),
            ("--unhealthy", getattr(args, "unhealthy", False)),
            ("--operating-hours", getattr(args, "operating_hours", None) is not None),
            ("--as-built-clearance", getattr(args, "as_built_clearance", None) is not None),
            ("--time", getattr(args, "time", None) is not None),
        )
        if value
    ]
    if given:
        raise PRSMHealthError(f"{given[0]} describes the recording's asset: give --asset ID")


def _modified(file: str) -> str:
    """The file's modification time, ISO 8601 in UTC to the second."""
    stamp = datetime.fromtimestamp(Path(file).stat().st_mtime, tz=timezone.utc)
    return stamp.isoformat(timespec="seconds")


def diagnosis_rows(file: str, result) -> list:
    """The table of ``diagnose``: a recording's :class:`Diagnosis` in words."""
    c = result.clearance
    clearance = (
        f"{um(c['estimate'])} [{um(c['lower'])}, {um(c['upper'])}]",
        "µm (90 % interval)",
    )
    hidden = not_observable_text(result, "clearance")
    rows = [
        ("file", file, ""),
        ("fault class", result.fault_class, ""),
        ("class set", ", ".join(result.class_set), "  not ruled out (90 %)"),
        ("clearance", *((hidden, "") if hidden else clearance)),
    ]
    rows += measured_rows(getattr(result, "measured_clearance", None))
    hidden = not_observable_text(result, "fault")
    if hidden and result.class_probabilities:  # one row, not a P(…) per class
        rows.append(("class probabilities", hidden, ""))
    else:
        rows += [(f"P({k})", v, "") for k, v in result.class_probabilities.items()]
    u = getattr(result, "undecided", None)
    if u is not None:
        told = ", ".join(u.missing or u.candidates)
        rows += [("cannot tell", u.kind.replace("_", " "), f"  ({told})" if told else "")]
        rows += [("record next", u.next_recording, "")]
    if getattr(result, "check_phases", None):  # a check read phase by phase: no windows
        seen = result.observability
        rows += [
            ("check phases", f"{role}: {phase}", "") for role, phase in result.check_phases.items()
        ]
        rows += [
            ("clearance observable", "yes" if seen.get("clearance") else "no", ""),
            ("class observable", "yes" if seen.get("fault") else "no", ""),
        ]
    else:
        rows += [
            ("clearance observable", share(result.observability.get("clearance"), "windows"), ""),
            ("class observable", share(result.observability.get("fault"), "windows"), ""),
            ("out-of-distribution score", ood_verdict(result), ""),
            ("windows", len(result.windows), ""),
        ]
    rows += [("model", f"{result.model['name']} v{result.model['version']}", "")]
    rows += asset_rows(getattr(result, "asset", None))
    rows += [("warning", text, "") for text in result.warnings]
    return rows


def measured_rows(measured) -> list:
    """How a check's clearance was measured (physics) and the learnt reading beside it."""
    if measured is None:
        return []
    how = f"{len(measured.reversals)} reversal(s)"
    if measured.stiffness_factor is not None:
        how += f" to zero load (stiffness ×{measured.stiffness_factor:.2f})"
    how += ", commissioned" if measured.commissioned else ", not commissioned"
    rows = [("clearance measured by", f"lost motion: {how}", "")]
    learnt = measured.learnt
    if learnt is not None and learnt.estimate is not None:
        agree = "agrees" if measured.agree else "DISAGREES"
        rows.append(
            (
                "learnt clearance",
                f"{um(learnt.estimate)} [{um(learnt.lower)}, {um(learnt.upper)}]",
                f"µm (cross-check: {agree})",
            )
        )
    return rows


#: Changes shown in the table of ``diagnose --asset`` (the JSON has them all).
SHOWN_CHANGES = 3


def asset_rows(asset) -> list:
    """The asset part of the ``diagnose`` table: the baseline (how full, the distance and the
    largest changes), the accumulated evidence and the change statistic."""
    if asset is None:
        return []
    rows = [("asset", asset.asset_id, "")]
    b, e = asset.baseline, asset.evidence
    if b is not None and b.recordings < b.needed:
        rows.append(("baseline", f"{b.recordings} of {b.needed} recordings", "(incomplete)"))
    elif b is not None:
        rows.append(("baseline", f"{b.recordings} recordings", ""))
        rows.append(
            ("baseline distance", scaled(b.distance), "(RMS of robust z; about 1: like it)")
        )
        for name, z in list(b.changes.items())[:SHOWN_CHANGES]:
            rows.append((f"change of {name}", f"{z:+.2f}", "robust z"))
    if e is not None and e.recordings == 0:
        rows.append(("evidence", "none yet", "(baseline recordings add none)"))
    elif e is not None:
        rows.append(("evidence", f"{e.recordings} recordings", ""))
        rows += [(f"posterior({k})", v, "") for k, v in e.posterior.items()]
        rows.append(("asset class", e.fault_class, ""))
    if e is not None and e.change_statistic is not None:
        alarm = "  ALARM: changed from its baseline" if e.change_alarm else ""
        rows.append(("change statistic", f"{e.change_statistic:.3g}", f"(CUSUM){alarm}"))
    return rows


# ----------------------------------------------------------------------------- replay
def replay(args) -> int:
    if args.live and (args.out or args.json):
        raise PRSMHealthError("--live plays the recording to Foxglove: drop --out and --json")
    bundle = None if args.statistics_only else load_bundle(args.model)
    window = args.window or (bundle.window if bundle else 1.0)
    if args.live:
        return play_live(args.file, args, bundle, window, rate=getattr(args, "rate", 1.0))
    steps = []
    rate = getattr(args, "rate", None)
    for step in replay_windows(args.file, bundle, window=window, rate=rate, out=args.out):
        steps.append(step.to_json())
        if not args.json:
            print(_replay_line(steps[-1]))
    if args.json:
        print_json({"file": args.file, "window": window, "windows": steps, "out": args.out})
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
        shown = not_observable_text(d, "clearance")
        shown = shown or f"{um(c['estimate'])} µm [{um(c['lower'])}, {um(c['upper'])}]"
        return head + f"{d['fault_class']:<12} clearance {shown}"
    ax = entry["statistics"].get("nut_axial_accel", {})
    return (
        head
        + f"axial rms {ax.get('rms', float('nan')):.4g} m/s²  "
        + f"peak {ax.get('peak', float('nan')):.4g} m/s²"
    )
