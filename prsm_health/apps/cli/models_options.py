"""The options of the model commands (:mod:`.models`): train, evaluate, diagnose, replay."""

from __future__ import annotations

import argparse

from .assets_options import add_store, asset_id, iso_time, non_negative_float
from .live_options import add_live_options
from .options import MODEL_WINDOW, SHIPPED_MODEL, add_json, finite_float, rate

#: ``train --target``: the diagnosis models' targets (prsm_health.training.train), and
#: ``rul``, a prognostics model of a fleet dataset.
TRAIN_TARGETS = ("clearance", "fault", "both", "rul")
#: ``train --cv`` when not given.
DEFAULT_CV = 5


def add_model_commands(command) -> None:
    t = command(
        "train",
        "train the clearance estimator and fault classifier on a dataset, a model's health-check "
        "part on a dataset of health checks, or a prognostics model on a fleet dataset "
        "(--target rul)",
    )
    t.add_argument(
        "dataset",
        help="dataset directory or URL (prsm-health generate); of health checks (a recipe with "
        "[units] and [profile] check): the check part, clearance and class together",
    )
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
        default_text=f"{DEFAULT_CV}; health checks: the check part's, by unit",
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
    t.add_argument(
        "--baseline",
        default=None,
        metavar="DATASET",
        default_text="required with a dataset of health checks",
        help="a dataset of health checks: the same units' checks when new and healthy (the same "
        "[units]), what each check is read against (docs/diagnostics.md)",
    )
    t.add_argument(
        "--window-model",
        default=None,
        metavar="BUNDLE",
        default_text="a bundle with the check part only",
        help="a dataset of health checks: the window model (.skops) of the same design that --out "
        "becomes a copy of, with the check part beside it (--out BUNDLE itself: added in place)",
    )
    add_json(t, "the metrics")
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
    add_json(e, "the metrics")
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
        help="write a PNG of the per-window estimates (a health check: of each phase with its "
        "reading and verdict)",
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
    add_store(d)
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
        "--as-built-clearance",
        type=finite_float,
        default=None,
        metavar="B",
        default_text="not given",
        help="--asset: the unit's thread half-clearance as built, measured at assembly [m], "
        "e.g. 6e-6 — given once, at commissioning: its baseline checks then fix the constant "
        "lost motion of its drive (bearing play, gearhead backlash, sensor lag) and the "
        "clearance a check measures narrows to the unit's own (docs/diagnostics.md)",
    )
    d.add_argument(
        "--time",
        type=iso_time,
        default=None,
        metavar="ISO",
        default_text="the file's modification time",
        help="--asset: when the recording was made (ISO 8601)",
    )
    add_json(d, "the Diagnosis contract")
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
    add_json(r, "every window")
    add_live_options(r, rate_option=False)
    r.set_defaults(handler="models:replay")
