"""Plain statistics of every measured channel of a window, whatever its rate: what a first
classifier on any rig reads (mean, standard deviation, extremes per channel) — the inputs of
the plain baseline that ``train`` cross-validates beside every fault model
(:mod:`prsm_health.training.fault_candidates`), and that the diagnosis computes like any other
indicator group (``statistics``) so that a shipped baseline diagnoses by the same path.

They are not condition indicators (the mean of a position says where the stroke sits, not how
the actuator is): the indicator models do not read them.
"""

from __future__ import annotations

import numpy as np

from prsm_health.core.channels import CHANNELS

#: The statistics of each channel, in column order.
STATISTICS = ("mean", "std", "min", "max")
#: Prefix of the statistics' names (``stat_drive_torque_mean``): apart from the indicators
#: of the same channel (``drive_torque_mean`` is the torque group's).
PREFIX = "stat_"


def _table() -> dict[str, str]:
    return {
        f"{PREFIX}{channel.name}_{statistic}": channel.unit
        for channel in CHANNELS
        for statistic in STATISTICS
    }


#: Statistic name → unit (its channel's), in column order: every measured channel of the
#: contract, NaN for a channel a window lacks.
CHANNEL_STATISTICS: dict[str, str] = _table()


def channel_statistics(run) -> dict[str, float]:
    """:data:`CHANNEL_STATISTICS` of ``run`` (each channel's finite samples; NaN for a channel
    it lacks or without any finite sample); truth signals are not read."""
    out = dict.fromkeys(CHANNEL_STATISTICS, np.nan)
    for channel in CHANNELS:
        if channel.name not in run.channels:
            continue
        values = np.asarray(run.channels[channel.name], dtype=float)
        values = values[np.isfinite(values)]
        if values.size:
            for statistic in STATISTICS:
                out[f"{PREFIX}{channel.name}_{statistic}"] = float(getattr(np, statistic)(values))
    return out
