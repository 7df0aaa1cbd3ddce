"""Import → train → evaluate on a rig's low-rate CSV logs, against a plain random forest.

    python tools/studies/import_round_trip.py [--per-class 12] [--rate 25] [--workers 2]
        [--work build/import-round-trip]

The "rig" is not the paper-01 PRSM: the paper-02 design (other diameters, pitch and rollers),
simulated under a slowly reversing load (±800 N at 0.5 Hz, 20 rad/s) and logged the way a
drive's data logger would — ``--rate`` Hz, 25 by default (anti-alias decimated 4:1 from the
sensors), output
position in mm from the LVDT and the motor current in A (torque / k_t), the motor angle in
degrees; nothing else. Classes healthy / wear / severe_wear / lubrication, ``--per-class``
recordings of 11 s each with their own seeds.

The CSV files, a labels table and a column map go through ``prsm-health import``; ``train
--target fault`` (its three candidates — boosting and a forest on the indicators, the plain
baseline on channel statistics — cross-validated by the same folds, the best shipped) and
``evaluate`` run on the imported dataset. In the same run a plain random
forest (scikit-learn defaults, 300 trees) on simple per-recording statistics of the same
channels (mean, standard deviation, percentiles 1/50/99, peak-to-peak, mean absolute
difference) is trained and scored on the same split. Prints both macro-F1s (JSON); results in
docs/import.md.
"""

from __future__ import annotations

import argparse
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]

K_T = 0.08  # N·m/A, the made-up motor's torque constant
CLASSES = {
    "healthy": {"clearance": (1e-6, 10e-6), "lubricant_degradation": (0.0, 0.3)},
    "wear": {"clearance": (17e-6, 28e-6), "lubricant_degradation": (0.0, 0.3)},
    "severe_wear": {"clearance": (32e-6, 45e-6), "lubricant_degradation": (0.0, 0.3)},
    "lubrication": {"clearance": (1e-6, 10e-6), "lubricant_degradation": (0.6, 1.0)},
}
MAP = """# a drive logger's export: {rate:g} Hz, mm, degrees, amps
sample_rate = {rate}
design = "paper02"
torque_constant = {k_t}
[columns]
nut_position = "rod_position_mm"
screw_angle = "motor_angle_deg"
motor_current = "phase_current_A"
[units]
rod_position_mm = "mm"
motor_angle_deg = "deg"
phase_current_A = "A"
"""


def record(job: tuple) -> dict:
    """Simulate one recording and write it as the logger's CSV."""
    from scipy import signal

    from prsm_health.simulation.scenario import Scenario

    path, cls, seed, rate = job
    rng = np.random.default_rng(seed)
    health = {k: float(rng.uniform(*v)) for k, v in CLASSES[cls].items()}
    scenario = Scenario.from_dict(
        {
            "design": "paper02",
            "health": health,
            "profile": {
                "duration": 11.0,  # 275 samples at 25 Hz: the indicators need 256
                "speed": 20.0,
                "load": float(rng.uniform(-100, 100)),
                "load_profile": "reversing",
                "load_amplitude": 800.0,
                "load_frequency": 0.5,
                "accel_time": 0.05,
            },
            # RK4 at 20 µs: paper 02's stiffest mode (14 kHz, stable step 29 µs) stays stable, and
            # a 25 Hz log needs nothing above it; 4× fewer steps than the 5 µs default
            "options": {"contact_law": "hertz", "max_step": 2e-5},
            "instrumentation": {"profile": "flight-ema", "sample_rate": 4.0 * rate},
            "seed": seed,
        }
    )
    run = scenario.simulate()
    ch = run.channels

    def log(x):  # the logger's 4:1 anti-alias decimation (8th-order Chebyshev, zero phase)
        return signal.decimate(x, 4, zero_phase=True)

    import pandas as pd

    pd.DataFrame(
        {
            "rod_position_mm": 1e3 * log(ch["nut_position"]),
            "motor_angle_deg": np.degrees(log(ch["screw_angle"])),
            "phase_current_A": log(ch["drive_torque"]) / K_T,
        }
    ).to_csv(path, index=False)
    return {"recording": Path(path).name, "fault_class": cls, "clearance": health["clearance"]}


