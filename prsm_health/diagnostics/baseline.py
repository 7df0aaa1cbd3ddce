"""Each unit against its own baseline: a robust baseline of a unit's indicators, the class
evidence accumulated over its recordings, and a sequential change detector.

Units of one design differ: an indicator's level depends on the unit's build (preload, roller
set, installation), often by more than an early fault moves it. A unit read against its own
baseline — its first recordings, when it is known to be healthy — sees the change a fault makes
rather than the spread between units. Three pure, frozen values (numpy only) do the work, and
:mod:`prsm_health.diagnostics.asset_history` keeps them per unit:

* :class:`Baseline`: robust centre and scale of each indicator over the unit's baseline
  recordings, the scale shrunk toward the within-unit repeatability the model learned while
  the recordings are few; a recording's robust z-scores against it and one change score (the
  RMS of the z-scores).
* :class:`Evidence`: a sequential Bayesian update of the class posterior with each recording's
  calibrated class probabilities, with a floor (no single recording vetoes a class) and
  exponential forgetting (a unit whose state changes is followed).
* :class:`Cusum`: Page's one-sided CUSUM on the change score: a small change that persists
  over recordings raises the alarm, one odd recording does not.

Every value has ``to_json``/``from_json`` (an exact round trip: floats are written in their
shortest exact form). docs/diagnostics.md, "Each unit against its own baseline", explains the
choices with numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from prsm_health.core.errors import ParameterError, require

from .contract import CANNOT_TELL

#: 1/Φ⁻¹(3/4): makes the median absolute deviation a consistent estimate of a normal
#: distribution's standard deviation (Hampel 1974).
MAD_TO_SIGMA = 1.482602218505602
#: Small-sample factors b_n that make 1.4826·MAD unbiased for normal samples of n = 2 … 9
#: (Croux & Rousseeuw 1992; for n > 9, b_n = n/(n − 0.8)). With the three
#: recordings of a baseline the uncorrected MAD is a third too small on average (b_3 = 1.495).
MAD_SMALL_SAMPLE = {2: 1.196, 3: 1.495, 4: 1.363, 5: 1.206, 6: 1.200, 7: 1.140, 8: 1.129, 9: 1.107}
#: Weight of the prior scale, in pseudo-recordings (``Baseline.fit(prior_weight=…)``): at the
#: three recordings of a baseline the prior and the unit's own spread weigh 3 : 2, at ten
#: recordings 3 : 9.
PRIOR_WEIGHT = 3.0
#: A scale is never below this fraction of |centre| (an indicator that repeated exactly over
#: the baseline recordings would otherwise turn any change into an infinite z-score) …
CENTRE_FLOOR = 0.01
#: … nor below this fraction of the prior scale, where one is given.
PRIOR_FLOOR = 0.1
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


def _finite(value) -> float | None:
    """``value`` as a finite float, or None (missing, None, NaN, ±inf, not a number)."""
    if value is None or isinstance(value, bool):
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def mad_factor(n: int) -> float:
    """Factor turning the MAD of ``n`` normal values into an unbiased standard deviation:
    :data:`MAD_TO_SIGMA` times Croux & Rousseeuw's small-sample factor b_n."""
    b = MAD_SMALL_SAMPLE.get(n, n / (n - 0.8) if n > 9 else 1.0)
    return MAD_TO_SIGMA * b


def shrunk_scale(own: float, n: int, prior: float | None, weight: float) -> float:
    """The scale of ``n`` recordings with robust spread ``own``, shrunk toward ``prior``.

    σ̂² = (ν₀ σ₀² + (n − 1) s²) / (ν₀ + n − 1): the posterior mean of σ² under a scaled
    inverse-χ² prior with ν₀ = ``weight`` degrees of freedom at σ₀ = ``prior`` and a flat prior
    on the centre (Gelman et al., BDA3, section 3.3). n − 1 because the centre is estimated
    from the same recordings. Without a prior, ``own``.
    """
    if prior is None:
        return own
    dof = max(n - 1, 0)
    if weight + dof <= 0:
        return own
    return math.sqrt((weight * prior**2 + dof * own**2) / (weight + dof))


