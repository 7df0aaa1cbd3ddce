"""Recirculating PRSM kinematics (paper 03): speeds, roller reset events and displacements.

Relative to the nut each roller drifts back by one lead per carrier revolution (eq. 31); in
the nut's threadless area (:mod:`prsm_health.physics.recirculating.geometry`) the cam ring pushes it
forward by that lead again ("reset"). Each roller resets once per carrier revolution, so the
mechanism has N reset events per carrier revolution, at N·f_c
(:func:`~prsm_health.physics.kinematics.characteristic_frequencies`, ``roller_reset``).

Readings of the paper (Tables 1–2 and the figures are not in the text)
----------------------------------------------------------------------
- **"Orbital angle 1.62π"** in §4.2 is not eq. (11)'s β (0.0161π for the reconstructed
  geometry) but the carrier angle φ_c of eq. (30) over the 0.1 s run (screw turned 4π):
  4π·d_s/(2d_c) = 1.6203π. :func:`motion` returns it as ``carrier_angle``.
- **Roller numbering and start angle.** Roller i sits (i − 1)·φ behind roller 1, which starts
  against the cam platform at the entrance of the threadless area (§3.2 steps 4–6). This is
  the only order consistent with §4.2–4.3: roller 7 resets after half a carrier turn (model
  0.062 s, paper "0.06–0.07 s") and rollers 11, 12 have not reset by 0.1 s.
- **Threadless-area layout.** Forward rotation (ω_s > 0) enters the 2β area at −β, reverse
  rotation at +β (:mod:`prsm_health.physics.recirculating.geometry`).

References
----------
Paper 03 (docs/references.md) — eqs. (23)–(33) motion, §2.1 and §3.2 (angles), §4.2 results.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import require, require_positive

from ..kinematics import characteristic_frequencies, speed_ratios
from .geometry import (
    TWO_PI,
    _require_recirculating,
    orbital_angle,
    reset_stroke,
    roller_spacing,
)


# ------------------------------------------------------------------------- input checks
def _require_speed(screw_speed) -> float:
    require(
        isinstance(screw_speed, (int, float, np.floating, np.integer))
        and math.isfinite(screw_speed),
        "screw_speed",
        screw_speed,
        "must be a finite number [rad/s] (sign = direction of rotation)",
    )
    return float(screw_speed)


def _require_times(time) -> np.ndarray:
    t = np.asarray(time, dtype=float)
    require(
        t.ndim <= 1 and bool(np.all(np.isfinite(t))) and bool(np.all(t >= 0.0)),
        "time",
        f"array of shape {t.shape}" if t.ndim else float(t),
        "must be finite times ≥ 0 [s] from run start (scalar or 1-D)",
    )
    return np.atleast_1d(t)


# ------------------------------------------------------------------------- kinematics
def carrier_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Carrier (roller revolution) speed ω_c = d_s/(2d_c)·ω_s [rad/s], signed like ω_s.

    References
    ----------
    Paper 03, eq. (25), via :func:`prsm_health.physics.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).carrier * _require_speed(screw_speed)


def roller_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Absolute roller spin ω_r = −d_s/(2d_r)·ω_s [rad/s] (opposite to the screw).

    References
    ----------
    Paper 03, eqs. (26)–(27), via :func:`prsm_health.physics.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).roller_spin * _require_speed(screw_speed)


def nut_speed(design: PRSMDesign, screw_speed: float) -> float:
    """Nut axial speed v_n = n·p·ω_s/2π [m/s], signed like ω_s.

    References
    ----------
    Paper 03, eq. (29), via :func:`prsm_health.physics.kinematics.speed_ratios`.
    """
    _require_recirculating(design)
    return speed_ratios(design).nut * _require_speed(screw_speed)


def _start_angles(design: PRSMDesign, roller1_angle: float | None) -> np.ndarray:
    beta = orbital_angle(design)
    if roller1_angle is None:
        roller1_angle = -beta
    require(
        isinstance(roller1_angle, (int, float)) and math.isfinite(roller1_angle),
        "roller1_angle",
        roller1_angle,
        "must be a finite angle [rad]",
    )
    i = np.arange(design.n_rollers)
    return roller1_angle - i * roller_spacing(design)


def _first_travel(design: PRSMDesign, screw_speed: float, roller1_angle) -> np.ndarray:
    """Carrier travel [rad, ≥ 0] before each roller next enters its crossing sector."""
    beta = orbital_angle(design)
    theta0 = _start_angles(design, roller1_angle)
    # Forward rotation enters the threadless area at −β, reverse rotation at +β.
    travel = (-beta - theta0) if screw_speed > 0 else (theta0 - beta)
    travel = np.mod(travel, TWO_PI)
    return np.where(travel >= TWO_PI, travel - TWO_PI, travel)


@dataclass(frozen=True)
class ResetEvents:
    """Roller reset events of a run, sorted by time.

    Attributes
    ----------
    times : numpy.ndarray [s]
        Instants a roller enters its crossing sector (contact with the platform chamfer).
    rollers : numpy.ndarray of int
        Roller number (1 … N) of each event.
    crossing_time : float [s]
        τ = β/|ω_c|, time spent crossing arc DE (inf at zero speed).
    rate : float [Hz]
        Reset events per second, N·f_c.
    """

    times: np.ndarray
    rollers: np.ndarray
    crossing_time: float
    rate: float

    @property
    def end_times(self) -> np.ndarray:
        """Instants each crossing ends (roller re-engages at E) [s]."""
        return self.times + self.crossing_time

    def __len__(self) -> int:
        return len(self.times)


def reset_events(
    design: PRSMDesign,
    screw_speed: float,
    duration: float,
    *,
    roller1_angle: float | None = None,
) -> ResetEvents:
    """When each roller enters the threadless area during a run at constant screw speed.

    Roller i starts at θ_i = θ_1 − (i − 1)·φ (nut frame, angle 0 = centre of the threadless
    area, positive in the sense of positive screw rotation) and moves with the carrier,
    θ_i(t) = θ_i + ω_c·t. It resets each time it reaches the crossing sector's entrance, −β
    going forward, +β going backward: exactly once per carrier revolution in either
    direction. A roller already inside the sector at t = 0 is taken as having crossed.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    screw_speed : float [rad/s]
        Signed; 0 gives no events.
    duration : float [s]
        Events are reported in [0, duration).
    roller1_angle : float or None [rad]
        θ_1. None: −β, roller 1 against the cam platform at the entrance (§3.2 step 4), so
        roller 1 resets at t = 0 when turning forward.

    Returns
    -------
    ResetEvents

    References
    ----------
    Paper 03 §2.1 (2β threadless area), §3.2 (assembly angles), eq. (25) (ω_c); reset rate
    N·f_c from :func:`prsm_health.physics.kinematics.characteristic_frequencies`.
    """
    _require_recirculating(design)
    w_s = _require_speed(screw_speed)
    require_positive("duration", duration)
    beta = orbital_angle(design)
    w_c = carrier_speed(design, w_s)
    rate = characteristic_frequencies(design, w_s).roller_reset
    if w_c == 0.0:
        _start_angles(design, roller1_angle)  # still validate the angle
        empty = np.zeros(0)
        return ResetEvents(empty, np.zeros(0, dtype=int), math.inf, 0.0)
    period = TWO_PI / abs(w_c)
    first = _first_travel(design, w_s, roller1_angle) / abs(w_c)
    n_rev = int(math.ceil(duration / period)) + 1
    times = first[:, None] + period * np.arange(n_rev)[None, :]
    rollers = np.broadcast_to(np.arange(1, design.n_rollers + 1)[:, None], times.shape)
    keep = times < duration
    t, r = times[keep], rollers[keep]
    order = np.argsort(t, kind="stable")
    return ResetEvents(t[order], r[order].astype(int), beta / abs(w_c), rate)


@dataclass(frozen=True)
class RecirculatingMotion:
    """Rigid-body motion of a recirculating PRSM at constant screw speed (all signed, SI).

    Attributes
    ----------
    time : numpy.ndarray [s]
    screw_angle : numpy.ndarray [rad]
        φ_s = ω_s·t.
    carrier_angle : numpy.ndarray [rad]
        φ_c = (ω_c/ω_s)·φ_s, eq. (30): the "orbital angle" of §4.2.
    nut : numpy.ndarray [m]
        L_n, nut displacement relative to the (axially fixed) screw, eq. (28).
    roller_drift : numpy.ndarray [m]
        L_r1 = lead·φ_c/2π, eq. (31): how far the rollers lag the nut (opposite to its travel).
    roller_threaded : numpy.ndarray [m]
        L_r2 = L_n − L_r1, eq. (32): roller relative to the screw without resets.
    roller : numpy.ndarray [m], shape (N, len(time))
        L_r3 of each roller, eq. (33) generalised: L_r2 plus one lead per completed reset,
        the jump spread linearly over the crossing time τ (the chamfer lifts at constant
        axial speed).
    resets : numpy.ndarray [-], shape (N, len(time))
        Resets completed by each roller (fractional during a crossing).
    """

    time: np.ndarray
    screw_angle: np.ndarray
    carrier_angle: np.ndarray
    nut: np.ndarray
    roller_drift: np.ndarray
    roller_threaded: np.ndarray
    roller: np.ndarray
    resets: np.ndarray

    @property
    def roller_relative_to_nut(self) -> np.ndarray:
        """Roller axial position relative to the nut, L_r3 − L_n [m], shape (N, T)."""
        return self.roller - self.nut[None, :]


def motion(
    design: PRSMDesign,
    screw_speed: float,
    time,
    *,
    roller1_angle: float | None = None,
) -> RecirculatingMotion:
    """Nut and roller displacements with one reset per roller per carrier revolution.

    Parameters
    ----------
    design : PRSMDesign
        Recirculating design.
    screw_speed : float [rad/s]
        Constant, signed.
    time : array_like [s]
        Times ≥ 0 from run start.
    roller1_angle : float or None [rad]
        See :func:`reset_events`.

    Returns
    -------
    RecirculatingMotion

    References
    ----------
    Paper 03, eqs. (28), (30)–(33); the reset of one lead, §2.3.
    """
    _require_recirculating(design)
    w_s = _require_speed(screw_speed)
    t = _require_times(time)
    ratios = speed_ratios(design)
    lead = reset_stroke(design)
    phi_s = w_s * t
    phi_c = ratios.carrier * phi_s
    nut = ratios.nut * phi_s
    drift = lead * phi_c / TWO_PI
    threaded = nut - drift
    resets = np.zeros((design.n_rollers, t.size))
    if w_s != 0.0 and t.size:
        # Events at or after the last time contribute nothing, so [0, t_max) suffices.
        horizon = max(float(t.max()), np.finfo(float).tiny)
        events = reset_events(design, w_s, horizon, roller1_angle=roller1_angle)
        tau = events.crossing_time
        for when, roller in zip(events.times, events.rollers):
            resets[roller - 1] += np.clip((t - when) / tau, 0.0, 1.0)
    else:
        _start_angles(design, roller1_angle)
    roller = threaded[None, :] + math.copysign(lead, w_s) * resets
    return RecirculatingMotion(t, phi_s, phi_c, nut, drift, threaded, roller, resets)
