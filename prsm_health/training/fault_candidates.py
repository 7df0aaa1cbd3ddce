"""Which fault model ``train`` ships: a few candidates cross-validated by the same grouped folds,
the best one shipped, a plain baseline always among them — so a user never gets a model worse
than what a first attempt on the same files would give without being told.

The candidates (:data:`CANDIDATES`), each a :class:`~prsm_health.diagnostics.estimators.
FaultClassifier` (calibrated probabilities, a conformal class set):

- ``boosting``: gradient-boosted trees on the condition indicators — the shipped models' learner
  since the first release, best on the thousands of windows of a generated dataset;
- ``forest``: a random forest on the same indicators — on a few dozen recordings of a rig it
  generalises better (measured 2026-12-02, docs/import.md);
- ``plain_baseline``: a random forest on per-channel mean, standard deviation and extremes
  (:mod:`prsm_health.signals.channel_statistics`), what a first classifier on any rig reads.
  Shipped, the diagnosis computes those statistics per window like any indicator group.

The best cross-validated macro-F1 is shipped; a tie goes to the earlier candidate. With a
single cross-validation choosing among three, the winner's score is slightly optimistic (it is
the best of three noisy estimates): the held-out split, never seen by the choice, says how it
does on new recordings.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from prsm_health.diagnostics.estimators import FOREST_TREES, FaultClassifier

from .evaluation import cross_validated_metrics


@dataclass(frozen=True)
class Candidate:
    """One fault model ``train`` may ship: its learner and what it reads."""

    name: str
    learner: str  # FaultClassifier(learner=…)
    reads: str  # "indicators" or "statistics"
    description: str


CANDIDATES = (
    Candidate("boosting", "boosting", "indicators", "gradient-boosted trees on the indicators"),
    Candidate(
        "forest", "forest", "indicators", f"random forest ({FOREST_TREES} trees) on the indicators"
    ),
    Candidate(
        "plain_baseline",
        "forest",
        "statistics",
        f"plain baseline: random forest ({FOREST_TREES} trees) on per-channel mean, std, min, max",
    ),
)
BY_NAME = {c.name: c for c in CANDIDATES}


def make_classifier(candidate: Candidate, params: dict, random_state: int = 0) -> FaultClassifier:
    """The unfitted classifier of a candidate (``params``: the boosting settings)."""
    return FaultClassifier(**params, learner=candidate.learner, random_state=random_state)


def cross_validate_candidates(inputs: dict, labels, groups, cv, params, random_state=0) -> dict:
    """Each candidate's cross-validated fault metrics, all by the same folds: ``inputs`` maps
    what a candidate reads (``"indicators"``, ``"statistics"``) to its training matrix; a
    candidate whose matrix has no column is left out. ``macro_f1``, ``accuracy`` … as
    :func:`~prsm_health.training.evaluation.cross_validated_metrics`, plus ``n_features`` and
    ``model`` (the description)."""
    out = {}
    for candidate in CANDIDATES:
        x = inputs[candidate.reads]
        if x.shape[1] == 0:
            continue
        metrics = cross_validated_metrics(
            lambda c=candidate: make_classifier(c, params, random_state),
            x,
            np.asarray(labels),
            groups=groups,
            cv=cv,
        )
        metrics["n_features"] = int(x.shape[1])
        metrics["model"] = candidate.description
        out[candidate.name] = metrics
    return out


def choose(scores: dict) -> tuple[str, list[str]]:
    """The candidate to ship (the best cross-validated macro-F1, ties to the earlier) and the
    sentences ``train`` says about the choice: one when the plain baseline wins."""
    order = [c.name for c in CANDIDATES if c.name in scores]
    best = max(order, key=lambda name: (scores[name]["macro_f1"], -order.index(name)))
    notes = []
    if best == "plain_baseline":
        indicator = max(
            (scores[n]["macro_f1"] for n in order if n != "plain_baseline"), default=None
        )
        shown = (
            "no indicator model" if indicator is None else f"the indicators' best {indicator:.2f}"
        )
        notes.append(
            f"the {BY_NAME[best].description} scores macro-F1 {scores[best]['macro_f1']:.2f} in "
            f"the same cross-validation, {shown}: on this dataset the condition indicators "
            "lose to plain statistics, so the plain baseline is shipped as the fault model "
            "(it diagnoses by the same path; docs/import.md)"
        )
    return best, notes