@dataclass(frozen=True)
class Baseline:
    """A unit's baseline: robust centre and scale of each indicator over its baseline
    recordings.

    Parameters
    ----------
    names : tuple of str
        The indicators, in order.
    center : tuple of float
        Median of each indicator over the baseline recordings [the indicator's unit].
    scale : tuple of float
        Robust scale of each (> 0) [the indicator's unit], see :meth:`fit`.
    count : int
        Recordings the baseline was fitted on.
    recordings : tuple of str
        Their identifiers (may be empty).

    References
    ----------
    .. [1] F. R. Hampel, "The influence curve and its role in robust estimation", JASA 69
       (1974) 383–393 (the median absolute deviation, 1.4826·MAD).
    .. [2] C. Croux, P. J. Rousseeuw, "Time-efficient algorithms for two highly robust
       estimators of scale", in Computational Statistics, vol. 1, Physica-Verlag, 1992,
       411–428 (small-sample factors b_n of the MAD; checked here by simulation).
    .. [3] A. Gelman, J. B. Carlin, H. S. Stern, D. B. Dunson, A. Vehtari, D. B. Rubin,
       *Bayesian Data Analysis*, 3rd ed., CRC Press, 2013, section 3.3 (normal model with a
       scaled inverse-χ² prior on the variance: the prior counts as ν₀ observations).
    """

    names: tuple[str, ...]
    center: tuple[float, ...]
    scale: tuple[float, ...]
    count: int
    recordings: tuple[str, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "names", tuple(str(n) for n in self.names))
        object.__setattr__(self, "center", tuple(float(c) for c in self.center))
        object.__setattr__(self, "scale", tuple(float(s) for s in self.scale))
        object.__setattr__(self, "recordings", tuple(str(r) for r in self.recordings))
        k = len(self.names)
        require(
            len(self.center) == k and len(self.scale) == k,
            "Baseline.center/scale",
            (len(self.center), len(self.scale)),
            f"one value per indicator ({k})",
        )
        require(
            all(math.isfinite(c) for c in self.center),
            "Baseline.center",
            self.center,
            "finite values",
        )
        require(
            all(math.isfinite(s) and s > 0 for s in self.scale),
            "Baseline.scale",
            self.scale,
            "finite values > 0",
        )
        require(
            isinstance(self.count, int) and self.count >= 1,
            "Baseline.count",
            self.count,
            "an integer >= 1",
        )

    @classmethod
    def fit(
        cls,
        rows: Sequence[Mapping[str, float | None]],
        *,
        prior_scale: Mapping[str, float] | None = None,
        names: Sequence[str] | None = None,
        recordings: Sequence[str] = (),
        prior_weight: float = PRIOR_WEIGHT,
    ) -> Baseline:
        """Fit a baseline to a unit's baseline recordings.

        Per indicator, over the recordings where it is finite (NaN and None are ignored):
        the centre is the median; the scale is b_n·1.4826·MAD (unbiased for normal values,
        [1]_ [2]_), shrunk toward ``prior_scale`` as a scaled inverse-χ² prior worth
        ``prior_weight`` recordings ([3]_, :func:`shrunk_scale`), so that 2–5 recordings give
        a usable scale and many recordings their own. The scale is at least
        :data:`CENTRE_FLOOR`·|centre| and :data:`PRIOR_FLOOR`·prior (never 0).

        Parameters
        ----------
        rows : sequence of mappings
            Indicator name → value, one mapping per recording (at least one).
        prior_scale : mapping or None
            Indicator → the within-unit repeatability (standard deviation between recordings
            of one healthy unit) the model learned [the indicator's unit]; indicators without
            one (or with one that is not finite and > 0) get their own spread only.
        names : sequence of str or None
            The indicators to fit; those with no finite value are left out. Default: every
            indicator finite in all the rows, in the order of the first row.
        recordings : sequence of str
            Identifiers of the rows (empty, or one per row).
        prior_weight : float
            ν₀ ≥ 0, the prior's weight in recordings.

        Returns
        -------
        Baseline

        Raises
        ------
        ParameterError
            No rows, ``recordings`` not one per row, a negative ``prior_weight``, or no
            indicator to fit.
        """
        rows = list(rows)
        recordings = tuple(str(r) for r in recordings)
        require(len(rows) >= 1, "rows", len(rows), "a baseline needs at least one recording")
        require(
            not recordings or len(recordings) == len(rows),
            "recordings",
            len(recordings),
            f"empty or one identifier per row ({len(rows)})",
        )
        require(
            _finite(prior_weight) is not None and prior_weight >= 0,
            "prior_weight",
            prior_weight,
            "a finite number >= 0",
        )
        # a prior of 0 (an indicator that never varied between the model's repeat recordings)
        # or NaN says nothing usable about this unit's scale: the unit's own spread decides
        priors = {
            str(name): float(value)
            for name, value in (prior_scale or {}).items()
            if _finite(value) is not None and value > 0
        }
        if names is None:
            names = [n for n in rows[0] if all(_finite(r.get(n)) is not None for r in rows)]
        kept, centres, scales = [], [], []
        for name in dict.fromkeys(names):
            values = np.array(
                [v for v in (_finite(r.get(name)) for r in rows) if v is not None], dtype=float
            )
            if values.size == 0:
                continue
            centre = float(np.median(values))
            n = values.size
            own = mad_factor(n) * float(np.median(np.abs(values - centre))) if n > 1 else 0.0
            prior = priors.get(name)
            scale = shrunk_scale(own, n, prior, float(prior_weight))
            floor = max(CENTRE_FLOOR * abs(centre), PRIOR_FLOOR * (prior or 0.0))
            # an indicator identically 0 over the baseline, without a prior: the smallest
            # scale that keeps every z-score finite
            scale = max(scale, floor) if max(scale, floor) > 0 else float(np.finfo(float).eps)
            kept.append(str(name))
            centres.append(centre)
            scales.append(scale)
        if not kept:
            raise ParameterError(
                "names", list(names), "no indicator is finite in the baseline recordings"
            )
        return cls(tuple(kept), tuple(centres), tuple(scales), len(rows), recordings)

    def change(self, row: Mapping[str, float | None]) -> dict[str, float]:
        """Robust z-score of each baseline indicator: (x − centre)/scale [-]; NaN where the
        recording lacks the indicator (missing, None, NaN)."""
        out = {}
        for name, centre, scale in zip(self.names, self.center, self.scale):
            x = _finite(row.get(name))
            out[name] = float("nan") if x is None else (x - centre) / scale
        return out

    def distance(self, row: Mapping[str, float | None]) -> float:
        """One change score: the root mean square of the finite z-scores of :meth:`change`.

        0 at the baseline's centre; about 1 for a recording that scatters as the baseline's
        recordings do (each z² has mean ≈ 1); larger as more indicators move, or further. The
        mean rather than the sum keeps the score comparable between units with different
        numbers of computable indicators. NaN when no z-score is finite.
        """
        z = np.array(list(self.change(row).values()), dtype=float)
        z = z[np.isfinite(z)]
        return float(np.sqrt(np.mean(z**2))) if z.size else float("nan")

    def to_json(self) -> dict:
        """Plain JSON values; :meth:`from_json` restores an equal baseline."""
        return {
            "names": list(self.names),
            "center": list(self.center),
            "scale": list(self.scale),
            "count": self.count,
            "recordings": list(self.recordings),
        }

    @classmethod
    def from_json(cls, data: Mapping) -> Baseline:
        """The baseline of :meth:`to_json`'s values."""
        return cls(
            tuple(data["names"]),
            tuple(data["center"]),
            tuple(data["scale"]),
            int(data["count"]),
            tuple(data.get("recordings", ())),
        )


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
        require(_finite(floor) is not None and 0 < floor < 1, "floor", floor, "in (0, 1)")
        require(
            _finite(forgetting) is not None and 0 < forgetting <= 1,
            "forgetting",
            forgetting,
            "in (0, 1]",
        )
        prior = _class_weights(self.classes, training_prior, "training_prior")
        p = np.array([_finite(probabilities.get(c, 0.0)) or 0.0 for c in self.classes])
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
    values = np.array([_finite(weights[c]) or 0.0 for c in classes])
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
            _finite(self.statistic) is not None and self.statistic >= 0,
            "Cusum.statistic",
            self.statistic,
            "a finite number >= 0",
        )
        require(_finite(self.reference) is not None, "Cusum.reference", self.reference, "finite")
        require(
            _finite(self.threshold) is not None and self.threshold > 0,
            "Cusum.threshold",
            self.threshold,
            "a finite number > 0",
        )

    def update(self, value: float) -> Cusum:
        """The statistic after one more change score ``value``; a missing (None, NaN) score
        leaves it as it is."""
        x = _finite(value)
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
