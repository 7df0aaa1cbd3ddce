"""Basic dynamic and static axial load ratings C_a and C_0a of a PRSM, from its design.

No catalogue factor: both ratings are computed from the thread contacts the rest of the
package models — the Hertz contact of one thread pair (:mod:`.stiffness.thread_geometry`,
:mod:`.stiffness.hertz`), the share of the engaged threads (:mod:`.stiffness.thread_load`) and
the rolling-contact fatigue law of :mod:`.wear` — in the way ISO 76, ISO 281 and ISO 3408-5
rate rolling bearings and ball screws.

**Static rating C_0a** (ISO 76:2006 §6, ISO 3408-5:2006 §5.1). The axial load at which the most
loaded thread contact reaches the Hertz pressure p_lim = 4.2 GPa (ISO 76's limit for point
contact of balls; about 10⁻⁴ of the rolling element's diameter of permanent deformation). The
load F is shared evenly by the n_R rollers (W = F/n_R, ideal carrier); within one roller the
``engaged_threads`` thread pairs share W as the compatibility model of
:func:`~.stiffness.thread_load.thread_load_distribution` says (the loaded-end thread carries the
most); the axial thread load becomes the normal load Q = F_j/(sin β cos λ) (paper 05) and the
pressure p₀(Q) of the exact Hertz solution. C_0a is the smaller of the screw-side and nut-side
solutions of p₀,max(F) = p_lim (brentq). The uniform sharing of ISO 76/3408-5 (every contact
loaded alike) is reported alongside (``static_uniform``).

**Dynamic rating C_a** (Lundberg & Palmgren 1947; ISO 281:2007 §6; ISO 3408-5:2006 §5.2). The
axial load, constant in size and direction, under which 90 % of a group of PRSMs complete 10⁶
revolutions of the screw (the nut held, one point of the screw under the nut at all times).
The life of one contact track is the law of :func:`~.wear.l10_cycles` — the Lundberg–Palmgren
point-contact life L = N_ref·(p_ref/p₀)⁹ stress cycles (L ∝ Q⁻³), the same law the life
simulation ages a unit with — so a unit loaded at C_a reaches its L10 at 10⁶ screw revolutions
in the life model too. The rating follows as in ISO 281 for a thrust bearing with i rows of Z
rolling elements, with the PRSM's rollers as the rolling elements (Z = n_R) and its engaged
thread turns as the rows (i = ``engaged_threads``); the screw and the nut are the raceways:

* stress cycles per screw revolution at a point of a raceway: u_screw = Z·|1 − r| and
  u_nut = Z·r, r the carrier/screw speed ratio (:func:`~.wear.stress_cycle_rates`, stroke 0);
* one track at Q lives 10⁶ revolutions when Q = Q_1 = (N_ref/(u·10⁶))^⅓·(p_ref/p₀(1 N))³,
  p₀(Q) = p₀(1 N)·Q^⅓ (Hertz);
* i equally loaded rows fail as one (Weibull slope e = 10/9 of ISO 281: L_i = L_1·i^(−1/e)),
  so each contact may carry Q_c = Q_1·i^(−0.3);
* the raceway's rating is C = Z·i·sin β·cos λ·Q_c = Z^⅔·i^0.7·sin β·cos λ·(...), the
  Z^(2/3) and i^0.7 of ISO 281 eq. (9) and its multi-row rule, here from the cycle count;
* the two raceways combine as ISO 281 and ISO 3408-5 (the bracket of its f_c) combine inner
  and outer ring, screw and nut: C_a = (C_screw^(−10/3) + C_nut^(−10/3))^(−0.3). This is a little
  below the weaker side alone (by 2^(−0.3) = 0.81 for equal sides); both sides are reported.

Assumptions (each stated in :attr:`LoadRatings.method`): even load sharing between rollers and
between threads for C_a (ISO's convention for an axial load; the uneven thread share is in
C_0a); reliability 90 %; 10⁶ revolutions of the screw; the roller flanks, like the balls of
ISO 281, are not a separate failure risk (their fatigue is inside the raceway calibration);
surfaces hardened bearing steel (≥ 58 HRC, ISO 3408-5's precondition: no hardness factor).
The reference pressure and cycles (p_ref = 4.2 GPa, N_ref = 4·10⁶) are the wear module's
defaults (:class:`~.wear.WearParameters`), an order-of-magnitude calibration; Lundberg–Palmgren's
stressed-volume term (which turns C ∝ size² into ISO's D_w^1.8) is not in that law, so
geometrically similar designs scale as size² here. Cross-check against catalogues:
docs/load-ratings.md (no commercial standard-PRSM table could be read; the one catalogue figure
available, a Rollvis value quoted by paper 03 §4.3, is met by paper03's C_0a within 12 %; at fixed
geometry C_a ∝ N_ref^⅓·p_ref³, so a catalogue C_a recalibrates the fatigue law, not a factor).

References
----------
- ISO 76:2006, Rolling bearings — Static load ratings (4200 MPa for point contact of balls).
- ISO 281:2007, Rolling bearings — Dynamic load ratings and rating life (eq. (9) C_a of thrust
  ball bearings ∝ Z^(2/3); multi-row rule C = (Σ C_k^(−10/3))^(−0.3); Weibull slope 10/9).
- ISO 3408-5:2006, Ball screws — Part 5: Static and dynamic axial load ratings and operational
  life (§5.1 C_0a at the ISO 76 pressure, §5.2 C_a with screw and nut combined in f_c; rating
  life 10⁶ revolutions, 90 % reliability).
- G. Lundberg, A. Palmgren, "Dynamic capacity of rolling bearings", Acta Polytechnica,
  Mech. Eng. Series 1(3), 1947.
- T.A. Harris, M.N. Kotzalas, *Rolling Bearing Analysis*, 5th ed., CRC (2007).
- Paper 05 (docs/references.md): Q = F/(i sin β cos λ); paper 04: thread load compatibility.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.design_files import design_fingerprint
from prsm_health.core.errors import ParameterError, require

from .stiffness.thread_geometry import normal_load, thread_contacts
from .stiffness.thread_load import thread_load_distribution
from .wear import WEIBULL_SLOPE, PartGeometry, WearParameters, contact_states, stress_cycle_rates

#: ISO 76:2006 limit of the Hertz pressure at the most loaded point contact (balls) [Pa].
#: The wear module's fatigue reference pressure has the same default (4.2 GPa) and is reused.
STATIC_CONTACT_PRESSURE: float = WearParameters().fatigue_pressure
#: Revolutions of the screw of the basic rating life (ISO 281, ISO 3408-5) [-].
RATING_REVOLUTIONS = 1e6
#: Exponent of the ISO 281 combination of raceways and rows: 3·e = 10/3 for point contact.
_COMBINE = 3.0 * WEIBULL_SLOPE
SIDES = ("screw", "nut")


@dataclass(frozen=True)
class SideRating:
    """Ratings of one engagement (the screw or the nut as raceway), SI.

    Attributes
    ----------
    dynamic : float [N]
        C of this raceway alone (10⁶ screw revolutions, 90 % reliability).
    static : float [N]
        Axial load at which its most loaded contact reaches the static pressure (thread
        load distribution of :mod:`.stiffness.thread_load`).
    static_uniform : float [N]
        The same with every thread loaded alike (ISO 76/3408-5 convention).
    cycles_per_revolution : float [-]
        Stress cycles per screw revolution at a point of the raceway (u).
    contact_capacity : float [N]
        Q_c, normal load per contact at C (rows combined).
    pressure_at_dynamic : float [Pa]
        Hertz pressure of a contact at the dynamic rating (even sharing).
    peak_share : float [-]
        Most loaded thread's share of the roller load at the static rating (1/n if uniform).
    """

    dynamic: float
    static: float
    static_uniform: float
    cycles_per_revolution: float
    contact_capacity: float
    pressure_at_dynamic: float
    peak_share: float

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True)
class LoadRatings:
    """Basic axial load ratings of a PRSM (module docstring for the method).

    Attributes
    ----------
    dynamic : float [N]
        C_a, screw and nut raceways combined (ISO 281 rule).
    static : float [N]
        C_0a, the smaller of the two sides.
    per_side : dict[str, SideRating]
        ``"screw"`` and ``"nut"``.
    method : str
        The method and its assumptions, one paragraph.
    """

    dynamic: float
    static: float
    per_side: dict
    method: str

    def as_dict(self) -> dict:
        """JSON-ready form, SI (N, Pa)."""
        return {
            "dynamic": self.dynamic,
            "static": self.static,
            "per_side": {k: v.as_dict() for k, v in self.per_side.items()},
            "method": self.method,
        }


METHOD = (
    "C_a: Lundberg-Palmgren point-contact fatigue (the wear module's L = N_ref (p_ref/p0)^9, "
    "p_ref = {p_ref:.3g} Pa, N_ref = {n_ref:.3g} cycles) counted as ISO 281/ISO 3408-5 do: "
    "rollers = rolling elements (Z = {z}), engaged threads = rows (i = {i}, i^0.7 rule), screw "
    "and nut = raceways combined as (sum C^-10/3)^-0.3; 90 % reliability, 1e6 screw "
    "revolutions, even load sharing over rollers and threads. C_0a: axial load at which the "
    "most loaded thread contact reaches {p_static:.3g} Pa (ISO 76 point contact), rollers "
    "sharing evenly, threads sharing by the thread-load compatibility model."
)


def _check_design(design) -> None:
    if not isinstance(design, PRSMDesign):
        raise ParameterError("design", design, "must be a PRSMDesign (a preset or design file)")


def _static_side(design: PRSMDesign, side: str, q_limit: float) -> tuple[float, float]:
    """(F, peak share) with the side's most loaded normal thread load equal to ``q_limit``."""
    n_r, n_t = design.n_rollers, design.engaged_threads
    axial_limit = float(q_limit / normal_load(design, 1.0, side))  # axial load of that contact

    def peak(w: float) -> float:
        dist = thread_load_distribution(design, w)
        return float(np.max(getattr(dist, side)))

    if n_t == 1:
        return n_r * axial_limit, 1.0
    # The peak thread load lies between W/n (uniform) and W: the root lies in
    # [axial_limit, n·axial_limit]. Solve on log W (loads span decades between designs).
    lo, hi = math.log(axial_limit), math.log(n_t * axial_limit)
    f = lambda x: math.log(peak(math.exp(x)) / axial_limit)  # noqa: E731
    f_lo, f_hi = f(lo), f(hi)
    if f_lo >= 0.0:  # pragma: no cover - one thread carries all: cannot happen with n ≥ 2
        x = lo
    elif f_hi <= 0.0:  # uniform within rounding (rigid bodies)
        x = hi
    else:
        x = brentq(f, lo, hi, xtol=1e-13, rtol=1e-13)
    w = math.exp(x)
    return n_r * w, peak(w) / w


