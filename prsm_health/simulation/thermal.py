"""The housing temperature a probe on the actuator sees, from the thread-contact temperature.

The lubricant's viscosity follows ``OperatingProfile.temperature`` [K], the lubricant
temperature at the thread contacts (prsm_health.physics.lubrication). A temperature probe sits on
the nut housing, outside the heat source: at steady state the friction heat of the contacts
flows out through the nut and the housing, so the housing runs cooler than the contacts by

    ΔT = R_th · P_f,        T_housing = T_contact − ΔT,

with P_f the run's mean friction power (the truth friction torque times the truth screw speed,
the energy book's friction term over the run) and R_th the thermal resistance from the contacts
to the probe (:data:`CONTACT_TO_HOUSING_RESISTANCE`).

A simulated run lasts seconds, the actuator's thermal time constants are minutes: the housing
temperature is the steady state for the run's friction power, constant over the run. For an
intermittent duty this overstates ΔT (the mean power over the duty cycle is lower than that of
a loaded stroke); the model stays simple and says so.
"""

from __future__ import annotations

import numpy as np

from prsm_health.core.errors import require_range

#: Thermal resistance [K/W] from the thread contacts to a probe on the nut housing, an
#: engineering estimate for the paper-01-size nut (bore 32.5 mm, outside 65 mm, ≈ 20 mm
#: engaged): conduction through the nut wall ln(r_o/r_i)/(2π·k·L) = ln 2/(2π·45·0.02)
#: ≈ 0.12 K/W, plus a nut-to-housing joint 1/(h·A) with h ≈ 3000 W/(m²·K) (bolted steel
#: joints: 1000–10 000) over π·0.065·0.02 m² ≈ 0.08 K/W; about half the contact heat leaves
#: this way (the rest through the screw shaft), so 0.5 × 0.2 ≈ 0.1 K/W. Uncertain by a factor
#: of about 3 either way: it scales the offset, not the sensor model.
CONTACT_TO_HOUSING_RESISTANCE = 0.1


def housing_temperature(contact_temperature: float, friction_power: float) -> float:
    """Steady-state housing temperature [K] at the probe, T_contact − R_th·P_f.

    Parameters
    ----------
    contact_temperature : float [K]
        Lubricant temperature at the thread contacts (``OperatingProfile.temperature``).
    friction_power : float [W]
        Mean friction power of the run (≥ 0; a negative mean — numerical noise at no load —
        counts as 0).

    Returns
    -------
    float [K]
    """
    require_range("profile.temperature", contact_temperature, 223.15, 473.15, unit="K")
    return float(contact_temperature) - CONTACT_TO_HOUSING_RESISTANCE * max(
        float(friction_power), 0.0
    )


def housing_temperature_signal(contact_temperature: float, truth: dict) -> np.ndarray:
    """The truth signal ``housing_temperature`` [K], constant over the run, from the truth
    signals ``friction_torque`` [N·m] and ``screw_speed`` [rad/s] (same length, any rate)."""
    friction = np.asarray(truth["friction_torque"], dtype=float)
    speed = np.asarray(truth["screw_speed"], dtype=float)
    power = float(np.mean(friction * speed)) if friction.size else 0.0
    return np.full(friction.shape, housing_temperature(contact_temperature, power))


__all__ = [
    "CONTACT_TO_HOUSING_RESISTANCE",
    "housing_temperature",
    "housing_temperature_signal",
]
