"""Wear and rolling-contact fatigue of the thread contacts: how a PRSM ages.

Quasi-static rates at one operating point (axial load, screw speed, lubricant state), for the
life simulation of :mod:`prsm_health.physics.life` — no dynamics, the contact loads of the thread model.

**Archard wear in mixed lubrication.** A surface point under a sliding contact loses depth at
ḣ = k·p·v_s (Archard 1953, local form), k [m²/N] the dimensional wear coefficient, p the
contact pressure, v_s the sliding speed. In a lubricated contact only the asperities touch: the
load they carry is the share f_c(Λ) of :func:`prsm_health.physics.lubrication.asperity_share` (Johnson,
Greenwood & Poon 1972), so ḣ = k·f_c·p·v_s (the EHL load-sharing wear model of Akbarzadeh &
Khonsari 2010). A point on the centre line of a wear track, crossed by a Hertz contact
(semi-axes a across and b along rolling, p₀ = 3Q/(2πab); :mod:`prsm_health.physics.stiffness.hertz`)
at rolling speed u, loses k·f_c·(v_s/u)·∫p dx = k·f_c·(v_s/u)·(π/2)·p₀·b = ¾·k·f_c·v_s·Q/(a·u)
per pass; it is passed n_c·u/L times a second (n_c contacts on a track of length L), so the
track deepens at ḣ = ¾·k·f_c·v_s·Q·n_c/(a·L) — the centre line, where the flanks meet, is
what sets the play.

Sliding speeds:

* screw–roller: paper 02's sliding velocity v_sr0 at steady rolling is axial, v = p_s·|ω_s|
  (p_s = lead/2π; :mod:`prsm_health.physics.friction`, paper 02 v_sr0), plus spin;
* roller–nut: rolling synchronised by the ring gear, no gross sliding (paper 02 has none
  there): spin only;
* spin of a contact whose normal is inclined by the flank angle β to the rolling axis: angular
  velocity ω_sp = (u_e/r_r)·sin β about the normal (Johnson 1985, §8.4); a point of the track's
  centre line crossing the contact at x slides at |x|·ω_sp, which over the Hertz pressure along
  it, ∫p|x|dx/∫p dx, is 4b/(3π)·ω_sp (b the semi-axis along rolling).

Tracks: a roller thread turn carries one contact per flank on a track of length 2πr_r; the
nut's flank track (2πr_n) is passed by n_R rollers; the screw's by n_R rollers per turn of the
screw relative to the carrier, but a point of the screw is under the nut only the share
L_nut/(L_nut + stroke) of the time of a reciprocating stroke. Each flank's normal wear depth h
opens the axial play by h/sin β (Q = F_a/(sin β cos λ), paper 05); the model's half-clearance b
grows by half of it (play 2b).

**Additive depletion.** Anti-wear additives lower the wear coefficient by an order of magnitude
and more until they are used up: k = k_0·(k_dry/k_0)^d with d the lubricant degradation of
:class:`~prsm_health.actuator.states.HealthState` (0 new … 1 depleted), a log-linear interpolation
between the protected and the depleted coefficient (engineering choice; the span, 10×, is the
order reported for ZDDP-protected against base-oil-only steel contacts).

**Rolling-contact fatigue.** Lundberg–Palmgren / ISO 281:2007 for point contacts: the basic
rating life falls with the cube of the load, L10 = (C/P)³, i.e. with the ninth power of the
Hertz pressure (p₀ ∝ P^⅓); referred here to a contact pressure, L10 = N_ref·(p_ref/p₀)⁹ stress
cycles, with p_ref ≈ the pressure of a point contact at its basic dynamic load rating
(≈ 4.2 GPa, Harris & Kotzalas 2007, order of magnitude) and N_ref = 4·10⁶ cycles (10⁶
revolutions of a raceway passed by ≈ 4 rolling elements per revolution). Scatter: the
two-parameter Weibull distribution of ISO 281 with slope e = 10/9, surfaces combined as
S = Π S_i. A spall then grows in length exponentially with stress cycles (engineering law;
spall propagation after Kotzalas & Harris 2001 takes a fraction of the initiation life).

References
----------
- J.F. Archard, "Contact and rubbing of flat surfaces", J. Appl. Phys. 24 (1953) 981–988.
- S. Akbarzadeh, M.M. Khonsari, "On the prediction of running-in behavior in mixed-lubrication
  line contact", J. Tribol. 132 (2010) 032102 (Archard wear of the asperity-borne load).
- K.L. Johnson, J.A. Greenwood, S.Y. Poon, Wear 19 (1972) 91–108 (load sharing).
- K.L. Johnson, *Contact Mechanics*, Cambridge University Press (1985), §8.4 (spin).
- ISO 281:2007, Rolling bearings — Dynamic load ratings and rating life (Weibull slope 10/9,
  life exponent 3 for point contact).
- T.A. Harris, M.N. Kotzalas, *Rolling Bearing Analysis*, 5th ed., CRC (2007).
- M.N. Kotzalas, T.A. Harris, "Fatigue failure progression in ball bearings", J. Tribol. 123
  (2001) 238–242.
- Paper 02 (friction torque, sliding velocity v_sr0); paper 05 (normal load of a thread pair).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require_known_keys, require_positive, require_range

#: Weibull slope of rolling-contact fatigue lives, point contact (ISO 281:2007).
WEIBULL_SLOPE = 10.0 / 9.0
#: Exponent of fatigue life on Hertz pressure for point contacts: L ∝ P⁻³ and p₀ ∝ P^⅓.
PRESSURE_LIFE_EXPONENT = 9.0
#: Fatigue surfaces of the life model.
SURFACES = ("screw", "roller", "nut")


@dataclass(frozen=True)
class WearParameters:
    """Coefficients of wear and fatigue (SI); module docstring for the laws.

    Parameters
    ----------
    wear_coefficient : float [m²/N]
        k_0, Archard's dimensional coefficient of the additive-protected, asperity-borne
        contact (hardened bearing steel in mixed lubrication, mild wear: 1e-18 … 1e-16).
    depleted_wear_ratio : float [-]
        k_dry/k_0: how much faster the contact wears once the additives are used up.
    fatigue_pressure : float [Pa]
        p_ref, the Hertz pressure with a basic rating life of ``fatigue_cycles``.
    fatigue_cycles : float [-]
        N_ref, stress cycles of the L10 life at ``fatigue_pressure``.
    spall_initial_length : float [m]
        Length of a spall when it appears (≈ the contact ellipse's width).
    spall_depth : float [m]
        Depth of the depression the contact follows (:class:`~prsm_health.actuator.faults.Spall`).
    spall_doubling : float [-]
        Stress cycles for a spall to double in length, as a share of its surface's L10 life.
    """

    wear_coefficient: float = 1e-17
    depleted_wear_ratio: float = 10.0
    fatigue_pressure: float = 4.2e9
    fatigue_cycles: float = 4e6
    spall_initial_length: float = 0.3e-3
    spall_depth: float = 20e-6
    spall_doubling: float = 0.05

    def __post_init__(self):
        require_range("wear.wear_coefficient", self.wear_coefficient, 1e-20, 1e-13, unit="m²/N")
        require_range("wear.depleted_wear_ratio", self.depleted_wear_ratio, 1.0, 1e3)
        require_range("wear.fatigue_pressure", self.fatigue_pressure, 1e9, 1e10, unit="Pa")
        require_positive("wear.fatigue_cycles", self.fatigue_cycles)
        require_range("wear.spall_initial_length", self.spall_initial_length, 1e-5, 5e-3, unit="m")
        require_range("wear.spall_depth", self.spall_depth, 1e-6, 200e-6, unit="m")
        require_range("wear.spall_doubling", self.spall_doubling, 1e-4, 10.0)

    @classmethod
    def from_dict(cls, values: dict, table: str = "life.wear") -> WearParameters:
        require_known_keys(table, values, [f.name for f in fields(cls)])
        return cls(**values)

    def as_dict(self) -> dict:
        return asdict(self)

    def coefficient(self, degradation: float) -> float:
        """k at lubricant degradation d: k_0·(k_dry/k_0)^d [m²/N]."""
        return self.wear_coefficient * self.depleted_wear_ratio**degradation


@dataclass(frozen=True)
class ContactState:
    """One thread engagement (screw or nut side) at an operating point: what wear and fatigue
    read. Per contact (one roller thread turn), SI."""

    normal_load: float  # Q [N]
    semi_major: float  # a [m], across rolling
    semi_minor: float  # b [m], along rolling
    max_pressure: float  # p₀ [Pa]
    sliding_speed: float  # v_s [m/s], gross + spin
    entrainment_speed: float  # u_e [m/s]


@dataclass(frozen=True)
class PartGeometry:
    """The design's quantities the rates need (computed once per design)."""

    screw_radius: float
    roller_radius: float
    nut_radius: float
    lead_per_radian: float
    rolling_ratio: float  # carrier speed / screw speed
    sin_beta: float
    contacts: int  # n_R·n_t
    n_rollers: int
    nut_length: float
    contacts_per_side: tuple  # (screw HertzContact, nut HertzContact)

    @classmethod
    def of(cls, design: PRSMDesign) -> PartGeometry:
        from .friction import FrictionParameters
        from .stiffness.thread_geometry import thread_contacts

        friction = FrictionParameters.from_design(design)
        return cls(
            screw_radius=design.screw_diameter / 2,
            roller_radius=design.roller_diameter / 2,
            nut_radius=design.nut_diameter / 2,
            lead_per_radian=friction.lead_per_radian,
            rolling_ratio=friction.rolling_ratio,
            sin_beta=math.sin(design.contact_angle),
            contacts=design.n_rollers * design.engaged_threads,
            n_rollers=design.n_rollers,
            nut_length=design.engaged_threads * design.pitch,
            contacts_per_side=thread_contacts(design),
        )


def contact_states(
    design: PRSMDesign, geometry: PartGeometry, axial_load: float, screw_speed: float
) -> dict[str, ContactState]:
    """Screw-side and nut-side contact of one roller thread turn at a steady operating point.

    The axial load is shared evenly by the n_R·n_t thread turns (the uneven share between
    rollers is the life model's wear spread).
    """
    from .stiffness.thread_geometry import normal_load

    per_turn = abs(axial_load) / geometry.contacts
    w_s = abs(screw_speed)
    w_carrier = geometry.rolling_ratio * w_s
    entrainment = {
        "screw": geometry.screw_radius * abs(w_s - w_carrier),  # as friction._sliding
        "nut": geometry.nut_radius * w_carrier,
    }
    gross = {"screw": geometry.lead_per_radian * w_s, "nut": 0.0}  # paper 02 v_sr0; nut: none
    out = {}
    for side, hertz in zip(("screw", "nut"), geometry.contacts_per_side):
        q = float(normal_load(design, per_turn, side))
        a, b = (float(v) for v in hertz.semi_axes(q))
        spin = entrainment[side] / geometry.roller_radius * geometry.sin_beta
        spin_sliding = 4.0 * b / (3.0 * math.pi) * spin  # pressure-weighted, centre line
        out[side] = ContactState(
            normal_load=q,
            semi_major=a,
            semi_minor=b,
            max_pressure=float(hertz.max_pressure(q)),
            sliding_speed=gross[side] + spin_sliding,
            entrainment_speed=entrainment[side],
        )
    return out


def track_passes(geometry: PartGeometry, side: str, stroke: float) -> dict:
    """Contact passes per metre rolled, n_c/L [1/m], over a point of each part's wear track,
    for the engagement ``side`` ("screw": the screw and the roller's screw-facing flank;
    "nut": the nut and the roller's nut-facing flank)."""
    roller = 1.0 / (2.0 * math.pi * geometry.roller_radius)
    if side == "screw":
        covered = geometry.nut_length / (geometry.nut_length + stroke)
        part = geometry.n_rollers / (2.0 * math.pi * geometry.screw_radius) * covered
    else:
        part = geometry.n_rollers / (2.0 * math.pi * geometry.nut_radius)
    return {"part": part, "roller": roller}


def clearance_growth_rate(
    geometry: PartGeometry,
    contact: ContactState,
    side: str,
    *,
    stroke: float,
    asperity_share: float,
    coefficient: float,
) -> float:
    """Growth rate of the half-clearance b of one engagement while it carries the load on one
    flank [m/s]: both parts' track centre lines deepening at ¾·k·f_c·v_s·Q·n_c/(a·L), as axial
    play h/sin β, halved (play = 2b)."""
    passes = track_passes(geometry, side, stroke)
    per_metre = (
        0.75 * coefficient * asperity_share * contact.sliding_speed * contact.normal_load
    ) / contact.semi_major
    depth_rate = per_metre * (passes["part"] + passes["roller"])
    return 0.5 * depth_rate / geometry.sin_beta


def stress_cycle_rates(geometry: PartGeometry, contacts: dict, stroke: float) -> dict[str, float]:
    """Stress cycles per second at the most-cycled point of each surface [1/s].

    Roller: its screw-facing track is passed once per spin of the roller relative to the
    screw contact; nut: n_R rollers per carrier turn; screw: n_R rollers per turn of the screw
    relative to the carrier, for the share of time the point is under the nut.
    """
    screw, nut = contacts["screw"], contacts["nut"]
    covered = geometry.nut_length / (geometry.nut_length + stroke)
    return {
        "screw": geometry.n_rollers
        * screw.entrainment_speed
        / (2 * math.pi * geometry.screw_radius)
        * covered,
        "roller": screw.entrainment_speed / (2 * math.pi * geometry.roller_radius),
        "nut": geometry.n_rollers * nut.entrainment_speed / (2 * math.pi * geometry.nut_radius),
    }


def l10_cycles(params: WearParameters, max_pressure) -> np.ndarray:
    """Basic rating life in stress cycles at Hertz pressure p₀: N_ref·(p_ref/p₀)⁹."""
    p = np.maximum(np.asarray(max_pressure, dtype=float), 1.0)
    return params.fatigue_cycles * (params.fatigue_pressure / p) ** PRESSURE_LIFE_EXPONENT