def load_ratings(
    design: PRSMDesign,
    *,
    static_pressure: float = STATIC_CONTACT_PRESSURE,
    fatigue: WearParameters | None = None,
) -> LoadRatings:
    """Basic dynamic and static axial load ratings C_a and C_0a of a PRSM design.

    Parameters
    ----------
    design : PRSMDesign
        Any valid design, standard or recirculating.
    static_pressure : float [Pa]
        Hertz pressure limit of the static rating; ISO 76's 4.2 GPa for point contact.
    fatigue : WearParameters or None
        Source of the contact fatigue law (p_ref, N_ref); ``None``: the defaults.

    Returns
    -------
    LoadRatings
        ``dynamic`` C_a [N], ``static`` C_0a [N], per-side details, the method.

    Raises
    ------
    ParameterError
        ``design`` is not a PRSMDesign, or ``static_pressure`` is outside 1…10 GPa, or the
        thread contacts do not close (Hertz geometry).

    Notes
    -----
    C_0a with the thread-load distribution is below the ISO-convention value with uniform
    sharing (``per_side[...].static_uniform``) by the peak share of the loaded-end thread.

    References
    ----------
    ISO 76:2006 §6; ISO 281:2007 eq. (9) and the multi-row rule; ISO 3408-5:2006 §5;
    Lundberg & Palmgren (1947); paper 05 (Q = F/(i sin β cos λ)); paper 04 (thread loads).
    """
    _check_design(design)
    require(
        isinstance(static_pressure, (int, float)) and 1e9 <= static_pressure <= 1e10,
        "static_pressure",
        static_pressure,
        "must lie in [1e9, 1e10] Pa",
    )
    params = WearParameters() if fatigue is None else fatigue
    require(isinstance(params, WearParameters), "fatigue", params, "must be WearParameters")
    try:
        key = (hash(design), static_pressure, params)
    except TypeError:  # a design holding an unhashable value: its fingerprint instead
        key = (design_fingerprint(design), static_pressure, params)
    found = _RATINGS.get(key)
    if found is None or found[0] != design:
        found = (design, _ratings(design, static_pressure, params))
        _RATINGS[key] = found
    return found[1]


