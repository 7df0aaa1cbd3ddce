"""The plain baseline beside every fault model: a random forest on per-channel statistics
(:mod:`prsm_health.signals.channel_statistics`), cross-validated by the same grouped folds as
the model, so a user never gets a model worse than what a first attempt on the same files would
give without being told.

On a recording the diagnosis' indicators were not built for (a rig sampled at tens of hertz,
no accelerometer) most of them are NaN or meaningless, while the statistics of the slow
channels still separate the classes (a new user's rig with seeded faults, slow drive and
position channels: cross-validated macro-F1 0.80 for the pipeline against 0.91 for such a
forest, measured 2026-12 on main 5cf74e9; docs/import.md).
"""

from __future__ import annotations

import numpy as np

from .evaluation import cross_validated_metrics

#: Trees of the baseline forest (scikit-learn's RandomForestClassifier, default otherwise).
TREES = 300
#: Macro-F1 by which the baseline must beat the model before ``train`` says so: about one
#: fold's scatter on a few dozen runs (a difference below it is noise).
MARGIN = 0.02
#: What the baseline is, in words.
DESCRIPTION = f"random forest ({TREES} trees) on per-channel mean, std, min, max"


def plain_baseline_cv(stats, labels, groups, cv, random_state: int = 0) -> dict:
    """The baseline's cross-validated fault metrics: ``stats`` the training runs' statistics
    (:func:`~prsm_health.signals.channel_statistics.dataset_statistics`, a DataFrame), and
    ``labels``, ``groups``, ``cv`` as the model's. ``macro_f1``, ``accuracy``,
    ``n_features``, ``model`` and the folds."""
    from sklearn.ensemble import RandomForestClassifier

    stats = stats.loc[:, stats.notna().any()]  # a channel no run has
    X = stats.fillna(stats.median()).to_numpy(float)

    def make():
        return RandomForestClassifier(n_estimators=TREES, random_state=random_state, n_jobs=1)

    metrics = cross_validated_metrics(make, X, np.asarray(labels), groups=groups, cv=cv)
    metrics["n_features"] = int(X.shape[1])
    metrics["model"] = DESCRIPTION
    return metrics


def baseline_verdict(model_f1: float, baseline: dict) -> list[str]:
    """One line when the baseline beats the model by more than :data:`MARGIN` (else none)."""
    plain = baseline.get("macro_f1")
    if plain is None or model_f1 is None or not plain > model_f1 + MARGIN:
        return []
    return [
        f"a plain {DESCRIPTION} scores macro-F1 {plain:.2f} in the same cross-validation, "
        f"this model {model_f1:.2f}: on this dataset the diagnosis' indicators (built for "
        "20 kHz PRSM recordings) lose to plain statistics — the baseline is not shipped (the "
        "diagnosis reads indicators), see docs/import.md"
    ]
