"""The options of the dataset commands (:mod:`.data`): generate, import."""

from __future__ import annotations

from .options import add_json, finite_float


def add_data_commands(command) -> None:
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
    add_json(g, "the generation report")
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
    add_json(i, "the summary")
    i.set_defaults(handler="data:import_recordings")
