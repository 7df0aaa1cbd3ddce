"""Axial stiffness of the whole PRSM: rollers in parallel, sides in series, plus the shaft.

Load path of an axial load F (nut loaded, screw held by its axial bearing)::

    nut ─┬─ roller 1: nut-side threads ── roller body ── screw-side threads ─┬─ screw shaft ─ bearing
         ├─ roller 2: …                                                     │  K = E·A/L_free
         └─ roller n_R                                                      ┘

Rollers share the load in parallel, each with its own axial gap (:mod:`.clearance`); one
roller's law is the load distribution over its engaged threads (:mod:`.thread_load`).

References
----------
- Paper 04 (docs/references.md) — 1/K_total = 1/K_engaged + 1/K_shaft with
  K_shaft = E_S π r_S²/L_free, the clearance/eccentricity discussion.
- Paper 01 (docs/references.md) §2.2 — K_sca = (Σ 1/K_pair)^(-1)·n_r.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import ConvergenceError, require

from ._thread_inputs import _as_array, _check_combination, _fmt_values
from .clearance import eccentricity_to_gaps
from .thread_compliance import shaft_stiffness
from .thread_load import _roller_model, _RollerModel, _RollerState, _stiffness_from_compliance

#: Iterations of the safeguarded Newton search for the common approach of rollers with gaps.
_APPROACH_MAXITER = 200


@dataclass(frozen=True, eq=False)
class AxialStiffness:
    """Axial load–deformation state of the whole mechanism.

    Arrays carry a leading load axis when ``load`` was an array; scalars otherwise.

    Attributes
    ----------
    load : [N]
    deformation : [m]
        Axial displacement of the nut relative to the screw's bearing: engagement approach
        (from the first roller to touch) + shaft.
    secant_stiffness : [N/m]
        F/δ (0 at F = 0, its limit).
    tangent_stiffness : [N/m]
        dF/dδ (0 at F = 0, where the Hertz compliance is infinite).
    roller_loads : (…, n_R) [N]
    roller_deflections : (…, n_R) [m]
        Axial approach of each roller's engagement (screw side + nut side); 0 if unloaded.
    thread_loads_screw, thread_loads_nut : (…, n_R, n) [N]
        Axial load per engaged thread, thread 1 first.
    deformation_split : dict of [m]
        ``contact``, ``teeth``, ``bodies`` (load-weighted over rollers and threads),
        ``gaps`` (load-weighted roller gap) and ``shaft``; they sum to ``deformation``.
    roller_gaps : (n_R,) [m]
        Axial gaps used, shifted so the smallest is 0.
    combination : str
    """

    load: np.ndarray
    deformation: np.ndarray
    secant_stiffness: np.ndarray
    tangent_stiffness: np.ndarray
    roller_loads: np.ndarray
    roller_deflections: np.ndarray
    thread_loads_screw: np.ndarray
    thread_loads_nut: np.ndarray
    deformation_split: dict
    roller_gaps: np.ndarray
    combination: str


def _mechanism_roller_states(model: _RollerModel, loads: np.ndarray, gaps: np.ndarray):
    """Common approach Δ (L,) and per-(load, roller) states for rollers with axial gaps."""
    n_roll = gaps.size
    n_load = loads.size
    uniq, inverse, counts = np.unique(gaps, return_inverse=True, return_counts=True)
    if uniq.size == 1:
        st = model.solve("load", loads / n_roll)
        delta = st.deflection.sum(axis=1)
        return delta, [st] * n_roll, inverse

    # Σ_i W_i(Δ − g_i) = F is monotone in Δ. Bracket: all rollers at gap 0 would need
    # Δ = δ(F/n_R) (a lower bound, gaps only unload), the gap-0 roller alone carrying F
    # needs δ(F) (an upper bound). Safeguarded Newton with the exact tangent Σ k_i.
    pos = loads > 0
    lo = np.zeros(n_load)
    hi = np.zeros(n_load)
    lo[pos] = model.solve("load", loads[pos] / n_roll).deflection.sum(axis=1)
    hi[pos] = model.solve("load", loads[pos]).deflection.sum(axis=1)
    delta = lo.copy()
    done = ~pos
    for _ in range(_APPROACH_MAXITER):
        trial = delta[:, None] - uniq[None, :]
        st = model.solve("roller", trial.ravel())
        w = st.load.reshape(n_load, uniq.size)
        k = _stiffness_from_compliance(st.compliance.sum(axis=1)).reshape(n_load, uniq.size)
        f = w @ counts - loads
        fp = k @ counts
        done = (np.abs(f) <= 1e-12 * np.maximum(loads, 1e-300)) | ~pos
        if np.all(done):
            break
        lo = np.where(f < 0, delta, lo)
        hi = np.where(f > 0, delta, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = delta - f / fp
        bad = ~np.isfinite(newton) | (newton <= lo) | (newton >= hi)
        delta = np.where(done, delta, np.where(bad, 0.5 * (lo + hi), newton))
    else:  # pragma: no cover
        raise ConvergenceError(
            "axial stiffness: the common approach of the rollers did not converge in "
            f"{_APPROACH_MAXITER} iterations for load F = {_fmt_values(loads[~done])} N "
            f"with roller gaps {_fmt_values(gaps)} m ({model.context})"
        )
    trial = delta[:, None] - uniq[None, :]
    st = model.solve("roller", trial.ravel())
    states = []
    for u in range(uniq.size):
        sel = np.arange(n_load) * uniq.size + u
        states.append(
            _RollerState(
                st.load[sel],
                st.screw[sel],
                st.nut[sel],
                st.deflection[sel],
                st.compliance[sel],
                st.split[sel],
            )
        )
    return delta, states, inverse


def axial_stiffness(
    design: PRSMDesign,
    load,
    *,
    roller_gaps=None,
    eccentricity: float | None = None,
    combination: str = "distributed",
) -> AxialStiffness:
    """Axial stiffness of the PRSM: rollers in parallel, sides in series, plus the shaft.

    Parameters
    ----------
    design : PRSMDesign
    load : float or array_like [N]
        Total axial load F on the nut, ≥ 0.
    roller_gaps : array_like (n_R,) [m] or None
        Axial gap of each roller's load path, ≥ 0 (e.g. from :func:`radial_to_axial_gap`).
        A roller carries load only once the common approach exceeds its gap. Gaps are
        measured from the first roller to touch (a common offset changes nothing).
    eccentricity : float [m] or None
        Screw–nut radial eccentricity; adds :func:`eccentricity_to_gaps` to the gaps.
    combination : {"distributed", "uniform", "paper01_series"}
        How the engaged threads of one roller combine (:mod:`.thread_load`).

    Returns
    -------
    AxialStiffness

    Notes
    -----
    1/K = 1/K_engaged + 1/K_shaft with K_engaged = Σ_i k_i over the loaded rollers (tangent)
    and K_shaft = E A/L_free. Without gaps each roller carries F/n_R.

    References
    ----------
    Paper 04, 1/K_total = 1/K_engaged + 1/K_shaft and the clearance/eccentricity discussion;
    paper 01 §2.2, K_sca = (Σ 1/K_pair)^(-1)·n_r for ``"paper01_series"``.
    """
    _check_combination(combination)
    f = _as_array("load", load)
    scalar = f.ndim == 0
    loads = np.atleast_1d(f).ravel()
    n_roll = design.n_rollers
    if roller_gaps is None:
        gaps = np.zeros(n_roll)
    else:
        gaps = _as_array("roller_gaps", roller_gaps)
        require(
            gaps.shape == (n_roll,),
            "roller_gaps",
            f"array of shape {gaps.shape}",
            f"must have one gap per roller, shape ({n_roll},)",
        )
    if eccentricity is not None:
        gaps = gaps + eccentricity_to_gaps(design, eccentricity)
    gaps = gaps - gaps.min()

    model = _roller_model(design, combination)
    delta, states, inverse = _mechanism_roller_states(model, loads, gaps)
    n_load = loads.size
    w = np.stack([states[inverse[i]].load for i in range(n_roll)], axis=1)
    defl = np.stack([states[inverse[i]].deflection.sum(axis=1) for i in range(n_roll)], axis=1)
    comp = np.stack([states[inverse[i]].compliance.sum(axis=1) for i in range(n_roll)], axis=1)
    split = np.stack([states[inverse[i]].split.sum(axis=1) for i in range(n_roll)], axis=1)
    q_s = np.stack([states[inverse[i]].screw for i in range(n_roll)], axis=1)
    q_n = np.stack([states[inverse[i]].nut for i in range(n_roll)], axis=1)

    k_shaft = shaft_stiffness(design)
    k_eng = _stiffness_from_compliance(comp).sum(axis=1)
    shaft = loads / k_shaft
    deformation = delta + shaft
    pos = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        secant = np.where(pos, loads / np.where(pos, deformation, 1.0), 0.0)
        tangent = np.where(
            k_eng > 0, 1.0 / (1.0 / np.where(k_eng > 0, k_eng, 1.0) + 1.0 / k_shaft), 0.0
        )
        weight = np.where(pos[:, None], w / np.where(pos, loads, 1.0)[:, None], 0.0)
    parts = {
        "contact": np.sum(weight * split[:, :, 0], axis=1),
        "teeth": np.sum(weight * split[:, :, 1], axis=1),
        "bodies": np.sum(weight * split[:, :, 2], axis=1),
        "gaps": weight @ gaps,
        "shaft": shaft,
    }

    def out(arr):
        return arr[0] if scalar else arr.reshape((n_load,) + arr.shape[1:])

    return AxialStiffness(
        load=out(loads),
        deformation=out(deformation),
        secant_stiffness=out(secant),
        tangent_stiffness=out(tangent),
        roller_loads=out(w),
        roller_deflections=out(np.where(w > 0, defl, 0.0)),
        thread_loads_screw=out(q_s),
        thread_loads_nut=out(q_n),
        deformation_split={k: out(v) for k, v in parts.items()},
        roller_gaps=gaps,
        combination=combination,
    )
