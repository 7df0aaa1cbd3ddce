"""The options of ``prognose`` (:mod:`.prognose`)."""

from __future__ import annotations

from .assets_options import add_store
from .options import SHIPPED_MODEL, add_json, finite_float

#: ``prognose --method``'s choices (prognostics.METHODS, which imports pandas and scipy).
PROGNOSIS_METHODS = (
    "degradation",
    "similarity",
    "physics",
    "degradation-exponential",
    "degradation-linear",
)


def add_prognose_command(command) -> None:
    g = command(
        "prognose",
        "remaining useful life from a history of diagnoses, or of a fleet dataset's unit",
    )
    g.add_argument(
        "source",
        nargs="?",
        default=None,
        metavar="HISTORY_OR_DATASET",
        help="history table (.csv or .parquet: age_hours, clearance, clearance_lower, "
        "clearance_upper [h, m]; optional design, fault_class, unit_id), or a fleet dataset "
        "directory or URL (prsm-health generate on a recipe with [life]) with --unit; or none "
        "with --asset",
    )
    g.add_argument(
        "--asset",
        default=None,
        metavar="ID",
        default_text="none",
        help="an asset recorded with diagnose --asset ... --operating-hours H: its stored "
        "diagnoses in --store are the history (the service's prognosis of the same asset "
        "reads the same way)",
    )
    add_store(g)
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
    add_json(g, "the prognosis")
    g.set_defaults(handler="prognose:prognose")
