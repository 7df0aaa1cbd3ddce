"""Commands on the asset histories of ``diagnose --asset``: ``asset show``, ``asset list``."""

from __future__ import annotations

from prsm_health.core.errors import PRSMHealthError
from prsm_health.monitoring import FileAssetStore, bundle_priors

from .output import print_columns, print_json, print_table

#: The columns of ``asset show``'s recordings table.
COLUMNS = (
    "recording",
    "time",
    "hours",
    "baseline",
    "distance",
    "leading class",
    "posterior",
    "named",
    "CUSUM",
)


def show(args) -> int:
    store = FileAssetStore(args.store)
    if args.asset not in store.asset_ids():
        raise PRSMHealthError(
            f"no asset {args.asset!r} in {store.directory} (prsm-health asset list --store "
            f"{store.directory})"
        )
    prior_scale = names = None
    if args.model is not None:
        # the model's dependencies (scikit-learn …) only when a model is given
        from prsm_health.diagnostics.diagnosis import load_bundle

        prior_scale, _, names = bundle_priors(load_bundle(args.model))
    report = store.load(args.asset).history.report(prior_scale, names)
    if args.json:
        print_json(report)
        return 0
    print_table(summary_rows(report))
    print()
    print_columns(COLUMNS, recording_rows(report))
    return 0


def summary_rows(report: dict) -> list:
    """The head of ``asset show``: the asset, its baseline, its evidence and change
    statistic now."""
    b, e, c = report["baseline"], report["evidence"], report["change"]
    rows = [
        ("asset", report["asset_id"], ""),
        ("recordings", report["recordings"], ""),
        (
            "baseline",
            f"{b['recordings']} of {b['needed']} recordings"
            if not b["complete"]
            else f"{b['recordings']} recordings, {len(b['indicators'])} indicators",
            "" if b["complete"] else "(incomplete)",
        ),
        ("evidence", f"{e['recordings']} recordings", ""),
    ]
    rows += [(f"posterior({k})", v, "") for k, v in e["posterior"].items()]
    rows.append(
        ("asset class", e["fault_class"], f"(named at posterior ≥ {e['name_probability']:g})")
    )
    rows.append(
        (
            "change statistic",
            f"{c['statistic']:.3g}",
            f"(CUSUM, k = {c['reference']:g}, alarm above {c['threshold']:g})"
            + ("  ALARM: changed from its baseline" if c["alarm"] else ""),
        )
    )
    return rows


def recording_rows(report: dict) -> list[tuple]:
    """One row per recording of ``asset show``, oldest first."""
    return [
        (
            r["filename"] or r["source"] or r["recording_id"],
            r["time"] or None,
            r["operating_hours"],
            "yes" if r["baseline"] else "no",
            r["distance"],
            r["leading_class"],
            r["leading_posterior"],
            r["named"],
            r["change_statistic"],
        )
        for r in report["entries"]
    ]


def list_assets(args) -> int:
    assets = FileAssetStore(args.store).asset_ids()
    if args.json:
        print_json(assets)
        return 0
    if not assets:
        print(f"no assets in {args.store}")
    for asset_id in assets:
        print(asset_id)
    return 0
