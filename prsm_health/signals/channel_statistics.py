"""Plain statistics of every measured channel of a recording, whatever its rate: what a first
classifier on any rig reads (mean, standard deviation, extremes per channel), and what the
diagnosis' indicators — built for a 20 kHz PRSM recording — must beat
(:mod:`prsm_health.training.plain_baseline`)."""

from __future__ import annotations

import numpy as np

#: The statistics of each channel, in column order.
STATISTICS = ("mean", "std", "min", "max")


def channel_statistics(run) -> dict[str, float]:
    """``{channel}_{statistic}`` of each measured channel of ``run`` (its finite samples; NaN
    for a channel without any); truth signals are not read."""
    out = {}
    for name in sorted(run.channels):
        values = np.asarray(run.channels[name], dtype=float)
        values = values[np.isfinite(values)]
        for statistic in STATISTICS:
            out[f"{name}_{statistic}"] = (
                float(getattr(np, statistic)(values)) if values.size else float("nan")
            )
    return out


def dataset_statistics(dataset, run_ids):
    """:func:`channel_statistics` of the runs ``run_ids`` of a dataset, one row each (a
    DataFrame in the order given)."""
    import pandas as pd

    rows = [channel_statistics(dataset.run(int(i), truth=False)) for i in run_ids]
    return pd.DataFrame(rows)
