"""``prsm-health prognose``: a history file, or a fleet dataset's unit → remaining useful
life."""

from __future__ import annotations

import sys
from pathlib import Path

from prsm_health.core.errors import PRSMHealthError
from prsm_health.diagnostics.diagnosis import load_bundle
from prsm_health.prognostics import (
    fleet_histories,
    load_prognostics_model,
    read_history,
)
from prsm_health.prognostics import (
    prognose as prognose_history,
)

from .output import hours, print_json, print_table, um

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


def _prognosis_rows(args, prognosis, history, true_rul) -> list:
    rul, hi, m = prognosis.rul_hours, prognosis.health_indicator, prognosis.model
    latest = history.iloc[-1]  # the latest diagnosis, with its own (maybe uneven) interval
    ages = hi["ages_hours"]
    source = f"{args.source}, unit {args.unit}" if args.unit is not None else args.source
    rows = [
        ("history", source, ""),
        ("diagnoses", f"{len(ages)} from {hours(ages[0])} to {hours(ages[-1])}", "h"),
        (
            "RUL",
            f"{hours(rul['estimate'])} [{hours(rul['lower'])}, {hours(rul['upper'])}]",
            "h (median, 90 % interval)",
        ),
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