def simple_statistics(frame) -> dict:
    """The per-recording statistics a plain baseline would use."""
    out = {}
    for column in frame.columns:
        x = frame[column].to_numpy(float)
        d = np.diff(x)
        out.update(
            {
                f"{column}_mean": x.mean(),
                f"{column}_std": x.std(),
                f"{column}_p01": np.percentile(x, 1),
                f"{column}_p50": np.percentile(x, 50),
                f"{column}_p99": np.percentile(x, 99),
                f"{column}_ptp": np.ptp(x),
                f"{column}_mad_diff": np.mean(np.abs(d)),
            }
        )
    return out


def main() -> int:
    import pandas as pd
    from sklearn.ensemble import RandomForestClassifier
    from sklearn.metrics import f1_score

    from prsm_health.datasets import Dataset
    from prsm_health.datasets.importer import import_recordings
    from prsm_health.diagnostics.diagnosis import load_bundle
    from prsm_health.training.evaluation import evaluate_model
    from prsm_health.training.train import train

    parser = argparse.ArgumentParser()
    parser.add_argument("--per-class", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--rate", type=float, default=25.0, help="the logger's rate [Hz]")
    parser.add_argument("--work", default=str(ROOT / "build" / "import-round-trip"))
    args = parser.parse_args()
    work = Path(args.work) / f"{args.rate:g}Hz"
    (work / "csv").mkdir(parents=True, exist_ok=True)
    jobs = [
        (str(work / "csv" / f"{cls}-{k:02d}.csv"), cls, 5000 + 100 * i + k, args.rate)
        for i, cls in enumerate(CLASSES)
        for k in range(args.per_class)
    ]
    with ProcessPoolExecutor(args.workers) as pool:
        labels = list(pool.map(record, jobs))
    pd.DataFrame(labels).to_csv(work / "labels.csv", index=False)
    (work / "map.toml").write_text(MAP.format(rate=args.rate, k_t=K_T))
    files = [job[0] for job in jobs]
    import_recordings(
        files, work / "labels.csv", work / "map.toml", work / "dataset", overwrite=True
    )
    metrics = train(work / "dataset", work / "model.skops", target="fault", cv=3, progress=False)
    report, records = evaluate_model(load_bundle(work / "model.skops"), Dataset(work / "dataset"))
    # the baseline on the same split
    ds = Dataset(work / "dataset")
    stats = pd.DataFrame(
        [simple_statistics(pd.read_csv(work / "csv" / r)) for r in ds.runs["recording"]]
    )
    train_rows = (ds.runs["split"] == "train").to_numpy()
    forest = RandomForestClassifier(n_estimators=300, random_state=0)
    forest.fit(stats[train_rows], ds.runs["fault_class"][train_rows])
    predicted = forest.predict(stats[~train_rows])
    baseline = f1_score(ds.runs["fault_class"][~train_rows], predicted, average="macro")
    result = {
        "rate_hz": args.rate,
        "recordings": len(files),
        "test": int((~train_rows).sum()),
        "pipeline": {
            "macro_f1_all": report["fault"]["macro_f1_all"],
            "macro_f1_named": report["fault"]["macro_f1_named"],
            "cannot_tell_fraction": report["fault"]["cannot_tell_fraction"],
            "f1_by_class": report["fault"]["f1_by_class"],
            "cv_macro_f1_classifier": metrics["fault_cv"]["macro_f1_classifier"],
            "shipped": metrics["fault_model"]["candidate"],
        },
        # train's candidates, the plain baseline among them, by the same grouped folds
        "candidates_cv_macro_f1": {
            name: cv["macro_f1"] for name, cv in metrics["fault_candidates"].items()
        },
        "indicator_groups": metrics["indicator_groups"],
        "random_forest_on_statistics": {"macro_f1": float(baseline)},
    }
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
