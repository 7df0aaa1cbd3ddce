"""The shipped prognostics model's card (``models/PROGNOSTICS_CARD.md``), rendered from its
metrics file (``models/prognostics.metrics.json``,
:func:`~prsm_health.release.prognostics_model.prognostics_metrics`) alone. Every number in it is
measured; the prose describes the shipped fleet recipe. Tables and number formats are those of
every card (:mod:`.cards`)."""

from __future__ import annotations

from pathlib import Path

from prsm_health.release.cards import fixed, header, table, write_card

#: The tool that measures the card's numbers.
TOOL = "tools/release/train_prognostics_model.py"

#: Columns of a metrics table, and how each method's summary fills them.
_METRICS_HEADER = (
    "method",
    "α–λ accuracy (α = 0.2), after half of life",
    "α–λ accuracy, whole life",
    "90 % coverage after half of life",
    "coverage, all",
    "RMSE after half of life [h]",
    "RMSE, all [h]",
    "prognostic horizon (mean; stay / first entry) [h]",
    "CRA",
    "monotonicity",
    "predictions",
)


def _indicator_words(fleet: dict) -> str:
    """What the model's health indicator is, for the fleet it was trained on."""
    if fleet["check"]:
        return (
            "the clearance a health check measures from its reversals' lost motion (the "
            "clearance gauge, each unit commissioned by its first check), with its 90 % interval"
        )
    return "the diagnosed clearance of in-service windows (mean of screw and nut half-clearances)"


def _indicator_errors(indicator: dict) -> str:
    """The fleet's diagnosed clearance against the truth, in words."""
    return (
        f"bias {indicator['bias'] * 1e6:+.2f} µm, sd {indicator['sd'] * 1e6:.2f} µm, unit bias sd "
        f"{indicator['unit_bias_sd'] * 1e6:.2f} µm, 90 % intervals covering "
        f"{indicator['coverage']:.2f}"
    )


def _metrics_table(summary: dict) -> str:
    return table(
        _METRICS_HEADER,
        (
            [
                method,
                fixed(s["alpha_lambda"]),
                fixed(s["alpha_lambda_all"]),
                fixed(s["coverage_after"]),
                fixed(s["coverage"]),
                fixed(s["rmse_after"], 0),
                fixed(s["rmse"], 0),
                f"{fixed(s['prognostic_horizon'], 0)} / {fixed(s['prognostic_horizon_first'], 0)}",
                fixed(s["cra"]),
                fixed(s["monotonicity"]),
                s["n_predictions"],
            ]
            for method, s in summary.items()
        ),
    )


def _accuracy_by_age_table(by_age: dict) -> str:
    return table(
        ["method", *(f"{lo:.0%}–{hi:.0%} of life" for lo, hi in by_age["bins"])],
        ([method, *(fixed(c, 2) for c in cells)] for method, cells in by_age["methods"].items()),
    )


def _per_unit_table(rows: list[dict]) -> str:
    return table(
        ["unit", "life [h]", "failure mode", "α–λ accuracy", "coverage", "RMSE [h]"],
        (
            [
                r["unit"],
                fixed(r["life_hours"], 0),
                r["failure_mode"],
                fixed(r["alpha_lambda"], 2),
                fixed(r["coverage"], 2),
                fixed(r["rmse"], 0),
            ]
            for r in rows
        ),
    )


def _sensitivity_table(limits: dict) -> str:
    def cell(c):
        d, s = c["degradation"], c["similarity"]
        return (
            f"{fixed(d['alpha_lambda'], 2)} / {fixed(s['alpha_lambda'], 2)} — "
            f"{fixed(d['coverage_after'], 2)} / {fixed(s['coverage_after'], 2)}"
        )

    return table(
        ["usage σ", *(f"indicator σ {n * 1e6:g} µm" for n in limits["noise"])],
        ([f"{u:g}", *map(cell, row)] for u, row in zip(limits["usage"], limits["cells"])),
    )


