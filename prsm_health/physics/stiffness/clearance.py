"""Axial gaps of the rollers from radial clearance and screw–nut eccentricity.

A roller with axial gap g takes load only once the common axial approach Δ of nut and screw
exceeds g (:func:`~.axial.axial_stiffness`). A change Δr of the radial room between the
screw and nut pitch cylinders at one roller becomes the axial gap Δr·cos β/(sin β cos λ)
(:func:`radial_to_axial_gap`); a screw–nut eccentricity e gives each roller Δr = e·cos φ_i
(:func:`eccentricity_to_gaps`). A roller displaced radially inside an unchanged room changes
both of its engagements by equal and opposite amounts and, floating axially, takes no gap at
first order.

References
----------
- Paper 05 (docs/references.md) — the contact normal components (cos β radial, sin β cos λ
  axial).
- Paper 04 (docs/references.md) — clearance and eccentricity reduce the stiffness.
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require

from ._thread_inputs import _as_array


def radial_to_axial_gap(design: PRSMDesign, radial_offset):
    """Axial gap [m] of a roller whose radial room grows by ``radial_offset`` [m].

    Parameters
    ----------
    design : PRSMDesign
    radial_offset : float or array_like [m]
        Change of the radial distance between the screw and nut pitch surfaces available to
        the roller, minus the change of the roller's pitch diameter (positive = looser:
        screw–nut eccentricity away from the roller, an undersized roller, wear).

    Returns
    -------
    ndarray [m]
        Axial gap (negative = pre-approach) of the roller's load path.

    Notes
    -----
    Derivation: at a flank whose unit normal has radial component cos β and axial component
    sin β·cos λ, moving the surfaces apart radially by Δr opens the normal gap by Δr·cos β;
    closing it axially takes Δr·cos β/(sin β cos λ). The roller floats axially between its
    two engagements, so only the *sum* of the screw-side and nut-side radial changes counts,
    however the roller sits radially: a roller offset radially inside an unchanged room
    (its own eccentricity or runout) opens one side by as much as it closes the other and
    takes no gap at first order. λ is the mean of the screw and nut lead angles (they differ
    by O(λ²) in the result).

    References
    ----------
    Paper 05, the contact normal components (cos β radial, sin β cos λ axial); paper 04
    (clearance and eccentricity reduce the stiffness).
    """
    dr = _as_array("radial_offset", radial_offset, nonnegative=False)
    beta = design.contact_angle
    inv_cos = 0.5 * (
        1.0 / math.cos(design.screw_lead_angle) + 1.0 / math.cos(design.nut_lead_angle)
    )
    return dr * inv_cos / math.tan(beta)


def eccentricity_to_gaps(design: PRSMDesign, eccentricity: float, phase: float = 0.0) -> np.ndarray:
    """Axial gaps [m] of the n_R rollers for a screw–nut radial eccentricity.

    Parameters
    ----------
    design : PRSMDesign
    eccentricity : float [m]
        Radial offset e of the screw axis from the nut axis over the engagement (or runout
        of a pitch circle), ≥ 0.
    phase : float [rad]
        Direction of the offset; roller i sits at φ_i = 2π·i/n_R.

    Returns
    -------
    ndarray (n_R,) [m]
        Gaps measured from the first roller to touch (the smallest is 0).

    Notes
    -----
    The screw moves toward roller i by e·cos(φ_i − phase), reducing its radial room by that
    much: gap_i = −:func:`radial_to_axial_gap` (e·cos(φ_i − phase)), shifted so min = 0.
    """
    require(
        isinstance(eccentricity, (int, float))
        and math.isfinite(eccentricity)
        and eccentricity >= 0,
        "eccentricity",
        eccentricity,
        "must be a finite number ≥ 0 [m]",
    )
    phi = 2.0 * math.pi * np.arange(design.n_rollers) / design.n_rollers
    gaps = radial_to_axial_gap(design, -eccentricity * np.cos(phi - phase))
    return gaps - gaps.min()
