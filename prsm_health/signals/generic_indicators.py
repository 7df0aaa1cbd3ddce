"""Indicators of any recording, whatever its rate and channels: what a slow rig's drive and
position channels show where the PRSM indicators (built for a 20 kHz recording with an
accelerometer) are NaN or meaningless.

Per slow channel (:data:`CHANNELS`): its spread (standard deviation, 1–99 % range), how fast it
changes (RMS of its rate of change) and where its power lies in the recording's own band
(shares of the detrended signal's power in the lower tenth, the next fifth and the rest of
[0, Nyquist]: unit-free, so the same at 25 Hz or 20 kHz). Across channels: the drive torque
per direction of motion (its forward and backward means and their gap — twice the friction
torque of a reversible screw under a load that does not change with the direction, Coulomb's
law) and per load level (its slope against the axial load: the motor's torque per newton,
L/(2π·η·N) through a reduction N, η the driving efficiency of paper 02 — under a reversing
load a mix of the driving and the back-driving ones), and the following error of the nut
against the screw angle (the position minus the kinematic travel, detrended: lost motion and
elastic lag). No mean of a position or an angle: where the stroke sits says nothing of the actuator.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import detrend, periodogram

from prsm_health.core.run import Run

from .percentiles import percentiles

#: The slow channels each get the per-channel indicators.
CHANNELS = ("nut_position", "screw_speed", "drive_torque", "axial_load")
#: Unit of each channel (for the indicators' units).
_UNITS = {"nut_position": "m", "screw_speed": "rad/s", "drive_torque": "N·m", "axial_load": "N"}
#: Band edges as shares of the Nyquist frequency: the lowest tenth (the duty: load and speed
#: profiles), the next fifth (the drive's and the linkage's modes at a slow rig's rates), the
#: rest (what a slow rate aliases in) — shares, so one table serves 25 Hz and 20 kHz.
BANDS = (0.0, 0.1, 0.3, 1.0)
#: Share of the largest |speed| below which a sample counts as not moving (no direction): the
#: speed estimate's noise and a reversal's ramp stay out of the per-direction means.
MOVING_SHARE = 0.05
#: Fewest samples an indicator is computed from (a mean or a slope of fewer is noise).
MIN_SAMPLES = 16


def _table() -> dict[str, str]:
    units = {}
    for channel in CHANNELS:
        unit = _UNITS[channel]
        units[f"{channel}_std"] = unit
        units[f"{channel}_range"] = unit
        units[f"{channel}_rate_rms"] = f"{unit}/s"
        for lo, hi in zip(BANDS[:-1], BANDS[1:]):
            units[f"{channel}_band_{int(100 * lo)}_{int(100 * hi)}"] = "-"
    units.update(
        {
            "torque_forward_mean": "N·m",
            "torque_backward_mean": "N·m",
            "torque_direction_gap": "N·m",
            "torque_per_load": "N·m/N",
            "following_error_std": "m",
            "following_error_range": "m",
        }
    )
    return units


#: Indicator name → unit, in column order.
GENERIC: dict[str, str] = _table()
#: The channels the group reads (at least one).
NEEDS_ANY = CHANNELS


def generic_indicators(run: Run, nut_per_rad: float | None) -> dict[str, float]:
    """The :data:`GENERIC` indicators of one window (NaN where a channel or the motion lacks);
    ``nut_per_rad``: the nut's travel per screw radian (the design's or the rig's lead / 2π)."""
    out = dict.fromkeys(GENERIC, np.nan)
    ch, rate = run.channels, float(run.sample_rate)
    for channel in CHANNELS:
        x = ch.get(channel)
        if x is None or len(x) < MIN_SAMPLES:
            continue
        x = np.asarray(x, float)
        low, high = percentiles(x, [1.0, 99.0])
        out[f"{channel}_std"] = float(np.std(x))
        out[f"{channel}_range"] = float(high - low)
        out[f"{channel}_rate_rms"] = float(np.sqrt(np.mean(np.diff(x) ** 2)) * rate)
        out.update(_band_shares(channel, x))
    torque, speed, load = ch.get("drive_torque"), ch.get("screw_speed"), ch.get("axial_load")
    if torque is not None and speed is not None:
        moving = np.abs(speed) > MOVING_SHARE * np.max(np.abs(speed))
        forward, backward = moving & (speed > 0), moving & (speed < 0)
        if forward.sum() >= MIN_SAMPLES:
            out["torque_forward_mean"] = float(np.mean(torque[forward]))
        if backward.sum() >= MIN_SAMPLES:
            out["torque_backward_mean"] = float(np.mean(torque[backward]))
        out["torque_direction_gap"] = out["torque_forward_mean"] - out["torque_backward_mean"]
    if torque is not None and load is not None and np.ptp(load) > 0:
        out["torque_per_load"] = float(np.polyfit(load, torque, 1)[0])
    position, angle = ch.get("nut_position"), ch.get("screw_angle")
    if position is not None and angle is not None and nut_per_rad:
        error = detrend(position - nut_per_rad * angle)  # offset and lead error out
        low, high = percentiles(error, [1.0, 99.0])
        out["following_error_std"] = float(np.std(error))
        out["following_error_range"] = float(high - low)
    return out


def _band_shares(channel: str, x: np.ndarray) -> dict[str, float]:
    """Shares of the linearly detrended signal's power in :data:`BANDS` of [0, Nyquist]
    (scipy's one-sided periodogram at a sample rate of 2: frequencies in shares of Nyquist)."""
    share, power = periodogram(x, fs=2.0, window="boxcar", detrend="linear")
    total = float(np.sum(power[1:]))
    out = {}
    for lo, hi in zip(BANDS[:-1], BANDS[1:]):
        inside = (share > lo) & (share <= hi)
        out[f"{channel}_band_{int(100 * lo)}_{int(100 * hi)}"] = (
            float(np.sum(power[inside]) / total) if total > 0 else np.nan
        )
    return out
