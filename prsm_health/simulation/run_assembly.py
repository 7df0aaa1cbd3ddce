"""From a model's truth at the integration rate to the :class:`~prsm_health.core.run.Run` a user
gets: what both dynamic models (the standard PRSM's, :mod:`.dynamics`; the recirculating one's,
:mod:`.recirculating`) do the same way once they have integrated — the housing temperature at
the probe, the scenario's sensors reading the truth, and the run's time axis, check phases,
labels and operating point.
"""

from __future__ import annotations

import numpy as np

from prsm_health.core.run import Run

from .instrumentation import bind_drive_train, sensor_rng
from .thermal import housing_temperature_signal


def measure(scenario, truth_raw: dict[str, np.ndarray], rate: float) -> dict[str, np.ndarray]:
    """The scenario's measured channels from its truth at the integration rate ``rate`` [Hz]:
    ``truth_raw`` gains ``housing_temperature`` (derived after the model's signals: the housing
    at the temperature probe, :mod:`.thermal`), then the instrumentation bound to the drive
    train reads it with the scenario's sensor seed."""
    truth_raw["housing_temperature"] = housing_temperature_signal(
        scenario.profile.temperature, truth_raw
    )
    return bind_drive_train(scenario.instrumentation, scenario.drive_train).measure(
        truth_raw, rate, sensor_rng(scenario.sensors_seed)
    )


def assemble_run(
    scenario,
    *,
    channels: dict[str, np.ndarray],
    truth: dict[str, np.ndarray],
    energy: dict[str, float],
    labels: dict,
    model_info: dict,
) -> Run:
    """The run of a scenario: its channels and its truth at the sample rate (``truth``'s
    length sets the time axis), the energy book, the scenario's labels with ``labels`` added,
    its dict form with ``model_info`` added, and — for a health check — which phase each sample
    is in (the controller commands them, so it is known) and the check's record."""
    check = scenario.profile.check
    rate = scenario.instrumentation.sample_rate
    time = np.arange(len(next(iter(truth.values())))) / rate
    return Run(
        time=time,
        channels=channels,
        sample_rate=rate,
        labels={**scenario.labels(), **labels},
        scenario={**scenario.to_dict(), **model_info},
        energy=energy,
        truth=truth,
        check_phase=None if check is None else check.phase_at(time),
        check=None if check is None else check.recorded(),
        operating=scenario.operating_point(),
    )
