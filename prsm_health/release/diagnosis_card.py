"""The shipped diagnosis model's card (``models/MODEL_CARD.md``), rendered from its metrics
file (``models/default.metrics.json``) alone: :func:`model_card` for the window model
(:func:`~prsm_health.release.diagnosis_model.train_default_model`'s numbers) and
:func:`check_card_section` for the health-check part
(:func:`~prsm_health.training.check_evaluation.evaluate_check_model`'s numbers). Every number in
it is measured; the prose describes the shipped recipe. Tables and number formats are those of
every card (:mod:`.cards`)."""

from __future__ import annotations

from pathlib import Path

from prsm_health.diagnostics.diagnosis import OOD_LIMIT
from prsm_health.release.cards import MISSING, fixed, header, table, um, write_card
from prsm_health.training.check_evaluation import (
    EVAL_STATES,
    SENSITIVITY_FACTORS,
    observable_states,
)

#: The tool that measures the window model's numbers.
TOOL = "tools/release/train_default_model.py"


def write_model_card(metrics: dict, model_path: str | Path, card_path: str | Path | None = None):
    """Write :func:`model_card` of ``metrics`` for the model file ``model_path`` (its size is
    measured) to ``card_path`` (default: ``MODEL_CARD.md`` beside the model); returns the path."""
    model_path = Path(model_path)
    card_path = model_path.with_name("MODEL_CARD.md") if card_path is None else Path(card_path)
    return write_card(card_path, model_card(metrics, model_path.stat().st_size))


def _confusion_table(fault: dict) -> str:
    """Per true class: its F1 and its row of the confusion matrix (columns predicted)."""
    confusion = fault["confusion"]
    return table(
        ["class", "F1", *confusion["predicted"]],
        (
            [c, fixed(fault["f1_by_class"][c], 2), *confusion["matrix"][i]]
            for i, c in enumerate(confusion["true"])
        ),
    )


def _importance_table(rows: list[dict]) -> str:
    return table(
        ["group", "importance"],
        (
            [r["name"], f"{r['importance_mean']:.4f} ± {r['importance_std']:.4f}"]
            for r in rows
            if r["kind"] == "group"
        ),
    )


