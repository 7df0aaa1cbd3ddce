"""The class evidence accumulated over a unit's recordings and a sequential change detector
on its distance from its baseline (:class:`prsm_health.diagnostics.baseline.Baseline`).

* :class:`Evidence`: a sequential Bayesian update of the class posterior with each recording's
  calibrated class probabilities, with a floor (no single recording vetoes a class) and
  exponential forgetting (a unit whose state changes is followed).
* :class:`Cusum`: Page's one-sided CUSUM on the change score: a small change that persists
  over recordings raises the alarm, one odd recording does not.

Both are pure, frozen values with ``to_json``/``from_json`` (an exact round trip).
docs/diagnostics.md, "Each unit against its own baseline", explains the choices with numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from prsm_health.core.errors import require
from prsm_health.core.jsonable import as_finite
from prsm_health.diagnostics.contract import CANNOT_TELL

#: Floor of a class probability in :meth:`Evidence.update`: one recording changes a class's
#: odds by at most a factor 1/0.01 = 100 (about two recordings' worth at p = 0.9 against 0.1).
EVIDENCE_FLOOR = 0.01
#: Default forgetting factor λ of :meth:`Evidence.update`: old log evidence is multiplied by λ
#: before a recording's is added, a memory of 1/(1 − λ) = 5 recordings (docs/diagnostics.md).
FORGETTING = 0.8
#: Posterior a class needs for :meth:`Evidence.named` to name it. Stricter than a single
#: recording's 0.5: recordings of one unit are not quite independent given its class (the
#: same build, the same installation), so the product of their likelihood ratios overstates
#: the evidence.
EVIDENCE_NAME_PROBABILITY = 0.9
#: Default CUSUM reference k on the change score (:class:`Cusum`): above the score of a
#: recording like the baseline (median 1.1–1.25, 95th percentile 1.6–2.0 for a 3-recording
#: baseline, docs/diagnostics.md), so the statistic stays near 0 while nothing changes.
CUSUM_REFERENCE = 1.5
#: Default CUSUM threshold h: a persistent score of 2.5 (every indicator about two baseline
#: scales away) alarms at the 6th recording, a score above k + h = 6.5 at once; in
#: simulation 0–5 % of unchanged units alarmed within 200 recordings (docs/diagnostics.md).
CUSUM_THRESHOLD = 5.0


def _normalised(log_p: np.ndarray) -> np.ndarray:
    """Log probabilities normalised to sum 1 (log-sum-exp)."""
    top = np.max(log_p)
    return log_p - (top + math.log(float(np.sum(np.exp(log_p - top)))))


def named_class(posterior: Mapping[str, float], threshold: float) -> str:
    """The most probable class of ``posterior`` (class → probability) when it reaches
    ``threshold``, else ``cannot_tell``."""
    best = max(posterior, key=posterior.get)
    return best if posterior[best] >= threshold else CANNOT_TELL


@dataclass(frozen=True)
class Evidence:
    """The class evidence accumulated over a unit's recordings: a log posterior per class.

    Parameters
    ----------
    classes : tuple of str
        The classes, in order.
    log_posterior : tuple of float
        Normalised log posterior of each (its exponentials sum to 1).
    recordings : int
        Recordings whose evidence has been added.

    References
    ----------
    .. [1] N. Morgan, H. Bourlard, "Continuous speech recognition: an introduction to the
       hybrid HMM/connectionist approach", IEEE Signal Processing Magazine 12(3) (1995)
       25–42 (a classifier's posterior divided by its training prior is a scaled likelihood).
    .. [2] R. Kulhavý, M. B. Zarrop, "On a general concept of forgetting", International
       Journal of Control 58(4) (1993) 905–924 (exponential forgetting: the old posterior
       raised to the power λ before the new evidence is added).
    .. [3] V. Peterka, "Bayesian system identification", Automatica 17(1) (1981) 41–53
       (the same forgetting for tracking slowly changing parameters; memory ≈ 1/(1 − λ)).
    """

    classes: tuple[str, ...]
    log_posterior: tuple[float, ...]
    recordings: int = 0

    def __post_init__(self):
        object.__setattr__(self, "classes", tuple(str(c) for c in self.classes))
        object.__setattr__(self, "log_posterior", tuple(float(v) for v in self.log_posterior))
        require(len(self.classes) >= 1, "Evidence.classes", self.classes, "at least one class")
        require(
            len(set(self.classes)) == len(self.classes),
            "Evidence.classes",
            self.classes,
            "distinct classes",
        )
        require(
            len(self.log_posterior) == len(self.classes),
            "Evidence.log_posterior",
            len(self.log_posterior),
            f"one value per class ({len(self.classes)})",
        )
        require(
            all(math.isfinite(v) for v in self.log_posterior),
            "Evidence.log_posterior",
            self.log_posterior,
            "finite values",
        )

    @classmethod
    def start(cls, classes: Sequence[str], prior: Mapping[str, float] | None = None) -> Evidence:
        """Evidence before any recording: ``prior`` (class → probability > 0, normalised
        here), uniform by default."""
        classes = tuple(str(c) for c in classes)
        weights = _class_weights(classes, prior, "prior")
        return cls(classes, tuple(_normalised(np.log(weights)).tolist()), 0)

    def update(
        self,
        probabilities: Mapping[str, float],
        *,
        training_prior: Mapping[str, float] | None = None,
        floor: float = EVIDENCE_FLOOR,
        forgetting: float = FORGETTING,
    ) -> Evidence:
        """The evidence after one more recording.

        A calibrated classifier's probability p_k divided by its training prior π_k is the
        recording's likelihood of class k up to a constant ([1]_); with recordings
        conditionally independent given the class,

            log P_t(k) = λ · log P_{t−1}(k) + log max(p_k, floor) − log π_k  (+ const),

        normalised. λ = ``forgetting`` discounts old evidence exponentially ([2]_, [3]_):
        it is worth λ^m after m more recordings, so a unit whose state changes is followed
        instead of being held by its past; the memory is about 1/(1 − λ) recordings, and a
        steady log-likelihood ratio ℓ per recording saturates at ℓ/(1 − λ) (no unbounded
        certainty). λ = 1: no forgetting. The floor bounds what one recording can do: it
        changes a class's odds by at most a factor 1/floor, so one recording (a glitch, a
        window the model misread) cannot veto a class.

        Parameters
        ----------
        probabilities : mapping
            Class → calibrated probability of the recording; a class of the evidence missing
            here counts as probability 0 (then the floor).
        training_prior : mapping or None
            Class → the class's share of the classifier's training set (normalised here);
            default uniform (the prior of a class-balanced classifier).
        floor : float
            Probability floor, in (0, 1).
        forgetting : float
            λ in (0, 1].

        Raises
        ------
        ParameterError
            A class the evidence does not track, a floor or forgetting factor out of range,
            a training prior not > 0.
        """
        unknown = [c for c in probabilities if str(c) not in self.classes]
        require(
            not unknown,
            "probabilities",
            unknown,
            f"classes of the evidence only: {', '.join(self.classes)}",
        )
        require(as_finite(floor) is not None and 0 < floor < 1, "floor", floor, "in (0, 1)")
        require(
            as_finite(forgetting) is not None and 0 < forgetting <= 1,
            "forgetting",
            forgetting,
            "in (0, 1]",
        )
        prior = _class_weights(self.classes, training_prior, "training_prior")
        p = np.array([as_finite(probabilities.get(c, 0.0)) or 0.0 for c in self.classes])
        log_lik = np.log(np.maximum(p, floor)) - np.log(prior)
        log_post = forgetting * np.array(self.log_posterior) + log_lik
        return Evidence(self.classes, tuple(_normalised(log_post).tolist()), self.recordings + 1)

    def posterior(self) -> dict[str, float]:
        """Class → posterior probability (sum 1)."""
        p = np.exp(np.array(self.log_posterior))
        p = p / p.sum()
        return {c: float(v) for c, v in zip(self.classes, p)}

    def named(self, threshold: float = EVIDENCE_NAME_PROBABILITY) -> str:
        """The class whose posterior reaches ``threshold``, else ``cannot_tell``."""
        return named_class(self.posterior(), threshold)

    def to_json(self) -> dict:
        """Plain JSON values; :meth:`from_json` restores an equal value."""
        return {
            "classes": list(self.classes),
            "log_posterior": list(self.log_posterior),
            "recordings": self.recordings,
        }

    @classmethod
    def from_json(cls, data: Mapping) -> Evidence:
        return cls(tuple(data["classes"]), tuple(data["log_posterior"]), int(data["recordings"]))


def _class_weights(classes: tuple[str, ...], weights: Mapping | None, field: str) -> np.ndarray:
    """``weights`` of ``classes`` normalised to sum 1 (uniform when None); each must be > 0."""
    if weights is None:
        return np.full(len(classes), 1.0 / len(classes))
    missing = [c for c in classes if c not in weights]
    require(not missing, field, sorted(weights), f"a value for every class: {', '.join(classes)}")
    values = np.array([as_finite(weights[c]) or 0.0 for c in classes])
    require(bool(np.all(values > 0)), field, dict(weights), "probabilities > 0 for every class")
    return values / values.sum()


@dataclass(frozen=True)
class Cusum:
    """Page's one-sided CUSUM on the baseline distance:
    S_t = max(0, S_{t−1} + x_t − k), alarm while S_t > h.

    A recording like the baseline scores below the reference k and pulls the statistic back
    toward 0; a change that persists adds x − k per recording until the threshold h is
    crossed, so a small lasting change alarms after a few recordings and one odd recording
    (below k + h) never does. The alarm holds while the statistic is above h.

    Parameters
    ----------
    statistic : float
        S_t ≥ 0.
    reference : float
        k, the change score a recording must exceed to add to the statistic.
    threshold : float
        h > 0.
    alarm : bool
        S_t > h.

    References
    ----------
    .. [1] E. S. Page, "Continuous inspection schemes", Biometrika 41 (1954) 100–115.
    .. [2] D. C. Montgomery, *Introduction to Statistical Quality Control*, 7th ed., Wiley,
       2013, section 9.1 (the tabular CUSUM, choice of k and h).
    """

    statistic: float = 0.0
    reference: float = CUSUM_REFERENCE
    threshold: float = CUSUM_THRESHOLD
    alarm: bool = False

    def __post_init__(self):
        require(
            as_finite(self.statistic) is not None and self.statistic >= 0,
            "Cusum.statistic",
            self.statistic,
            "a finite number >= 0",
        )
        require(as_finite(self.reference) is not None, "Cusum.reference", self.reference, "finite")
        require(
            as_finite(self.threshold) is not None and self.threshold > 0,
            "Cusum.threshold",
            self.threshold,
            "a finite number > 0",
        )

    def update(self, value: float) -> Cusum:
        """The statistic after one more change score ``value``; a missing (None, NaN) score
        leaves it as it is."""
        x = as_finite(value)
        if x is None:
            return self
        s = max(0.0, self.statistic + x - self.reference)
        return Cusum(s, self.reference, self.threshold, s > self.threshold)

    def to_json(self) -> dict:
        return {
            "statistic": self.statistic,
            "reference": self.reference,
            "threshold": self.threshold,
            "alarm": self.alarm,
        }

    @classmethod
    def from_json(cls, data: Mapping) -> Cusum:
        return cls(
            float(data["statistic"]),
            float(data["reference"]),
            float(data["threshold"]),
            bool(data["alarm"]),
        )
