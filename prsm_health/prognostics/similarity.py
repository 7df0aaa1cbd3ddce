"""The similarity baseline, one of the RUL methods (:class:`SimilarityRUL`; Wang et al. 2008):
a history aligned to each training unit's fitted degradation curve, the units weighted by a
tempered Gaussian kernel of the alignment distance, the RUL their weighted remaining lives
(Wang, Yu, Siegel & Lee, PHM 2008).

The library curves are the training units' per-unit fits of the
chosen form; the alignment distance of library unit i is the weighted sum of squares
``d_i = min_shift sum_j (S_j - c_i(t_j + shift))^2 / (sd_j^2 + r_i^2)`` (``sd_j`` the
diagnosis' measurement standard deviation, ``r_i^2`` the unit's residual variance about its
curve beyond its measurement noise; the aligned current age ranges from the history's span
minus half the unit's life, the curve extrapolated back before its first age, to 1.5 x
the unit's life: a grid of 161 ages refined on 41 points around the best). With
``e_i = d_i - min d``, the weight is the Gaussian kernel
``w_i = exp(-e_i / (2 h))``: for ``h = 1`` the likelihood ratio of the history under unit i
against the best unit; the bandwidth ``h = max(1, e_(k) / 2)``, ``e_(k)`` the k-th smallest
excess, ``k = max(2, ceil(U / 5))``, tempers it so that the k-th nearest unit keeps at least
``exp(-1)`` of the best one's weight (a likelihood over tens of diagnoses would otherwise
single out one library unit and give an interval of zero width).
``RUL_i = T_i - aligned current age`` clipped to [0, horizon].
"""

from __future__ import annotations

import math

import numpy as np

from .degradation import DegradationRUL, curve, weighted_quantiles
from .method import Estimate, RULMethod, TrainingFleet, UnitHistory
from .prognosis import QUANTILES

# Similarity alignment: the aligned first diagnosis may lie this fraction of a library unit's
# life before the unit's first age (its curve extrapolated back). Forbidding it (shifts >= 0
# only) lets slow units align and penalizes fast or high-starting ones: an upward RUL bias.
_ALIGN_BEFORE_START = 0.5
# Similarity alignment: coarse grid of aligned ages, then a fine grid around the best.
_ALIGN_GRID = 161
_ALIGN_REFINE = 41
# Similarity bandwidth: from the excess distance of the k-th nearest library unit,
# k = max(2, ceil(U/5)).
_BANDWIDTH_NEIGHBOUR_FRACTION = 0.2


def similarity_rul(
    params, residual_var, *, form, phi, threshold, lives, t_scale, horizon, t, value, sd
):
    """RUL [h] quantiles and the details of the similarity prediction for one history
    (ages ``t`` [h], clearances ``value`` [m], their standard deviations ``sd`` [m]) against
    the library of training units (per-unit ``params`` of ``form``, their ``residual_var``,
    their failure ``lives`` [h])."""
    thr = float(threshold)
    n_units, n = len(lives), len(t)
    tiny = (1e-8 * thr) ** 2
    weights = 1.0 / (sd[None, :] ** 2 + residual_var[:, None] + tiny)  # (U, n)
    # aligned current ages from (history span - half the unit's life) to 1.5 x its life
    bottom = (t[-1] - t[0]) - _ALIGN_BEFORE_START * lives
    top = np.maximum(1.5 * lives, bottom + 1e-3 * lives)

    back = (t[-1] - t) / t_scale  # scaled time of each diagnosis before the latest
    if form == "exponential":  # exp(a + b (A - back)) = exp(a + b A) exp(-b back)
        decay = np.exp(-params[:, 1, None] * back[None, :])  # (U, n)

    def distances(aligned):  # aligned current ages (U, G) -> weighted squared distance
        now = aligned / t_scale
        if form == "exponential":
            level = np.exp(np.minimum(params[:, 0, None] + params[:, 1, None] * now, 700.0))
            fitted = phi + level[:, :, None] * decay[:, None, :]
        else:  # not named `curve`: that would hide the module's function in this scope
            fitted = curve(
                form,
                params[:, 0, None, None],
                params[:, 1, None, None],
                now[:, :, None] - back[None, None, :],
                phi,
                thr,
            )
        return np.einsum("un,ugn->ug", weights, (value[None, None, :] - fitted) ** 2)

    grid = bottom[:, None] + (top - bottom)[:, None] * np.linspace(0.0, 1.0, _ALIGN_GRID)[None, :]
    d = distances(grid)
    best = np.argmin(d, axis=1)
    rows = np.arange(n_units)
    low = grid[rows, np.maximum(best - 1, 0)]
    high = grid[rows, np.minimum(best + 1, _ALIGN_GRID - 1)]
    fine = low[:, None] + (high - low)[:, None] * np.linspace(0.0, 1.0, _ALIGN_REFINE)[None, :]
    d_fine = distances(fine)
    pick = np.argmin(d_fine, axis=1)
    aligned = fine[rows, pick]
    excess = d_fine[rows, pick]
    excess = excess - excess.min()
    k = max(2, math.ceil(_BANDWIDTH_NEIGHBOUR_FRACTION * n_units))
    bandwidth = max(1.0, 0.5 * float(np.sort(excess)[min(k, n_units) - 1]))
    w = np.exp(-excess / (2.0 * bandwidth))
    rul = np.clip(lives - aligned, 0.0, horizon)
    low_q, mid, high_q = weighted_quantiles(rul, w, QUANTILES)
    details = {
        "form": form,
        "bandwidth": bandwidth,
        "effective_units": float(w.sum() ** 2 / np.sum(w**2)),
        "nearest": int(np.argmin(excess)),
        "history_points": n,
    }
    rul_hours = {"estimate": float(mid), "lower": float(low_q), "upper": float(high_q)}
    return rul_hours, details


class SimilarityRUL(RULMethod):
    """The similarity baseline as a RUL method (module docstring): its library is the
    training units' fitted curves of the form ``library`` (a :class:`DegradationRUL`) chose,
    and their failure ages.

    Parameters
    ----------
    library : DegradationRUL
        Fitted by :meth:`fit` unless already fitted on the same fleet.
    """

    name = "similarity"

    def __init__(self, library: DegradationRUL):
        self.library = library

    def fit(self, fleet: TrainingFleet) -> SimilarityRUL:
        if getattr(self.library, "fleet_", None) is not fleet.summary:
            self.library.fit(fleet)
        return self

    def predict(self, history: UnitHistory) -> Estimate:
        library = self.library
        fleet = library.fleet_
        state = library.forms_[library.form_]
        rul, details = similarity_rul(
            state["params"],
            state["residual_var"],
            form=library.form_,
            phi=state["phi"],
            threshold=fleet.threshold,
            lives=fleet.lives,
            t_scale=fleet.t_scale,
            horizon=fleet.horizon,
            t=history.t,
            value=history.value,
            sd=history.sd,
        )
        model = {"name": self.name, **details}
        model["nearest_unit"] = fleet.units[model.pop("nearest")]
        return Estimate(rul, model, [])