def model_card(metrics: dict, size: int) -> str:
    """The model card (Markdown) from :func:`train_default_model`'s metrics and the model file's
    size [bytes]: every number in it is measured; the prose describes the shipped recipe."""
    ct, cv, og = metrics["clearance_test"], metrics["clearance_cv"], metrics["off_grid"]
    ft, fcv = metrics["fault_test"], metrics["fault_cv"]
    ogc, ogf = og["clearance"], og["fault"]
    recipe = metrics["model"]
    ds = metrics["default_severity"]
    dsf = ds["fault"]
    members = sorted({k for row in dsf["set_membership"].values() for k in row})
    set_table = table(
        ["class", *members],
        (
            [c, *(fixed(row.get(k, 0.0), 2) for k in members)]
            for c, row in dsf["set_membership"].items()
        ),
    )
    sets = [
        (
            "3-fold CV on train (grouped by operating point; models alone)",
            cv["mae"],
            cv["interval_coverage"],
            cv["mean_interval_width"],
            fcv["macro_f1_classifier"],
        ),
        (
            f"held-out split ({ct['n']} runs; models alone)",
            ct["mae"],
            ct["interval_coverage"],
            ct["mean_interval_width"],
            ft["macro_f1_classifier"],
        ),
        (
            f"off-grid ({ogc['n']} runs: a fresh hypercube, recipe seed + 1, run seeds never "
            "used in training; through the diagnosis)",
            ogc["mae"],
            ogc["coverage"],
            ogc["mean_width"],
            ogf["macro_f1_all"],
        ),
    ]
    metrics_table = table(
        [
            "set",
            "clearance MAE",
            "90 % coverage",
            "mean width",
            "fault macro-F1 (models alone: argmax; through the diagnosis: class sets)",
        ],
        (
            [label, um(mae), fixed(cover), um(width), fixed(f1)]
            for label, mae, cover, width, f1 in sets
        ),
    )
    honesty_table = table(
        [
            "recording",
            "n",
            f"OOD flagged (score > {OOD_LIMIT:g})",
            "median OOD score",
            "`cannot_tell`",
            "confident wrong",
            "warned",
        ],
        (
            [
                label,
                h["n"],
                h["ood_flagged"],
                f"{h['median_ood_score']:.2f}",
                h["cannot_tell"],
                h["confident_wrong"],
                h["warned"],
            ]
            for label, h in metrics["honesty"].items()
        ),
    )
    sensitivity_table = table(
        ["element", "range", "n", "bias", "MAE", "coverage"],
        (
            [
                f"`{r['parameter']}`",
                f"{r['low']:.4g} … {r['high']:.4g}",
                r["n"],
                um(r["bias"]),
                um(r["mae"]),
                fixed(r["coverage"]),
            ]
            for r in metrics["sensitivity"]
        ),
    )
    ablation_table = table(
        [
            "features",
            "n",
            "clearance MAE",
            "90 % coverage",
            "mean width",
            "fault macro-F1 (argmax)",
        ],
        (
            [
                r["features"],
                r["n_features"],
                um(r["mae"]),
                f"{r['coverage']:.3f}",
                um(r["width"]),
                f"{r['macro_f1']:.3f}",
            ]
            for r in metrics["ablation"]
        ),
    )

    return (
        header(
            "Model card — `models/default.skops` (instrumentation `flight-ema`)",
            TOOL,
        )
        + f"""
**What it is.** The default diagnosis model of `prsm-health diagnose` / `replay` / the service,
for a paper-01 PRSM measured by the `flight-ema` instrumentation (resolver, phase-current
torque, LVDT on the output rod, one axial MEMS accelerometer; no load cell —
docs/instrumentation.md): a `ClearanceEstimator` (gradient-boosted point model; gradient-boosted
quantiles of its out-of-fold residual, conformally calibrated to a 90 % interval), a
`FaultClassifier` (gradient boosting, sigmoid-calibrated probabilities) and a
`DistributionGuard` (k-nearest-neighbour out-of-distribution score), on the
{len(metrics["feature_names"])} indicators of `prsm_health.signals.features` this instrumentation gives,
over {recipe["window"]:g} s windows at {metrics["sample_rate"]:g} Hz. File size
{size / 1e6:.2f} MB; prsm_health, scikit-learn and numpy versions are recorded in the file and
checked on load. Required channels: {", ".join(metrics["channels"])}.

**Data.** `datasets/flight-ema-reference.toml`, domain-randomised: {metrics["runs"]["train"]}
training and {metrics["runs"]["test"]} held-out runs (random 20 % split) of a Latin hypercube over
clearance 0–40 µm, uneven wear, preload 0–5 µm, speed 50–130 rad/s, mean load ±400 N with a
300–2500 N swing at 4–16 Hz and 1–20 ms reversal ramps, lubricant degradation 0–1,
temperature 10–70 °C, the fault cases of docs/faults.md (spalls on screw, nut, roller; ring-
and roller-gear tooth cracks; a tooth pit; preload loss) at 0.5–1.5× default severity, contact
damping 0.02–0.034 and restitution 0.4–0.8, coupling stiffness and damping, payload, linkage
stiffness, accelerometer/LVDT/torque noise; sensor gains, offsets and harmonic errors and the
manufacturing scatter drawn per run from their documented spreads. Classes (precedence):
spall > tooth_damage > severe_wear (b ≥ 30 µm) > wear (b ≥ 15 µm) > preload_loss (≥ 50 % lost)
> lubrication (degradation ≥ 0.5) > healthy.

## Metrics

Clearance through the diagnosis (gates and OOD score applied: an interval is the whole trained
range where the clearance was not observable or the window out of distribution); fault macro-F1
counts `cannot_tell` as a miss.

{metrics_table}

Off-grid: clearance observable in {fixed(ogc["observable_fraction"], 2)} of the runs; out of
distribution {fixed(og["ood"]["flagged_fraction"], 3)}; `cannot_tell` {fixed(ogf["cannot_tell_fraction"], 3)};
macro-F1 of the runs given a class {fixed(ogf["macro_f1_named"])}.

Figures of the off-grid set: [predicted vs true clearance](figures/clearance.png),
[class calibration](figures/calibration.png) (the probabilities are cautious: the share correct
lies above the top probability), [confusion matrix](figures/confusion.png).

### Each class at its default severity

{ds["per_class"]} runs per class, on otherwise healthy units (clearance
< 12 µm, lubricant degradation < 0.4) except where the class is the clearance or the lubricant,
everything else drawn from the reference ranges, fresh seeds: fault macro-F1
**{fixed(dsf["macro_f1_all"])}** (`cannot_tell` counted as a miss;
{fixed(dsf["macro_f1_named"])} over the runs given a class,
`cannot_tell` {fixed(dsf["cannot_tell_fraction"], 3)}); clearance MAE
{um(ds["clearance"]["mae"])}, coverage
{fixed(ds["clearance"]["coverage"])}.

{_confusion_table(dsf)}

**Named classes and class sets.** A diagnosis names the most probable class when its
probability reaches 0.5, else it answers `cannot_tell`; beside it, the model's 90 % class set
(per-class conformal thresholds from the calibration folds: `FaultClassifier.predict_set`)
lists the classes the evidence cannot rule out, in a warning when it holds more than the named
class. At default severity the sets hold the true class in {fixed(dsf["set_coverage"])} of the runs, with
{fixed(dsf["mean_set_size"], 2)} classes on average; confident wrong answers (a class named, wrong,
top probability > 0.6): {fixed(dsf["confident_wrong_fraction"], 3)} of the runs (off-grid:
{fixed(ogf["confident_wrong_fraction"], 3)}). Share of each class's runs whose set holds each
class (rows true):

{set_table}

### Fault classes (off-grid): F1 and confusion (rows true, columns predicted)

{_confusion_table(ogf)}

## Honesty checks (simulated recordings the model must not answer confidently)

Six recordings each, from test-split points of the reference recipe with new seeds. A
*confident wrong* class is a class other than the truth and `cannot_tell` with probability > 0.6.

{honesty_table}

## Sensitivity (off-grid runs in thirds of each varied element's range)

How the clearance estimate shifts across each chain element's range: bias (estimate − truth),
MAE and interval coverage of the runs in each third.

{sensitivity_table}

## What each indicator group adds (held-out split, both models retrained without it)

{ablation_table}

Permutation importance (held-out, groups permuted together) — clearance (drop of R²):

{_importance_table(metrics.get("clearance_importance", []))}

Fault class (drop of accuracy):

{_importance_table(metrics.get("fault_importance", []))}

## What it does not cover

- One design (paper01); another design's recording is refused when it says its design, and
  scored out of distribution when it does not (honesty checks), not diagnosed.
- One instrumentation (flight-ema). A recording without one of its channels is diagnosed with
  what it has, the clearance is not observable without the LVDT, and the class is
  `cannot_tell`.
- Contact damping ratios above 0.034 (the RK4 step would have to shrink, docs/performance.md),
  clearances beyond 40 µm, speeds beyond 50–130 rad/s, loads beyond the trained swing: the
  diagnosis warns outside the trained speed and drive-torque ranges.
- Clearance is not observable without a load or motion reversal (steady load holds each roller
  on one flank): the interval is the trained range and the class `cannot_tell`.
- **Faults this chain cannot tell apart.** Gear tooth damage has no signature in these
  channels (docs/faults.md); spalls at default severity barely do at these loads, and the
  impacts of the clearance at every reversal dominate the envelope; a lubricant's extra
  friction is hidden in a drive torque dominated by an axial load no sensor measures (no load
  cell on a flight EMA); a partial preload loss changes the play by a few µm, inside the
  clearance's own spread. Only wear and severe wear are seen (by the lost motion: the argmax of
  the classifier reaches F1 ≈ 0.7–0.9 on them, ablation and earlier cards). But a spall or a
  cracked tooth may sit on a worn unit too (the taxonomy names the localised fault first), and
  nothing in these channels rules it out: the class set keeps spall and tooth damage for nearly
  every window, and the warning says so beside what it *does* rule out (healthy and
  lubrication for most worn units, the class-set table); the clearance estimate and its
  interval carry the wear. The issue asked for a fault macro-F1 ≥ 0.9 at default severities;
  this instrumentation cannot give it honestly: naming the most probable class whatever its
  probability (the previous card, 2026-11-24) scored 0.34, and gave a wrong class to 25–29 of
  the 30 runs of healthy, preload loss, spall and tooth damage (14 of lubrication), at
  probabilities of 0.25–0.3; naming only classes that reach 0.5 scores
  {fixed(dsf["macro_f1_all"])} with {fixed(dsf["confident_wrong_fraction"], 3)} confident wrong answers.
  No indicator we tried (time-synchronous averages, envelope lines at the defect frequencies,
  spectral kurtosis, plain-spectrum lines at the defect frequencies) changed that (ablation
  table, docs/faults.md). What would: a load cell, a tangential accelerometer, longer windows
  at higher load (docs/faults.md).
- Real recordings differ from the simulator (mounting, transfer paths, temperature): validate
  on measured data (`prsm-health import`, `prsm-health evaluate`) before trusting it.
"""
        + check_card_section(metrics.get("check", {}))
        + gauge_card_section(metrics.get("gauge", {}))
    )


