"""The options of the asset commands (:mod:`.assets`) and the asset options of ``diagnose``."""

from __future__ import annotations

import argparse
import re
from datetime import datetime

from prsm_health.core.identifiers import ASSET_ID_PATTERN, ASSET_ID_RULE

from .options import add_json, command_maker, finite_float

#: The asset histories of ``diagnose --asset`` and ``asset`` when ``--store`` is not given.
DEFAULT_ASSET_STORE = "prsm-assets"


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


def add_store(p) -> None:
    p.add_argument(
        "--store",
        default=DEFAULT_ASSET_STORE,
        default_text=f"./{DEFAULT_ASSET_STORE}, in the current directory",
        metavar="DIR",
        help="directory of the asset histories, one JSON file per asset (created)",
    )


def add_asset_commands(command) -> None:
    action = command_maker(
        command("asset", "units recorded with diagnose --asset: baseline, evidence, changes"),
        "action",
    )
    s = action("show", "an asset's baseline, evidence and change statistic over its recordings")
    s.add_argument("asset", type=asset_id, metavar="ID", help="the asset id")
    add_store(s)
    s.add_argument(
        "--model",
        default=None,
        default_text="none: each indicator's scale from the unit's recordings alone",
        help="model bundle whose baseline indicators and within-unit repeatability the "
        "baseline's scales use, as diagnose --asset uses them (--json shows the scales)",
    )
    add_json(s, "the asset's history report")
    s.set_defaults(handler="assets:show")
    s = action("list", "the assets in the store")
    add_store(s)
    add_json(s, "the asset ids")
    s.set_defaults(handler="assets:list_assets")
