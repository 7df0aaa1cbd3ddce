"""``prsm-health prognose``: a history file, or a fleet dataset's unit → remaining useful
life; ``prsm-health train --target rul``: a prognostics model fitted on a fleet dataset."""

from __future__ import annotations

import sys
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.monitoring import FileAssetStore, validate_asset_id
from prsm_health.prognostics import (
    fit_prognostics_model,
    fleet_histories,
    load_prognostics_model,
    prognose_readings,
    read_history,
    save_prognostics_model,
)
from prsm_health.prognostics import (
    prognose as prognose_history,
)

from .output import hours, print_json, print_table, scaled, share, um

#: The options that only a fleet dataset takes.
FLEET_OPTIONS = (
    ("--unit", "unit"),
    ("--until-age", "until_age"),
    ("--diagnosis-model", "diagnosis_model"),
)


def is_dataset(source: str) -> bool:
    """A fleet dataset (a directory, or an object-store URL) rather than a history file."""
    return "://" in source or Path(source).is_dir()


def prognose(args) -> int:
    if args.asset is not None:
        return _prognose_asset(args)
    if args.source is None:
        raise PRSMHealthError(
            "prognose needs a history table, a fleet dataset with --unit, or --asset ID"
        )
    fleet = is_dataset(args.source)
    if not fleet:
        for option, name in FLEET_OPTIONS:
            if getattr(args, name) is not None:
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
    prognosis = prognose_history(history, model, args.method)
    if args.json:
        print_json(prognosis.as_dict())
        return 0
    print_table(_prognosis_rows(args, prognosis, history, true_rul))
    return 0


def _prognose_asset(args) -> int:
    """The prognosis of an asset recorded with ``diagnose --asset`` (its stored diagnoses with
    operating hours), as the service makes it (:func:`prognose_readings`)."""
    if args.source is not None:
        raise PRSMHealthError(
            f"--asset reads the asset's stored diagnoses: give no history or dataset "
            f"({args.source})"
        )
    for option, name in FLEET_OPTIONS:
        if getattr(args, name) is not None:
            raise PRSMHealthError(f"{option} applies to a fleet dataset, not to --asset")
    model = load_prognostics_model(args.model)
    store = FileAssetStore(args.store)
    asset = validate_asset_id(args.asset, "--asset")
    if asset not in store.asset_ids():
        raise PRSMHealthError(
            f"no asset {asset!r} in {args.store} (diagnose its recordings with --asset "
            f"{asset} --operating-hours H first)"
        )
    rows = store.load(asset).history.operating_history()
    prognosis, history = prognose_readings(rows, model, args.method, asset=f"asset {asset!r}")
    if args.json:
        print_json(prognosis.as_dict())
        return 0
    print_table(_prognosis_rows(args, prognosis, history, None))
    return 0


def _prognosis_rows(args, prognosis, history, true_rul) -> list:
    hi, m = prognosis.health_indicator, prognosis.model
    latest = history.iloc[-1]  # the latest diagnosis, with its own (maybe uneven) interval
    ages = hi["ages_hours"]
    source = f"{args.source}, unit {args.unit}" if args.unit is not None else args.source
    if args.asset is not None:
        source = f"asset {args.asset} ({args.store})"
    rows = [
        ("prognosis", prognosis.headline.text, ""),  # what a maintainer reads, one rule
        ("history", source, ""),
        ("diagnoses", f"{len(ages)} from {hours(ages[0])} to {hours(ages[-1])}", "h"),
        ("RUL", prognosis.headline.short, "(median, 90 % interval)"),
    ]
    if true_rul is not None:
        rows.append(("true RUL", hours(true_rul), "h (the simulator's truth, dataset labels)"))
    rows += [
        (
            "clearance now",
            f"{um(hi['current']).strip()} [{um(float(latest['clearance_lower'])).strip()}, "
            f"{um(float(latest['clearance_upper'])).strip()}]",
            "µm (90 % interval)",
        ),
        ("failure threshold", um(hi["threshold"]).strip(), "µm"),
        ("method", m["name"], ""),
        ("model", f"{m['design']}, {m['units_trained']} training units, v{m['version']}", ""),
    ]
    rows += [("warning", text, "") for text in prognosis.warnings]
    return rows


# ----------------------------------------------------------------------------- train --target rul
#: The options of ``train`` that only ``--target rul`` takes, and those it does not.
RUL_OPTIONS = (("--model", "model"), ("--threshold", "threshold"))
DIAGNOSIS_OPTIONS = (("--cv", "cv"), ("--baseline", "baseline"), ("--window-model", "window_model"))


def check_train_options(args) -> None:
    """Options of ``train`` given with a target they do not apply to: one sentence."""
    rul = args.target == "rul"
    for option, name in DIAGNOSIS_OPTIONS if rul else RUL_OPTIONS:
        if getattr(args, name) is not None:
            applies = "clearance, fault or both" if rul else "rul"
            raise PRSMHealthError(
                f"{option} applies to --target {applies}, not to --target {args.target}"
            )


def train_prognostics(args) -> int:
    """``train FLEET --target rul``: fit, save, print the report (a table, or ``--json``)."""
    if Path(args.out).suffix != ".json":
        raise PRSMHealthError(f"--out {args.out}: a prognostics model is a .json file")
    if args.threshold is not None and args.threshold <= 0:
        raise PRSMHealthError(f"--threshold {args.threshold:g} must be a clearance > 0 [m]")
    bundle = None if args.model is None else load_bundle(args.model)
    model, report = fit_prognostics_model(
        args.dataset,
        bundle=bundle,
        threshold=args.threshold,
        progress=not args.json and sys.stderr.isatty(),  # a person is watching
    )
    out = save_prognostics_model(args.out, model)
    result = {"model": str(out), **report.as_dict()}
    if args.json:
        print_json(result)
        return 0
    print_table(fit_rows(result))
    return 0


def fit_rows(report: dict) -> list:
    """The table of ``train --target rul``: the model file, its design, the data, the
    threshold and each method's held-out score."""
    fingerprint = report["design_fingerprint"]
    rows = [
        ("model", report["model"], ""),
        ("design", report["design"] + (f" ({fingerprint})" if fingerprint else ""), ""),
        (
            "units",
            f"{len(report['train_units'])} training, {len(report['test_units'])} held out",
            f"({report['snapshots']} snapshots)",
        ),
        (
            "failure threshold",
            um(report["threshold"]).strip(),
            "µm diagnosed clearance"
            + (", learnt from the training units" if report["threshold_learnt"] else ", given"),
        ),
    ]
    if report["true_failure_clearance"] is not None:
        rows.append(
            ("true failure clearance", um(report["true_failure_clearance"]).strip(), "µm (recipe)")
        )
    for method, metrics in report["summary"].items():
        # a metric with nothing to count (no prediction late in life) is NaN: shown as "–"
        m = {k: None if v is None or v != v else v for k, v in metrics.items()}
        rows += [
            (f"{method} held-out RMSE", scaled(m.get("rmse")), "h"),
            (
                f"{method} α–λ accuracy",
                share(m.get("alpha_lambda"), "predictions"),
                "(in the second half of life)",
            ),
            (f"{method} 90 % interval coverage", share(m.get("coverage"), "predictions"), ""),
            (f"{method} prognostic horizon", scaled(m.get("prognostic_horizon")), "h"),
        ]
    if not report["summary"]:
        rows.append(("held-out score", "–", "no held-out units"))
    return rows