#: The ratings of the designs met in this process, by design (a frozen, hashable dataclass) and
#: method parameters: one thread-load solution (≈ 20–60 ms) per design, shared by every caller —
#: a check reading's no-load threshold, the contact mode's duty band, a scenario's labels, the
#: life model. Callers share the result: read it, never modify its ``per_side``.
_RATINGS: dict = {}


def _ratings(design: PRSMDesign, static_pressure: float, params: WearParameters) -> LoadRatings:
    z, i = design.n_rollers, design.engaged_threads

    geometry = PartGeometry.of(design)
    # One screw revolution per second, stroke 0: cycles per second = cycles per revolution.
    states = contact_states(design, geometry, 1.0, 2.0 * math.pi)
    cycles = stress_cycle_rates(geometry, states, stroke=0.0)
    hertz = dict(zip(SIDES, thread_contacts(design)))

    per_side = {}
    for side in SIDES:
        contact = hertz[side]
        p_unit = float(contact.max_pressure(1.0))  # p0 at Q = 1 N; p0 ∝ Q^(1/3)
        u = float(cycles[side])
        require(
            u > 0.0,
            "design",
            design.name,
            f"the {side} raceway is not rolled over (carrier ratio makes u = 0)",
        )
        one_track = (params.fatigue_cycles / (u * RATING_REVOLUTIONS)) ** (1.0 / 3.0) * (
            params.fatigue_pressure / p_unit
        ) ** 3
        q_c = one_track * i ** (-1.0 / _COMBINE)
        axial_per_contact = float(1.0 / normal_load(design, 1.0, side))  # sin β cos λ
        dynamic = z * i * axial_per_contact * q_c
        q_static = (static_pressure / p_unit) ** 3
        static, share = _static_side(design, side, q_static)
        per_side[side] = SideRating(
            dynamic=dynamic,
            static=static,
            static_uniform=z * i * axial_per_contact * q_static,
            cycles_per_revolution=u,
            contact_capacity=q_c,
            pressure_at_dynamic=p_unit * q_c ** (1.0 / 3.0),
            peak_share=share,
        )
    dynamic = sum(s.dynamic ** (-_COMBINE) for s in per_side.values()) ** (-1.0 / _COMBINE)
    static = min(s.static for s in per_side.values())
    method = METHOD.format(
        p_ref=params.fatigue_pressure,
        n_ref=params.fatigue_cycles,
        z=z,
        i=i,
        p_static=static_pressure,
    )
    return LoadRatings(dynamic=dynamic, static=static, per_side=per_side, method=method)
