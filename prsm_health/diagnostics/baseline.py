"""A unit's own baseline: robust centre and scale of its indicators, against which a health
check is read (:func:`prsm_health.diagnostics.diagnosis.diagnose` with ``baseline``).

Units of one design differ: an indicator's level depends on the unit's build (preload, roller
set, installation), often by more than an early fault moves it. A unit read against its own
baseline — its first recordings, when it is known to be healthy — sees the change a fault makes
rather than the spread between units. The baseline is inference's input; the evidence and the
change statistic accumulated over a unit's recordings are :mod:`prsm_health.monitoring.evidence`,
and :mod:`prsm_health.monitoring` keeps all three per unit:

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
from prsm_health.core.jsonable import as_finite

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
            as_finite(prior_weight) is not None and prior_weight >= 0,
            "prior_weight",
            prior_weight,
            "a finite number >= 0",
        )
        # a prior of 0 (an indicator that never varied between the model's repeat recordings)
        # or NaN says nothing usable about this unit's scale: the unit's own spread decides
        priors = {
            str(name): float(value)
            for name, value in (prior_scale or {}).items()
            if as_finite(value) is not None and value > 0
        }
        if names is None:
            names = [n for n in rows[0] if all(as_finite(r.get(n)) is not None for r in rows)]
        kept, centres, scales = [], [], []
        for name in dict.fromkeys(names):
            values = np.array(
                [v for v in (as_finite(r.get(name)) for r in rows) if v is not None], dtype=float
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
            x = as_finite(row.get(name))
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
