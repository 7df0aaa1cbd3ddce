"""Stiffness models: gear mesh (:mod:`.gear_mesh`, tooth damage :mod:`.tooth_damage` and the
damaged mesh :mod:`.damaged_mesh`), Hertz contact (:mod:`.hertz`), the electric cylinder
(:mod:`.cylinder`), and the thread contacts — load distribution over the engaged threads and
the PRSM's axial stiffness, below. Import each name from the module that defines it.


Load path of an axial load F (nut loaded, screw held by its axial bearing)::

    nut ─┬─ roller 1: nut-side threads ── roller body ── screw-side threads ─┬─ screw shaft ─ bearing
         ├─ roller 2: …                                                     │  K = E·A/L_free
         └─ roller n_R                                                      ┘

Rollers share the load in parallel; within one roller the nut-side engagement and the
screw-side engagement are in series; within one engagement the ``engaged_threads`` thread
pairs carry load in parallel, and the compliance of the bodies between adjacent threads makes
the sharing non-uniform (deformation compatibility, paper 04). One thread pair is a Hertz
point contact (δ ∝ Q^(2/3)) in series with the two thread teeth (linear).

Modules (each documents its readings of the papers):

- :mod:`.thread_geometry` — flank curvatures by differential geometry, the Hertz contact of
  one thread pair, axial ↔ normal load.
- :mod:`.thread_compliance` — thread teeth (Yamamoto's formulas, the one implementation),
  bodies between threads, screw shaft.
- :mod:`.thread_load` — load distribution over the engaged threads of one roller
  (``combination``), the roller side laws the simulator uses.
- :mod:`.clearance` — roller axial gaps from radial clearance and eccentricity.
- :mod:`.axial` — the mechanism's axial stiffness versus load, with gaps and the shaft.

References
----------
- Paper 04 (docs/references.md) — fundamental forms, curvature, δ_H, thread compatibility,
  body stiffnesses, K_shaft, clearance and eccentricity.
- Paper 01 (docs/references.md) §2.2 — K_pair and K_sca = (Σ 1/K_pair)^(-1)·n_r.
- Paper 05 (docs/references.md) — principal curvatures, Q = F/(i sin β cos λ), Yamamoto
  terms γ1…γ5.
- A. Yamamoto, *The Theory and Computation of Threads Connection*, Yokendo, Tokyo, 1980.
"""