#: The tool that measures the clearance gauge's numbers.
GAUGE_TOOL = "tools/studies/clearance_gauge.py"
#: The gauge's readings in the card, in order: key → what it is.
GAUGE_READINGS = {
    "commissioned": "measured, commissioned (the unit's own chain, heavier reversal)",
    "commissioned_two_load": "measured, commissioned on the zero-load extrapolation instead",
    "one_reversal": "measured, commissioned, a check with one reversal",
    "nominal": "measured, not commissioned (the datasheets' ranges)",
    "learnt": "learnt (the check model's own clearance)",
}


def gauge_card_section(gauge: dict) -> str:
    """The card's "Clearance measured by physics" section from ``metrics["gauge"]`` (the
    study's numbers, :data:`GAUGE_TOOL`); empty before it is measured."""
    if not gauge:
        return ""
    units = gauge["units"]
    rows = []
    for key, what in GAUGE_READINGS.items():
        fresh = gauge[key]["fresh"]
        rows.append(
            [
                what,
                fixed(fresh["error_mean_um"], 2),
                fixed(fresh["error_sd_um"], 2),
                fixed(fresh["unit_bias_sd_um"], 2),
                fixed(fresh.get("coverage"), 2),
                fixed(gauge[key].get("conformal_scale"), 2),
            ]
        )
    readings = table(
        [
            "clearance",
            "error mean [µm]",
            "error sd [µm]",
            "unit bias sd [µm]",
            "90 % coverage",
            "conformal factor",
        ],
        rows,
    )
    factors = table(
        ["factor", "range", "lower third: error mean (sd) [µm]", "upper third"],
        (
            [
                name,
                gauge["ranges"].get(name, MISSING),
                f"{v['lower third'][0]:+.2f} ({v['lower third'][1]:.2f})",
                f"{v['upper third'][0]:+.2f} ({v['upper third'][1]:.2f})",
            ]
            for name, v in gauge["by_factor"].items()
        ),
    )
    budget = ", ".join(f"{k} {v:.2f}" for k, v in gauge["budget_mean_um"].items())
    return f"""
## Clearance measured by physics (the health check as a measuring instrument)

*Measured by `{GAUGE_TOOL}`.* The clearance of a health check is measured from its reversals'
lost motion through the actuator's compliance chain (docs/diagnostics.md, "Clearance measured
by physics"); the check model's learnt clearance is its cross-check. Units of paper01 with the
flight-ema sensors, each built from the ranges below (drawn uniformly), an as-built clearance
of 2–8 µm and a worn one up to 30 µm; two checks at the as-built clearance (commissioning), three
on the way to the worn one, each at a housing temperature of 10–70 °C with its own sensor noise.
The conformal factor of each reading's 90 % interval is calibrated on {units["calibration"]}
units, the figures are of {units["fresh"]} fresh units (seeds used nowhere else), against the
realised mean clearance (the rollers' mean half-clearance, screw and nut sides):

{readings}

The heavier reversal's lost motion between a unit's two commissioning checks (one clearance,
each at its own temperature: the friction's torsion, which the measured torque carries into
the chain) has an sd of {fixed(gauge["commissioning_step_sd_um"], 2)} µm. The commissioned
reading's budget, mean over the fresh checks [µm of clearance]: {budget}.

Sensitivity of the commissioned reading (fresh units; each factor's drawn values cut into
thirds, the others drawn as usual — units, not a controlled change):

{factors}
"""


