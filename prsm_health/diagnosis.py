"""Diagnosis: recording → windows → indicators → estimators → Diagnosis (contract JSON).

A **model bundle** (saved by :func:`prsm_health.training.train`) holds the clearance estimator,
the fault classifier, the indicator names they were trained on, the window length of the
training runs and the design. :func:`diagnose` cuts a recording into windows of that length,
computes the indicators (:mod:`prsm_health.features`) of each, and returns per window and for
the whole recording the Diagnosis contract of ../shared/DESIGN.md::

    {"clearance": {"estimate": m, "lower": m, "upper": m}, "fault_class": str,
     "class_probabilities": {class: p}, "indicators": {name: value}, "model": {name, version}}

Sources: MCAP (contract topics), a Parquet run (``simulate --out``), or a CSV with contract
channel names and a ``time`` column [s].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import PRSMHealthError
from .features import MIN_SAMPLES, extract_features, windows
from .run import Run

#: Where the shipped default model lives (repository layout: models/ next to the package).
DEFAULT_MODEL = Path(__file__).resolve().parents[1] / "models" / "default.skops"


@dataclass
class ModelBundle:
    """A loaded diagnosis model."""

    clearance: object | None
    fault: object | None
    feature_names: list[str]
    metadata: dict

    @property
    def name(self) -> str:
        return self.metadata.get("name", "unnamed")

    @property
    def version(self) -> str:
        return str(
            self.metadata.get("model_version", self.metadata.get("prsm_health_version", "?"))
        )

    @property
    def window(self) -> float:
        """Window length the model was trained on [s]."""
        return float(self.metadata.get("window", 0.4))

    @property
    def design(self) -> str:
        return self.metadata.get("design", "paper01")


def load_bundle(
    path: str | Path | None = None, *, allow_version_mismatch: bool = False
) -> ModelBundle:
    """Load a model bundle (default: the shipped model); version checks in estimators.load_model."""
    from .persistence import load_model

    path = Path(path) if path is not None else DEFAULT_MODEL
    if not path.exists():
        hint = " (run tools/train_default_model.py)" if path == DEFAULT_MODEL else ""
        raise PRSMHealthError(f"{path}: no such model file{hint}")
    model, metadata = load_model(path, allow_version_mismatch=allow_version_mismatch)
    if not isinstance(model, dict) or "feature_names" not in model:
        raise PRSMHealthError(f"{path}: not a prsm_health diagnosis bundle")
    return ModelBundle(
        model.get("clearance"), model.get("fault"), list(model["feature_names"]), metadata
    )


def read_recording(path: str | Path) -> Run:
    """A recording as a Run: ``.mcap``, ``.parquet`` (single run) or ``.csv`` (contract names)."""
    path = Path(path)
    if not path.exists():
        raise PRSMHealthError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".mcap":
        from .mcap_io import read_mcap

        return read_mcap(path)
    if suffix == ".parquet":
        return Run.from_parquet(path)
    if suffix == ".csv":
        return _read_csv(path)
    raise PRSMHealthError(f"{path}: unsupported file type {suffix!r} (use .mcap, .parquet or .csv)")


def _read_csv(path: Path) -> Run:
    import pandas as pd

    from .channels import CHANNEL_NAMES

    try:
        frame = pd.read_csv(path)
    except Exception as exc:  # pandas raises many types for bad CSVs
        raise PRSMHealthError(f"{path}: not a readable CSV ({exc})") from None
    if "time" not in frame.columns:
        raise PRSMHealthError(f"{path}: no 'time' column")
    channels = {c: frame[c].to_numpy(float) for c in CHANNEL_NAMES if c in frame.columns}
    if not channels:
        raise PRSMHealthError(
            f"{path}: no usable channels (expected contract names such as nut_axial_accel)"
        )
    time = frame["time"].to_numpy(float)
    if len(time) < 2 or not np.all(np.diff(time) > 0):
        raise PRSMHealthError(f"{path}: 'time' must increase strictly")
    rate = 1.0 / float(np.median(np.diff(time)))
    return Run(time, channels, rate)


def _clean(value):
    return (
        None if value is None or (isinstance(value, float) and not math.isfinite(value)) else value
    )


def _matrix(rows: list[dict], names: list[str]):
    import pandas as pd

    return pd.DataFrame(
        [[r.get(n, np.nan) for n in names] for r in rows], columns=names, dtype=float
    )


def diagnose_indicators(rows: list[dict], bundle: ModelBundle) -> list[dict]:
    """Diagnosis contract dicts for rows of indicators (one per window)."""
    from threadpoolctl import threadpool_limits

    x = _matrix(rows, bundle.feature_names)
    n = len(rows)
    # A few rows per call: OpenMP threads in the boosted trees only add spin-wait latency, and
    # under load (the service, parallel replays) oversubscribe the cores.
    with threadpool_limits(limits=1, user_api="openmp"):
        return _predict(rows, x, n, bundle)


def _predict(rows: list[dict], x, n: int, bundle: ModelBundle) -> list[dict]:
    estimate = lower = upper = np.full(n, np.nan)
    if bundle.clearance is not None:
        estimate = np.asarray(bundle.clearance.predict(x), float)
        lower, upper = (np.asarray(a, float) for a in bundle.clearance.predict_interval(x))
        # Regime gate: without a load or motion reversal the clearance is not observable
        # (steady preload keeps each roller on one flank, docs/validation.md), so the interval
        # is the whole range the model was trained on, whatever the regression says.
        gate = bundle.metadata.get("observability_feature")
        span = bundle.metadata.get("clearance_range")
        if gate in x.columns and span:
            hidden = ~np.isfinite(x[gate].to_numpy(float))
            lower = np.where(hidden, span[0], lower)
            upper = np.where(hidden, span[1], upper)
    classes, proba = [], np.zeros((n, 0))
    if bundle.fault is not None:
        classes = [str(c) for c in bundle.fault.classes_]
        proba = np.asarray(bundle.fault.predict_proba(x), float)
    out = []
    for i, row in enumerate(rows):
        probabilities = {c: float(p) for c, p in zip(classes, proba[i])} if classes else {}
        out.append(
            {
                "clearance": {
                    "estimate": _clean(float(estimate[i])),
                    "lower": _clean(float(lower[i])),
                    "upper": _clean(float(upper[i])),
                },
                "fault_class": max(probabilities, key=probabilities.get) if probabilities else None,
                "class_probabilities": probabilities,
                "indicators": {k: _clean(float(v)) for k, v in row.items()},
                "model": {"name": bundle.name, "version": bundle.version},
            }
        )
    return out


def aggregate(diagnoses: list[dict], bundle: ModelBundle) -> dict:
    """One diagnosis for a recording: medians of the window estimates and bounds, mean
    class probabilities, median indicators."""

    def median(values):
        values = [v for v in values if v is not None]
        return float(np.median(values)) if values else None

    probs: dict[str, float] = {}
    for d in diagnoses:
        for c, p in d["class_probabilities"].items():
            probs[c] = probs.get(c, 0.0) + p / len(diagnoses)
    names = diagnoses[0]["indicators"].keys()
    return {
        "clearance": {
            k: median([d["clearance"][k] for d in diagnoses])
            for k in ("estimate", "lower", "upper")
        },
        "fault_class": max(probs, key=probs.get) if probs else None,
        "class_probabilities": probs,
        "indicators": {n: median([d["indicators"][n] for d in diagnoses]) for n in names},
        "model": {"name": bundle.name, "version": bundle.version},
    }


def diagnose(run: Run, bundle: ModelBundle | None = None, *, window: float | None = None) -> dict:
    """Diagnose a recording: the contract dict for the whole recording, plus ``windows``.

    Parameters
    ----------
    run : Run
    bundle : ModelBundle, default the shipped model
    window : float or None [s]
        Window length; default the model's training window. A recording shorter than one
        window but longer than the indicators' minimum is diagnosed as one window.
    """
    bundle = bundle or load_bundle()
    window = window or bundle.window
    if len(run) < MIN_SAMPLES:
        raise PRSMHealthError(
            f"recording too short: {len(run)} samples, need at least {MIN_SAMPLES} "
            f"({MIN_SAMPLES / run.sample_rate:.3g} s at {run.sample_rate:g} Hz)"
        )
    parts = list(windows(run, window)) if len(run) >= window * run.sample_rate else [run]
    rows = [extract_features(part, bundle.design) for part in parts]
    per_window = diagnose_indicators(rows, bundle)
    for k, (part, d) in enumerate(zip(parts, per_window)):
        d["window"] = {"index": k, "start": float(part.time[0]), "end": float(part.time[-1])}
    result = aggregate(per_window, bundle)
    result["windows"] = per_window
    return result


def plot_diagnosis(result: dict, path: str | Path) -> Path:
    """Clearance estimate with its interval per window, and class probabilities, as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w = result["windows"]
    t = [d["window"]["start"] for d in w]
    est = (
        np.array(
            [
                np.nan if d["clearance"]["estimate"] is None else d["clearance"]["estimate"]
                for d in w
            ]
        )
        * 1e6
    )
    lo = (
        np.array(
            [np.nan if d["clearance"]["lower"] is None else d["clearance"]["lower"] for d in w]
        )
        * 1e6
    )
    hi = (
        np.array(
            [np.nan if d["clearance"]["upper"] is None else d["clearance"]["upper"] for d in w]
        )
        * 1e6
    )
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.fill_between(t, lo, hi, step="post", alpha=0.3, label="90 % interval")
    a1.step(t, est, where="post", label="estimate")
    a1.set_ylabel("clearance [µm]")
    a1.legend()
    classes = list(result["class_probabilities"])
    for c in classes:
        a2.step(t, [d["class_probabilities"].get(c, 0) for d in w], where="post", label=c)
    a2.set_ylabel("class probability")
    a2.set_xlabel("window start [s]")
    a2.set_ylim(-0.02, 1.02)
    a2.legend(fontsize=8)
    c = result["clearance"]
    fig.suptitle(
        f"{result['fault_class']}  clearance {1e6 * (c['estimate'] or np.nan):.1f} µm "
        f"[{1e6 * (c['lower'] or np.nan):.1f}, {1e6 * (c['upper'] or np.nan):.1f}]  model {result['model']['name']}"
    )
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
