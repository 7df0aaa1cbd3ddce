"""Rigid-body kinematics and characteristic frequencies of standard and recirculating PRSMs.

Model: the screw turns at ω_s and is axially fixed; the nut does not turn; rollers roll without
slip on the screw and on the nut at their pitch diameters (the ring gear enforces this on the
nut side of a standard PRSM) and do not move axially relative to the nut (roller and nut helix
angles match). Angular speeds are signed, in the screw's sense of rotation.

References
----------
- Paper 01 §3.1–3.2: carrier/screw ratio and mesh frequency f_m = z2·f_p.
- Paper 03 eqs. (23)–(33): ω_c = d_s/(2 d_c)·ω_s, ω_r = (d_s/d_r + 1)ω_c − (d_s/d_r)ω_s,
  v_n = n·p·ω_s/2π, roller displacement relative to nut L_r1 = p·φ_c/2π.
- Paper 04 eq. for s(θ_S): nut travel = θ_S (r_R P_S + r_S P_R)/(2π r_R) · (r_S + 2r_R)/(2r_S + 2r_R).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class SpeedRatios:
    """Speeds per unit screw speed (dimensionless ratios; nut: metres per radian).

    Attributes
    ----------
    carrier : float [-]
        ω_c/ω_s, roller revolution (carrier) speed.
    roller_spin : float [-]
        ω_r/ω_s, absolute roller spin about its own axis.
    roller_spin_relative : float [-]
        (ω_r − ω_c)/ω_s, roller spin seen from the carrier (what its gear teeth and threads see).
    nut : float [m/rad]
        v_n/ω_s, nut axial speed per screw angular speed = effective lead / 2π.
    """

    carrier: float
    roller_spin: float
    roller_spin_relative: float
    nut: float

    @property
    def effective_lead(self) -> float:
        """Nut travel per screw revolution [m]."""
        return TWO_PI * self.nut


def speed_ratios(design: PRSMDesign) -> SpeedRatios:
    """Rigid-body speed ratios of a design.

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    SpeedRatios

    References
    ----------
    Carrier: paper 03 eq. (25) (rolling at both pitch circles, nut fixed), equal to paper 01's
    r_s/(2(r_s + r_c)) = 0.375. Roller spin: paper 03 eqs. (26)–(27). Nut: paper 04 kinematic
    relation (standard PRSM), paper 03 eq. (29) (recirculating: one lead per screw turn, the
    rollers being reset by one pitch per carrier revolution in the threadless area).
    """
    r_s = design.screw_diameter / 2
    r_r = design.roller_diameter / 2
    carrier = r_s / (2.0 * (r_s + r_r))
    roller_spin = (r_s / r_r + 1.0) * carrier - r_s / r_r
    if design.variant == "recirculating":
        nut = design.screw_lead / TWO_PI
    else:
        # Roller moves relative to the screw by the screw lead and its own lead (it spins the
        # other way); it is axially locked to the nut. Paper 04's s(θ_S).
        nut = (
            (1.0 - carrier) * (r_r * design.screw_lead + r_s * design.roller_lead) / (TWO_PI * r_r)
        )
    return SpeedRatios(carrier, roller_spin, roller_spin - carrier, nut)


@dataclass(frozen=True)
class CharacteristicFrequencies:
    """Characteristic frequencies [Hz] at one screw speed (all non-negative).

    Attributes
    ----------
    screw : screw rotation f_s
    carrier : roller revolution f_c (one carrier turn)
    roller_spin : roller spin relative to the carrier |ω_r − ω_c|/2π
    gear_mesh : z_ring·f_c (standard PRSM; None for the recirculating variant, which has no gears)
    thread_passing : screw thread starts passing one roller contact, n_s·|f_s − f_c|
    roller_pass_screw : rollers passing a point of the screw thread, n_r·|f_s − f_c|
    roller_pass_nut : rollers passing a point of the nut thread, n_r·f_c
    roller_reset : roller resets in the nut threadless area, n_r·f_c (recirculating only)
    """

    screw: float
    carrier: float
    roller_spin: float
    gear_mesh: float | None
    thread_passing: float
    roller_pass_screw: float
    roller_pass_nut: float
    roller_reset: float | None

    def as_dict(self) -> dict:
        return asdict(self)


def characteristic_frequencies(design: PRSMDesign, screw_speed: float) -> CharacteristicFrequencies:
    """Characteristic frequencies for a design at a screw speed.

    Parameters
    ----------
    design : PRSMDesign
    screw_speed : float [rad/s]
        Signed; frequencies are magnitudes.

    Returns
    -------
    CharacteristicFrequencies [Hz]

    References
    ----------
    Paper 01 §3.2 (f_m = z2·f_p); paper 03 §2.4 (one reset per roller per carrier revolution).
    """
    require(
        isinstance(screw_speed, (int, float)) and math.isfinite(screw_speed),
        "screw_speed",
        screw_speed,
        "must be a finite number [rad/s]",
    )
    ratios = speed_ratios(design)
    f_s = abs(screw_speed) / TWO_PI
    f_c = abs(ratios.carrier) * f_s
    f_rel = abs(1.0 - ratios.carrier) * f_s
    mesh = None if design.gear is None else design.gear.ring_teeth * f_c
    reset = design.n_rollers * f_c if design.variant == "recirculating" else None
    return CharacteristicFrequencies(
        screw=f_s,
        carrier=f_c,
        roller_spin=abs(ratios.roller_spin_relative) * f_s,
        gear_mesh=mesh,
        thread_passing=design.screw_starts * f_rel,
        roller_pass_screw=design.n_rollers * f_rel,
        roller_pass_nut=design.n_rollers * f_c,
        roller_reset=reset,
    )


def defect_frequencies(design: PRSMDesign, screw_speed: float) -> dict[str, float]:
    """Rates [Hz] at which a localised defect at each location meets its mating part, by the
    rolling-bearing reasoning of defect-passing frequencies (a fixed point is passed by every
    rolling element; a point on a rolling element meets both races once per spin).

    * ``screw_flank``: a point on a screw flank is rolled over by each roller, n_r·|f_s − f_c|;
    * ``nut_flank``: a point on a nut flank, n_r·f_c;
    * ``roller_flank``: a point on one roller's thread meets the screw and the nut once each per
      spin relative to the carrier, 2·f_spin (the roller's orbit, f_c, modulates it);
    * ``ring_gear_tooth``: a ring-gear tooth meshes with each roller once per carrier turn,
      n_r·f_c (standard PRSM only);
    * ``roller_gear_tooth``: a tooth of one roller's gear meshes once per spin relative to the
      carrier, f_spin (standard PRSM only);
    * ``carrier``: f_c, the rate at which a roller's load zone turns.

    Parameters
    ----------
    design : PRSMDesign
    screw_speed : float [rad/s]

    References
    ----------
    Randall & Antoni, Rolling element bearing diagnostics — a tutorial, MSSP 25 (2011), §2
    (defect frequencies); kinematics of paper 01 (speed ratios).
    """
    f = characteristic_frequencies(design, screw_speed)
    out = {
        "screw_flank": f.roller_pass_screw,
        "nut_flank": f.roller_pass_nut,
        "roller_flank": 2.0 * f.roller_spin,
    }
    if design.gear is not None and design.variant != "recirculating":
        out["ring_gear_tooth"] = design.n_rollers * f.carrier
        out["roller_gear_tooth"] = f.roller_spin
    out["carrier"] = f.carrier
    return out