def write_prognostics_card(metrics: dict, card_path: str | Path) -> Path:
    """Write :func:`prognostics_card` of ``metrics`` to ``card_path``; returns the path."""
    return write_card(card_path, prognostics_card(metrics))


def prognostics_card(metrics: dict) -> str:
    """The prognostics card (Markdown) from
    :func:`~prsm_health.release.prognostics_model.prognostics_metrics`' numbers."""
    model, fleet = metrics["model"], metrics["fleet"]
    cross = metrics["cross_validated"]
    generation = fleet["generation"]
    lives = fleet["lives_hours"]
    n_test = len(fleet["test_units"])
    if generation["seconds"] is None:  # partly generated before: its time is not the whole's
        generated = "generation timed in docs/prognostics.md"
    else:
        generated = f"generated in {generation['seconds']:.0f} s on {generation['workers']} workers"
    figures = ", ".join(f"[{Path(name).stem}](figures/{name})" for name in metrics["figures"])
    lines = [
        header("Prognostics card — `models/prognostics.json`", TOOL),
        "**What it is.** The default model of `prsm-health prognose` and of the service's "
        "`GET /v1/assets/{id}/prognosis`: remaining useful life [h] with a 90 % interval from a "
        "history of diagnoses of one asset over its operating hours, for a paper-01 PRSM "
        "measured by the `flight-ema` instrumentation and diagnosed by the default model "
        f"(`models/default.skops`). Health indicator: {_indicator_words(fleet)}. Methods: "
        f"the degradation model (`{model['form']}` form with Bayesian updating, Gebraeel et "
        "al. 2005); the similarity baseline (Wang et al. 2008); "
        "and `physics`: the PRSM's ageing as a NASA progpy model — "
        "Archard wear of the thread contacts speeding up as the lubricant depletes, the unit's "
        "wear and lubricant-life factors estimated by progpy's particle filter on the "
        "diagnoses (each weighted by its own 90 % interval as the measurement's noise, the "
        "logged duty as input), progpy's Monte Carlo prediction to the wear limit "
        f"(docs/prognostics.md). Default method: **`{model['method']}`**, the one with the best "
        "α–λ accuracy after half of life over every unit of the fleet (cross-validated, below).",
        "",
        f"**Data.** `datasets/{fleet['recipe']}.toml`: {fleet['units']} units × "
        f"{fleet['snapshots']} ages × {fleet['recordings']} "
        f"{'health check' if fleet['check'] else 'recording'}{'s' if fleet['recordings'] > 1 else ''}"
        f" of {fleet['duration']:g} s "
        f"({generation['runs']} runs"
        f"; {generated}). Each unit wears by Archard wear of its thread contacts, "
        "faster as its lubricant's additives deplete, with unit-to-unit scatter of build, wear "
        "coefficient, lubricant life, temperature, loads and a wandering usage intensity "
        "(docs/prognostics.md); it fails when its installed clearance (the threads' mean "
        "half-clearance plus its assembly's play: what a check's zero-load lost motion reads) "
        "reaches "
        f"{fleet['failure_clearance'] * 1e6:g} µm or a spall grows "
        f"{fleet['failure_spall_length'] * 1e3:g} mm long. Lives {lives[0]:.0f}–{lives[1]:.0f} h; "
        "failure modes "
        + ", ".join(f"{k} {v}" for k, v in fleet["failure_modes"].items())
        + f". Trained on {len(fleet['train_units'])} units, scored on the {n_test} held-out "
        f"units ({fleet['test_units']}): run seeds never used in training, every prefix of "
        "their histories (≥ 2 diagnoses) predicted on its own.",
        "",
        f"**Threshold.** The model's threshold is on the diagnosed clearance: "
        f"{model['threshold'] * 1e6:.2f} µm, the diagnosed clearance at failure learnt from the "
        f"training units (the true limit is {fleet['failure_clearance'] * 1e6:g} µm plus the "
        "diagnosis' median bias over their last quarter of life).",
        "",
        "## Metrics on the held-out units (Saxena et al. 2010)",
        "",
        _metrics_table(metrics["held_out"]),
        "",
        f"## Every unit held out once ({cross['folds']} folds over the {fleet['units']} units)",
        "",
        "Each unit predicted by a model fitted on the other folds' units "
        "(`prsm_health.prognostics.cross_validate_units`, what the default method is chosen "
        f"by): a score on every unit, where the held-out split above scores {n_test}.",
        "",
        _metrics_table(cross["summary"]),
        "",
        "α–λ accuracy by age (every unit's predictions): the bound ±0.2·RUL narrows to the "
        "end of life, where the clearance is read with the diagnosis' scatter and its "
        "unit-to-unit bias.",
        "",
        _accuracy_by_age_table(cross["accuracy_by_age"]),
        "",
        "Between 50 and 80 % of life, pooled: "
        + ", ".join(f"{m} {fixed(v, 3)}" for m, v in cross["alpha_lambda_50_80"].items())
        + ".",
        "",
        "Prognostic horizon: *stay* from the first prediction after which every one stays "
        "within ±α·life of the true RUL, *first entry* from the first one inside "
        "(progpy's `prognostic_horizon`); CRA, the cumulative relative accuracy (Saxena "
        "§6.3), and monotonicity of the predicted RUL through progpy "
        "(`prsm_health.prognostics.metrics`).",
        "",
        f"### Per held-out unit (default method `{model['method']}`, after half of life)",
        "",
        _per_unit_table(metrics["per_unit"]),
        "",
        "### What limits it: usage variability and indicator noise",
        "",
        "The life model's own trajectories (60 units, 40 fitted, 20 scored; no dynamics), "
        "observed with Gaussian errors of σ (this fleet's diagnoses: "
        f"{_indicator_errors(metrics['indicator'])}; an in-service window's ≈ 2 µm); cells: "
        "α–λ accuracy degradation / "
        "similarity — 90 % coverage degradation / similarity, after half of life.",
        "",
        _sensitivity_table(metrics["sensitivity"]),
        "",
        "Reading it: the first column is the models' own error with a perfect indicator — for "
        "the degradation model, the misfit of one fleet-wide baseline φ to units whose initial "
        "clearance and wear amplitude differ (its intervals are then too narrow); the other "
        "columns add the diagnosis' scatter, which at the end of life, where the clearance "
        "grows by 0.01–0.02 µm/h, is worth ±100–200 h against an α bound of ±0.2·RUL. The usage "
        "rows add the unpredictable future of a unit's usage.",
        "",
        f"Figures: {figures}.",
        "",
        "## What it cannot do",
        "",
        "- A spall's start is random (rolling-contact fatigue, ISO 281 scatter) and the "
        "diagnosis rarely sees a young spall: a unit that fails by a spall before it wears out "
        "is predicted as if it would wear out (its RUL overestimated). The fleet recipe's duty "
        "makes such failures rare; a heavier duty would not.",
        "- One duty cycle family, one design, one instrumentation: another actuator needs its "
        f"own fleet recipe and `{TOOL}` run on it.",
        "- The health indicator is the clearance alone; lubricant degradation and spall "
        "probabilities of the diagnosis are not used.",
        *(
            [
                "- Its accuracy is that of commissioned health checks: an asset needs its "
                "as-built clearance (`diagnose --asset ID --as-built-clearance B`, or the "
                "service's `PUT /v1/assets/{id}/commissioning`) and its checks; without "
                "commissioning a check reads ≈ 1 µm (sd) off, and in-service windows ≈ 2 µm — "
                "the limits table above shows what that costs."
            ]
            if fleet["check"]
            else []
        ),
    ]
    return "\n".join(lines) + "\n"