def check_card_section(check: dict) -> str:
    """The model card's "Health-check recordings" section from ``metrics["check"]``
    (:func:`~prsm_health.training.check_evaluation.evaluate_check_model`'s numbers and the
    training's); empty before the check part is evaluated."""
    ev = check.get("evaluation")
    if not ev:
        return ""
    tr = check.get("training", {})
    single, acc, clr = ev["single"], ev["accumulated"], ev["clearance"]
    rel = ev["against_baseline_single"]
    states = list(EVAL_STATES)
    predicted = sorted({p for row in single["confusion"].values() for p in row})
    single_table = table(
        ["state", *predicted],
        ([s, *(single["confusion"].get(s, {}).get(p, 0) for p in predicted)] for s in states),
    )
    named = sorted({p for row in acc["confusion"].values() for p in row})
    accumulated_table = table(
        ["state", *named],
        ([s, *(acc["confusion"].get(s, {}).get(p, 0) for p in named)] for s in states),
    )
    held = tr.get("held_out", {})
    counts = ", ".join(f"{k} {v}" for k, v in tr.get("class_counts", {}).items()) or MISSING
    sensitivity_table = table(
        ["factor", "range", "checks", "named right", "wrong class", "clearance MAE"],
        (
            [
                SENSITIVITY_FACTORS[row["factor"]],
                f"{row['low']:.3g} – {row['high']:.3g}",
                row["n"],
                fixed(row["named_right"]),
                fixed(row["wrong"]),
                um(row["clearance_mae"]),
            ]
            for row in ev.get("sensitivity", [])
        ),
    )
    strict_table = table(
        ["t", "macro-F1", "healthy named healthy", "wrong class"],
        (
            [
                f"{row['threshold']:.1f}",
                fixed(row["macro_f1"]),
                fixed(row["healthy_named_healthy"]),
                fixed(row["wrong_fraction"]),
            ]
            for row in single.get("naming_thresholds", [])
        ),
    )
    evidence_table = table(
        ["t", "macro-F1", "wrong class", "`cannot_tell`"],
        (
            [
                f"{row['threshold']:.2f}",
                fixed(row["macro_f1"]),
                fixed(row["wrong_fraction"]),
                fixed(row["cannot_tell_fraction"]),
            ]
            for row in acc.get("thresholds", [])
        ),
    )
    readings_table = table(
        [
            "reading",
            "n",
            "macro-F1",
            "healthy named healthy",
            "wrong class",
            "confident wrong",
            "`cannot_tell`",
        ],
        [
            [
                "one check alone",
                single["n"],
                fixed(single["macro_f1"]),
                fixed(single["healthy_named_healthy"]),
                fixed(single["wrong_fraction"]),
                fixed(single.get("confident_wrong_fraction")),
                fixed(single["cannot_tell_fraction"]),
            ],
            [
                "one check against the unit's baseline",
                rel["n"],
                fixed(rel["macro_f1"]),
                fixed(rel["healthy_named_healthy"]),
                fixed(rel["wrong_fraction"]),
                MISSING,
                fixed(rel["cannot_tell_fraction"]),
            ],
            [
                "five checks against the baseline, evidence accumulated (named at posterior "
                f"≥ {acc['threshold']})",
                f"{acc['units']} units",
                fixed(acc["macro_f1"]),
                MISSING,
                fixed(acc["wrong_fraction"]),
                MISSING,
                fixed(acc["cannot_tell_fraction"]),
            ],
        ],
    )
    per_state = acc["units"] // max(1, len(observable_states(tr.get("not_observable", {}))))
    auc = ", ".join(f"{k} {v:.3f}" for k, v in acc["spall_auc"].items()) or MISSING
    return f"""
## Health-check recordings (the check part of the bundle)

*Generated by `tools/release/train_check_model.py`; the part lives in
`models/default.check.skops`, beside the window model, and is loaded with it.* A recording of the built-in health check
(`prsm-health simulate --profile health-check`; docs/diagnostics.md) is read phase by phase:
the no-load stroke (preload), the torque at two speeds under one load with the housing
temperature (lubricant), the slow reversal under load (clearance, lost motion), the high-load
stroke (synchronous averages of the vibration and of its envelope at the nut-pass,
roller-spin and carrier periods: spalls). Trained on
80 units ({tr.get("runs", {}).get("train", MISSING)} check recordings of 64 units, {tr.get("runs", {}).get("test", MISSING)} of 16 held-out units; per class
{counts}): `datasets/flight-ema-check.toml` (every state, drawn independently of the unit),
`flight-ema-check-aging.toml` (each unit at its as-built clearance with one new state) and
`flight-ema-check-healthy.toml` (more healthy checks), with the same units' baselines
(`flight-ema-check-baseline.toml`: two checks of each unit new, whose spread is each
indicator's repeatability). Classes weighted equally; probabilities calibrated, and class sets
set, on folds that keep a unit's checks together (a unit seen in both halves made the model as
sure of a new unit as of a known one). The classes a check does not show are left out of the
classifiers and named in every check diagnosis: {", ".join(tr.get("not_observable", {})) or "none"}; those
only the change against the unit's baseline shows are left out of the classifier that reads a
check alone, and named in its diagnoses: {", ".join(tr.get("baseline_only", {})) or "none"}. Held-out units: clearance MAE
{um(held.get("clearance_mae"))}, coverage {fixed(held.get("clearance_coverage"))};
macro-F1 (argmax) alone {fixed(held.get("macro_f1_alone"))}, against the unit's baseline
{fixed(held.get("macro_f1_against_baseline"))}.

**Fresh units** ({per_state} per state, a units
seed never used in training): three baseline checks each, then five checks in each state at
default severity. Fault macro-F1 over the states the check is built to show — healthy, wear,
severe wear, lubrication, a nut spall, a roller spall, preload loss, less any named not
observable above (`cannot_tell` a miss; screw spalls and tooth damage in the tables below; a
check alone is not scored on the classes only the baseline shows):

{readings_table}

Spall detection after five checks (ROC AUC of the spall posterior, spall units vs healthy
units; the check's high-load stroke is at 25 % of C_a): {auc}. Clearance on the check
recordings: MAE {um(clr["mae"])}, 90 % coverage {fixed(clr["coverage"])}, mean width
{um(clr["mean_width"])}.

One check alone, per state (rows: the unit's state; columns: the diagnosis):

{single_table}

A stricter naming rule (one check alone, a class named only from probability t up): what it
costs in healthy units named healthy and in F1, what it saves in wrong names. The wrong names
left at 0.5 are units whose fault leaves its signature inside the healthy units' scatter
(docs/diagnostics.md, "Measured").

{strict_table}

Sensitivity (one check alone, the headline states, each factor's drawn range cut into thirds;
the others drawn as usual). The temperature is drawn per check; the sensors' noise levels (the
parts installed on a unit), uneven wear, payload and coupling once per unit, so their thirds are
groups of the 8 units — a comparison of units, not a controlled change:

{sensitivity_table}

Five checks against the baseline, per unit:

{accumulated_table}

The evidence's naming rule (five checks against the baseline, a class named from posterior t
up; the diagnosis uses {acc["threshold"]}): what a looser or stricter rule does to the same units.

{evidence_table}
"""
