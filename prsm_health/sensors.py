"""Sensor models: anti-alias decimation from the integration rate, noise, resolution, bandwidth.

The simulator records every channel at its integration rate f_int = m·f_s (m integer); the
sensor model turns that into what a data logger would store at the sample rate f_s:

1. accelerometer bandwidth: optional Butterworth low-pass (zero-phase) at ``accel_bandwidth``;
2. anti-alias decimation by m with a polyphase FIR (``scipy.signal.resample_poly``, Kaiser
   window β = 5, cut-off at the new Nyquist; ``padtype="line"`` so ramps such as angles and
   positions have no edge transients);
3. white noise on accelerations and torques, quantisation of the screw encoder (counts per
   revolution) and the linear encoder (resolution).

Noise is drawn from the run's seeded generator, so a run stays bit-identical for a given seed.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import signal

from .channels import VIBRATION as ACCEL_CHANNELS
from .errors import require, require_positive, require_range

TORQUE_CHANNELS = ("drive_torque", "friction_torque")


@dataclass(frozen=True)
class SensorModel:
    """What the data logger measures.

    Parameters
    ----------
    sample_rate : float [Hz]
        Output sample rate f_s.
    accel_noise : float [m/s²]
        RMS white noise added to every acceleration channel (0: none).
    torque_noise : float [N·m]
        RMS white noise on the torque channels.
    encoder_counts : int
        Screw (motor) encoder counts per revolution; 0 = ideal.
    linear_encoder_resolution : float [m]
        Nut linear encoder resolution; 0 = ideal.
    accel_bandwidth : float or None [Hz]
        Accelerometer −3 dB bandwidth; None = flat up to the anti-alias filter.
    """

    sample_rate: float = 20_000.0
    accel_noise: float = 0.0
    torque_noise: float = 0.0
    encoder_counts: int = 0
    linear_encoder_resolution: float = 0.0
    accel_bandwidth: float | None = None

    def __post_init__(self):
        require_range("sensors.sample_rate", self.sample_rate, 100.0, 1e6, unit="Hz")
        require_range("sensors.accel_noise", self.accel_noise, 0.0, 1e4, unit="m/s²")
        require_range("sensors.torque_noise", self.torque_noise, 0.0, 1e3, unit="N·m")
        require(
            isinstance(self.encoder_counts, int) and self.encoder_counts >= 0,
            "sensors.encoder_counts",
            self.encoder_counts,
            "must be an integer ≥ 0",
        )
        require_range(
            "sensors.linear_encoder_resolution", self.linear_encoder_resolution, 0.0, 1e-3, unit="m"
        )
        if self.accel_bandwidth is not None:
            require_positive("sensors.accel_bandwidth", self.accel_bandwidth)

    def as_dict(self) -> dict:
        return asdict(self)


def decimate(values: np.ndarray, factor: int) -> np.ndarray:
    """Anti-aliased decimation by an integer factor along axis 0 (polyphase FIR).

    Parameters
    ----------
    values : ndarray, shape (n, …)
    factor : int

    Returns
    -------
    ndarray, shape (ceil(n / factor), …)
    """
    if factor == 1:
        return values.copy()
    return signal.resample_poly(values, 1, factor, axis=0, window=("kaiser", 5.0), padtype="line")


def measure(
    raw: dict[str, np.ndarray], integration_rate: float, sensors: SensorModel, rng
) -> dict[str, np.ndarray]:
    """Turn channels recorded at ``integration_rate`` into sampled sensor channels.

    Parameters
    ----------
    raw : dict of name → ndarray [SI]
        Channels at the integration rate (every name of the channel contract except time).
    integration_rate : float [Hz]
        An integer multiple of ``sensors.sample_rate``.
    sensors : SensorModel
    rng : numpy.random.Generator

    Returns
    -------
    dict of name → float64 ndarray at ``sensors.sample_rate``
    """
    factor = int(round(integration_rate / sensors.sample_rate))
    require(
        factor >= 1
        and abs(factor * sensors.sample_rate - integration_rate) < 1e-6 * integration_rate,
        "sensors.sample_rate",
        sensors.sample_rate,
        f"must divide the integration rate {integration_rate:g} Hz",
    )
    out: dict[str, np.ndarray] = {}
    for name, values in raw.items():
        x = np.asarray(values, dtype=float)
        if name in ACCEL_CHANNELS and sensors.accel_bandwidth is not None:
            nyquist = 0.5 * integration_rate
            if sensors.accel_bandwidth < 0.95 * nyquist:
                sos = signal.butter(2, sensors.accel_bandwidth / nyquist, output="sos")
                x = signal.sosfiltfilt(sos, x)
        out[name] = decimate(x, factor)
    for name in ACCEL_CHANNELS:
        if sensors.accel_noise > 0 and name in out:
            out[name] = out[name] + rng.normal(0.0, sensors.accel_noise, out[name].shape)
    for name in TORQUE_CHANNELS:
        if sensors.torque_noise > 0 and name in out:
            out[name] = out[name] + rng.normal(0.0, sensors.torque_noise, out[name].shape)
    if sensors.encoder_counts and "screw_angle" in out:
        step = 2 * np.pi / sensors.encoder_counts
        out["screw_angle"] = np.round(out["screw_angle"] / step) * step
    if sensors.linear_encoder_resolution and "nut_position" in out:
        step = sensors.linear_encoder_resolution
        out["nut_position"] = np.round(out["nut_position"] / step) * step
    return out
