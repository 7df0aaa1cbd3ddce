"""The check model judged on units it never saw: one check recording alone, and five check
recordings of a unit read against its own baseline with the evidence accumulated.

:func:`evaluation_recipes` derives, from a check training recipe, recipes of *fresh* units (a
``[units]`` seed never used in training): each unit recorded three times new and healthy (its
baseline) and five times in each state of :data:`EVAL_STATES` at default severity, as built
(its preload, uneven wear, installation and the noise levels of its sensors the same in all
its recordings), the temperature and the sensors' noise, gains and offsets drawn per
recording. :func:`evaluate_check_model` diagnoses every recording through
:func:`prsm_health.diagnostics.diagnosis.diagnose` — alone, and against the unit's baseline —
and accumulates each unit's evidence (:class:`~prsm_health.diagnostics.baseline.Evidence`).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from prsm_health.diagnostics.contract import CANNOT_TELL

#: Fresh units: a seed the training recipes never used.
EVAL_UNITS_SEED = 7373
#: Recordings per unit and state, and baseline recordings per unit.
RECORDINGS, BASELINE = 5, 3
#: States of the evaluation: (true class, the sweep entries of the state, extra unit build).
EVAL_STATES = {
    "healthy": ("healthy", {}, {}),
    "wear": ("wear", {}, {"clearance": [17e-6, 28e-6]}),
    "severe_wear": ("severe_wear", {}, {"clearance": [32e-6, 40e-6]}),
    "lubrication": ("lubrication", {"lubricant_degradation": [0.6, 1.0]}, {}),
    "spall_nut": ("spall", {"fault_case": ["spall_nut"]}, {}),
    "spall_roller": ("spall", {"fault_case": ["spall_roller"]}, {}),
    "preload_loss": ("preload_loss", {"fault_case": ["preload_loss"]}, {}),
    "spall_screw": ("spall", {"fault_case": ["spall_screw"]}, {}),
    "tooth_damage": (
        "tooth_damage",
        {"fault_case": ["crack_ring_gear", "crack_roller_gear", "tooth_pit"]},
        {},
    ),
}
#: The states the check is built to show, over which the headline scores are taken; the others
#: (a spall on the screw: its impacts pass a roller only at one stroke position; gear tooth
#: damage: not observable) are reported beside them, row by row.
HEADLINE_STATES = (
    "healthy",
    "wear",
    "severe_wear",
    "lubrication",
    "spall_nut",
    "spall_roller",
    "preload_loss",
)
#: A wrong answer is *confident* when its class probability exceeds this.
CONFIDENT = 0.6
#: Naming thresholds of the trade-off table (the diagnosis names from
#: :data:`~prsm_health.diagnostics.answer.NAME_PROBABILITY` = 0.5 up).
NAMING_THRESHOLDS = (0.5, 0.6, 0.7, 0.8)
#: Posterior thresholds of the accumulated evidence's trade-off table (the diagnosis names from
#: :data:`~prsm_health.diagnostics.baseline.EVIDENCE_NAME_PROBABILITY` = 0.9).
EVIDENCE_THRESHOLDS = (0.7, 0.8, 0.9, 0.95)
#: What the sensitivity table splits the checks by: label → how the card names it (the
#: documented ranges drawn per check or per unit by the recipes).
SENSITIVITY_FACTORS = {
    "instrumentation.nut_axial_accel.noise_density_ug": "accelerometer noise [µg/√Hz]",
    "instrumentation.nut_position.noise": "LVDT noise [µm RMS]",
    "instrumentation.drive_torque.noise": "torque noise [mN·m RMS]",
    "temperature": "temperature [°C]",
    "wear_spread": "uneven wear between rollers [-]",
    "drive_train.payload_mass": "payload [kg]",
    "drive_train.coupling_stiffness": "coupling stiffness [kN·m/rad]",
}
#: Display scale of each factor (SI inside; the card in the units above).
_FACTOR_SCALE = {
    "instrumentation.nut_position.noise": (1e6, 0.0),
    "instrumentation.drive_torque.noise": (1e3, 0.0),
    "temperature": (1.0, -273.15),
    "drive_train.coupling_stiffness": (1e-3, 0.0),
}
#: The unit as built in every evaluation recipe: a preloaded nut (so a preload loss is one),
#: clearance as built 2–8 µm, the training recipe's uneven wear and installation ranges.
AS_BUILT = {"preload": [2e-6, 5e-6], "clearance": [2e-6, 8e-6]}


def evaluation_recipes(training, units: int = 8) -> dict:
    """``{"baseline": Recipe, state: Recipe …}`` of fresh units (:data:`EVAL_UNITS_SEED`)
    from a check training recipe (``datasets/flight-ema-check.toml``)."""
    from prsm_health.datasets import Recipe

    source = copy.deepcopy(training.source)
    build = dict(source.get("units", {}).get("build", {}))
    build.update(AS_BUILT)
    sweep = {
        k: v
        for k, v in source["sweep"].items()
        if k.split(".")[0] in ("options", "instrumentation") or k == "temperature"
    }

    def recipe(name, seed, per_unit, extra_sweep, extra_build):
        return Recipe.from_dict(
            dict(
                source,
                name=f"{training.name}-eval-{name}",
                seed=seed,
                test_fraction=0.0,
                units={"count": units, "seed": EVAL_UNITS_SEED, "build": build | extra_build},
                sweep={
                    "mode": "random",
                    "samples": units * per_unit,
                    "severity": [1.0, 1.0],
                    "lubricant_degradation": [0.0, 0.2],
                    "fault_case": ["none"],
                    **sweep,
                    **extra_sweep,
                },
            )
        )

    out = {"baseline": recipe("baseline", training.seed + 100, BASELINE, {}, {})}
    for k, (state, (_, extra_sweep, extra_build)) in enumerate(EVAL_STATES.items()):
        out[state] = recipe(state, training.seed + 101 + k, RECORDINGS, extra_sweep, extra_build)
    return out


def generate_evaluation(recipes: dict, work: str | Path, *, workers: int | None = None) -> dict:
    """Generate (resumably) every evaluation recipe into ``work``: name → dataset directory."""
    from prsm_health.datasets import generate

    work = Path(work)
    out = {}
    for name, recipe in recipes.items():
        generate(recipe, work / recipe.name, workers=workers)
        out[name] = work / recipe.name
    return out


def evaluate_check_model(bundle, datasets: dict, *, threshold: float = 0.9) -> dict:
    """Every evaluation recording through the diagnosis, alone and against its unit's
    baseline, and each unit's evidence accumulated over its five recordings of a state.

    Returns
    -------
    dict
        ``single``: one recording alone (per-state confusion, macro-F1 over the states the
        check shows, healthy named healthy, confident wrong); ``accumulated``: five recordings
        against the baseline (macro-F1 of the units' named classes, ROC AUC of the spall
        posterior of nut/roller spall units vs healthy units); ``clearance``: MAE and 90 %
        coverage on the check recordings; ``records``: one row per recording.
    """
    from prsm_health.datasets import Dataset
    from prsm_health.diagnostics.baseline import Baseline
    from prsm_health.diagnostics.check_model import CheckModel
    from prsm_health.diagnostics.diagnosis import diagnose
    from prsm_health.monitoring.evidence import Evidence

    model = CheckModel.from_part(bundle.check)
    base = Dataset(datasets["baseline"])
    baselines = {}
    for unit, group in base.runs.groupby("unit_id"):
        rows = [diagnose(base.run(int(i), truth=False), bundle).indicators for i in group.run_id]
        baselines[int(unit)] = Baseline.fit(
            rows, prior_scale=model.repeatability, names=list(model.feature_names)
        )
    records, units = [], []
    for state, (true_class, _, _) in EVAL_STATES.items():
        ds = Dataset(datasets[state])
        for unit, group in ds.runs.groupby("unit_id"):
            evidence = None
            for run_id in group.run_id:
                run = ds.run(int(run_id), truth=False)
                alone = diagnose(run, bundle)
                against = diagnose(run, bundle, baseline=baselines[int(unit)])
                if evidence is None:
                    evidence = Evidence.start(list(against.class_probabilities))
                evidence = evidence.update(
                    against.class_probabilities, training_prior=model.training_prior
                )
                row = group[group.run_id == run_id].iloc[0]
                records.append(
                    {
                        "state": state,
                        "fault_class": true_class,
                        "unit_id": int(unit),
                        "predicted_alone": alone.fault_class,
                        "top_alone": max(alone.class_probabilities.values()),
                        "predicted_against": against.fault_class,
                        "top_against": max(against.class_probabilities.values()),
                        "clearance": 0.5 * (row.clearance_screw + row.clearance_nut),
                        "estimate": alone.clearance["estimate"],
                        "lower": alone.clearance["lower"],
                        "upper": alone.clearance["upper"],
                        "conditions": {
                            k: float(row[k]) for k in SENSITIVITY_FACTORS if k in row.index
                        },
                    }
                )
            posterior = evidence.posterior()
            units.append(
                {
                    "state": state,
                    "fault_class": true_class,
                    "unit_id": int(unit),
                    "named": evidence.named(threshold),
                    "posterior": posterior,
                }
            )
    return {
        "single": _class_scores(records, "predicted_alone", model),
        "against_baseline_single": _class_scores(records, "predicted_against", model),
        "accumulated": _accumulated(units, model, threshold),
        "clearance": _clearance(records),
        "sensitivity": _sensitivity(records, model),
        "records": records,
        "units": units,
    }


def observable_states(not_observable) -> list[str]:
    """The :data:`HEADLINE_STATES` whose class is not among ``not_observable``."""
    return [s for s in HEADLINE_STATES if EVAL_STATES[s][0] not in not_observable]


def _class_scores(records, key: str, model) -> dict:
    from sklearn.metrics import f1_score

    # a class only the unit's baseline shows is not scored on checks read alone
    hidden = dict(model.not_observable)
    if key == "predicted_alone":
        hidden.update(getattr(model, "baseline_only", {}))
    shown = set(observable_states(hidden))
    rows = [r for r in records if r["state"] in shown]
    truth = np.array([r["fault_class"] for r in rows])
    pred = np.array([r[key] for r in rows])
    labels = sorted(set(truth))
    confusion = {}
    for r in records:
        confusion.setdefault(r["state"], {}).setdefault(r[key], 0)
        confusion[r["state"]][r[key]] += 1
    healthy = truth == "healthy"
    wrong = (pred != truth) & (pred != CANNOT_TELL)
    out = {
        "n": len(rows),
        "macro_f1": float(f1_score(truth, pred, labels=labels, average="macro", zero_division=0)),
        "per_class_f1": dict(
            zip(
                labels,
                map(float, f1_score(truth, pred, labels=labels, average=None, zero_division=0)),
            )
        ),
        "healthy_named_healthy": float(np.mean(pred[healthy] == "healthy"))
        if healthy.any()
        else None,
        "wrong_fraction": float(np.mean(wrong)),
        "cannot_tell_fraction": float(np.mean(pred == CANNOT_TELL)),
        "confusion": confusion,
    }
    top_key = "top_alone" if key == "predicted_alone" else "top_against"
    if all(top_key in r for r in rows):
        top = np.array([r[top_key] for r in rows])
        if key == "predicted_alone":
            out["confident_wrong_fraction"] = float(np.mean(wrong & (top > CONFIDENT)))
        out["naming_thresholds"] = _naming_thresholds(truth, pred, top, labels)
    return out


def _naming_thresholds(truth, pred, top, labels) -> list[dict]:
    """The same answers had a class been named only from probability ``t`` up (below it
    ``cannot_tell``): what a stricter naming rule costs in named healthy units and F1, and
    what it saves in wrong names."""
    from sklearn.metrics import f1_score

    out = []
    for t in NAMING_THRESHOLDS:
        named = np.where(top >= t, pred, CANNOT_TELL)
        healthy = truth == "healthy"
        out.append(
            {
                "threshold": t,
                "macro_f1": float(
                    f1_score(truth, named, labels=labels, average="macro", zero_division=0)
                ),
                "healthy_named_healthy": float(np.mean(named[healthy] == "healthy"))
                if healthy.any()
                else None,
                "wrong_fraction": float(np.mean((named != truth) & (named != CANNOT_TELL))),
            }
        )
    return out


def _accumulated(units, model, threshold) -> dict:
    from sklearn.metrics import f1_score, roc_auc_score

    shown = set(observable_states(model.not_observable))
    rows = [u for u in units if u["state"] in shown]
    truth = np.array([u["fault_class"] for u in rows])
    pred = np.array([u["named"] for u in rows])
    labels = sorted(set(truth))
    confusion = {}
    for u in units:
        confusion.setdefault(u["state"], {}).setdefault(u["named"], 0)
        confusion[u["state"]][u["named"]] += 1
    auc = {}
    for state in ("spall_nut", "spall_roller"):
        sick = [u["posterior"].get("spall", 0.0) for u in units if u["state"] == state]
        well = [u["posterior"].get("spall", 0.0) for u in units if u["state"] == "healthy"]
        if sick and well:
            auc[state] = float(roc_auc_score([1] * len(sick) + [0] * len(well), sick + well))
    from prsm_health.monitoring.evidence import named_class

    trade_off = []
    for t in EVIDENCE_THRESHOLDS:
        named = np.array([named_class(u["posterior"], t) for u in rows])
        trade_off.append(
            {
                "threshold": t,
                "macro_f1": float(
                    f1_score(truth, named, labels=labels, average="macro", zero_division=0)
                ),
                "wrong_fraction": float(np.mean((named != truth) & (named != CANNOT_TELL))),
                "cannot_tell_fraction": float(np.mean(named == CANNOT_TELL)),
            }
        )
    return {
        "units": len(rows),
        "threshold": threshold,
        "macro_f1": float(f1_score(truth, pred, labels=labels, average="macro", zero_division=0)),
        "wrong_fraction": float(np.mean((pred != truth) & (pred != CANNOT_TELL))),
        "cannot_tell_fraction": float(np.mean(pred == CANNOT_TELL)),
        "spall_auc": auc,
        "confusion": confusion,
        "thresholds": trade_off,
    }


def _sensitivity(records, model) -> list[dict]:
    """One check alone, the headline states, split into thirds of each
    :data:`SENSITIVITY_FACTORS` range: share named right, share named wrong, clearance MAE."""
    shown = set(observable_states({**model.not_observable, **getattr(model, "baseline_only", {})}))
    rows = [r for r in records if r["state"] in shown and r.get("conditions")]
    out = []
    for factor in SENSITIVITY_FACTORS:
        values = np.array([r["conditions"].get(factor, np.nan) for r in rows], float)
        if not np.isfinite(values).any():
            continue
        edges = np.nanquantile(values, [0.0, 1 / 3, 2 / 3, 1.0])
        scale, offset = _FACTOR_SCALE.get(factor, (1.0, 0.0))
        for k in range(3):
            upper = values <= edges[k + 1] if k == 2 else values < edges[k + 1]
            inside = (values >= edges[k]) & upper
            chosen = [r for r, keep in zip(rows, inside) if keep]
            if not chosen:
                continue
            right = np.mean([r["predicted_alone"] == r["fault_class"] for r in chosen])
            wrong = np.mean(
                [r["predicted_alone"] not in (r["fault_class"], CANNOT_TELL) for r in chosen]
            )
            mae = np.mean([abs(r["estimate"] - r["clearance"]) for r in chosen])
            out.append(
                {
                    "factor": factor,
                    "low": float(edges[k] * scale + offset),
                    "high": float(edges[k + 1] * scale + offset),
                    "n": len(chosen),
                    "named_right": float(right),
                    "wrong": float(wrong),
                    "clearance_mae": float(mae),
                }
            )
    return out


def _clearance(records) -> dict:
    y = np.array([r["clearance"] for r in records], float)
    est = np.array([r["estimate"] for r in records], float)
    lo = np.array([r["lower"] for r in records], float)
    hi = np.array([r["upper"] for r in records], float)
    return {
        "n": len(y),
        "mae": float(np.mean(np.abs(est - y))),
        "coverage": float(np.mean((y >= lo) & (y <= hi))),
        "mean_width": float(np.mean(hi - lo)),
    }
