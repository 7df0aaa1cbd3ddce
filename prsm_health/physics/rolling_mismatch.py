"""Pitch mismatch between a PRSM roller's gear and its thread rolling on the nut.

A standard PRSM roller rolls on the screw and on the nut threads and meshes with the ring gear:
it is over-constrained. Any mismatch ε between the gear ratio z_ring/z_roller and the
nut–roller rolling ratio r_nut/r_roller (the "effective nut–roller helical gear pair") must be
taken by the gear or by slip at the nut: Jones & Velinsky, "Kinematics of roller migration in
the planetary roller screw mechanism", J. Mech. Des. 134(6) 061006, 2012 (manufacturing errors,
deformation under load, uncertain radii of contact); paper 03 §1 cites it for roller migration.
The dynamic model (:mod:`prsm_health.simulation.dynamics`) resolves the sharing with a creeping
traction on both threads; this module gives its inputs.

Terms of ε (relative excess of the nut-thread rolling ratio over the gear ratio):

* **Nominal**: (d_n/d_r)/(z_ring/z_roller) − 1 from the design — 0 when the tooth counts follow
  the thread diameters, as in every preset (the model's threads touch at their pitch radii).
* **Tolerance**: Δr_nut/r_nut − Δr_roller/r_roller from the rolling-radius errors of the nut and
  of each roller (``ManufacturingVariation.rolling_radius_error``).
* **Elastic**: each steel surface takes half the Hertz approach δ of a thread contact (equal
  elastic constants, Johnson, *Contact Mechanics*, 1985, §4.2), whose radial part is δ/2·cos β:
  the roller's rolling radius on the nut shrinks and the nut's grows,
  ε_el = δ/2·cos β·(1/r_r + 1/r_n), δ at the operating load per roller shared evenly over the
  engaged turns. Engineering estimate: the rolling point of a conformal contact is not exactly
  the deformed surface point, but its order (10⁻⁴ at 5–40 % of C_a) is what matters against
  the creep a traction needs.

Relaxation length of a thread traction: the Mindlin stiffness of a circular contact 8G*a
(G* = G/(2(2 − ν)) for two steels) and Kalker's linear creep force G·c²·C11·ξ agree when the
tangential displacement relaxes over L = C11·(2 − ν)·c/4 ≈ 1.8·c of rolling, c = √(ab) the
contact's mean semi-axis (Johnson 1985 §7.2 and §8.2; an engineering reading of the linear
theory as a transient creep state, as relaxation lengths are used in wheel–rail dynamics).
"""

from __future__ import annotations

import math

from prsm_health.actuator.design import PRSMDesign

#: Kalker's linear creep coefficient C11 of a circular contact for ν = 0.3 (Kalker 1967,
#: tabulated in Johnson, Contact Mechanics, 1985, Table 8.1: 3.40 at ν = 0, 4.12 at 0.25).
KALKER_C11 = 4.3


def rolling_mismatch_terms(
    design: PRSMDesign, roller_load: float
) -> tuple[float, float, tuple[float, float]]:
    """Nominal and elastic pitch mismatch ε of a design at one per-roller axial load, and the
    relaxation lengths of the screw-side and nut-side thread tractions (module docstring).

    Parameters
    ----------
    design : PRSMDesign
        A standard PRSM (with gears).
    roller_load : float [N]
        Axial load of one roller side.

    Returns
    -------
    (nominal, elastic, (L_screw, L_nut)) : float [-], float [-], (float, float) [m]
    """
    from prsm_health.physics.stiffness.thread_geometry import normal_load, thread_contacts

    gear = design.gear
    r_r, r_n = design.roller_diameter / 2, design.nut_diameter / 2
    nominal = (r_n / r_r) / (gear.ring_teeth / gear.roller_teeth) - 1.0
    per_turn = max(roller_load, 1e-3) / design.engaged_threads
    nu = design.roller_material.poisson_ratio
    lengths, approach = [], 0.0
    for side, contact in zip(("screw", "nut"), thread_contacts(design)):
        q = float(normal_load(design, per_turn, side))
        a, b = contact.semi_axes(q)
        lengths.append(KALKER_C11 * (2.0 - nu) * math.sqrt(float(a) * float(b)) / 4.0)
        if side == "nut":
            approach = float(contact.deflection(q))
    elastic = 0.5 * approach * math.cos(design.contact_angle) * (1.0 / r_r + 1.0 / r_n)
    return nominal, elastic, (lengths[0], lengths[1])
