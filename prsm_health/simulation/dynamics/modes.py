"""The nut's modes: the simulator's model linearised on the loaded flanks at an axial load.

The signals layer tracks the nut's axial contact mode in the band these modes predict
(:mod:`prsm_health.signals.axial_mode`); the model's parameter layout stays in this layer.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.states import HealthState, ManufacturingVariation, OperatingProfile

from . import layout as L
from .model import SimulationOptions, build_model
from .simulate import linearised_modes


def nut_modes(
    design: PRSMDesign, load: float, drive_train: DriveTrain, thread_stiffness_scale: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues [1/s] of the model linearised on the loaded flanks at the axial ``load`` [N],
    and each mode's peak nut accelerance [1/kg] (nut acceleration per force on the nut).

    The flank law is linearised at the load (paper 04's tangent stiffness there; the Hertzian
    law's power-law fit would move it by < 0.3 %), rollers identical, healthy; the drive train
    as given (close its backlash and play to linearise it loaded too).
    ``thread_stiffness_scale`` multiplies both thread contacts' law coefficient (a mode's
    sensitivity to the thread stiffness).

    References
    ----------
    Paper 04 (thread axial stiffness, Hertz contact k_H = dQ/dδ_H).
    """
    options = SimulationOptions(
        contact_law="linear", variation=ManufacturingVariation.ideal(), operating_load=load
    )
    profile = OperatingProfile(duration=0.1, speed=100.0, load=load)
    model = build_model(design, HealthState.uniform(0.0), profile, options, 0, drive_train)
    if thread_stiffness_scale != 1.0:
        params = model.params.copy()
        params[L.P_K_THREAD_S] *= thread_stiffness_scale
        params[L.P_K_THREAD_N] *= thread_stiffness_scale
        model = replace(model, params=params)
    values, vectors, free = linearised_modes(model)
    v_nut = free.index(model.n_coordinates + L.Q_ZN)
    # Modal expansion of the state-space response, H(s) = Σ r_j/(s − λ_j): residue r_j of mode
    # j from a force on the nut (the input row of the nut's velocity, 1/m_N) to the nut's
    # velocity; the acceleration is s·H, whose peak at s = iω_j is ≈ ω_j·|r_j|/|Re λ_j|
    left = np.linalg.inv(vectors)
    residue = vectors[v_nut, :] * left[:, v_nut] / model.params[L.P_M_N]
    with np.errstate(divide="ignore", invalid="ignore"):
        peak = np.abs(residue * values.imag / values.real)
    return values, peak
