"""Channels the signal contract can derive from others a recording has, derived the same way
for every reader (and so for the importer, ``diagnose`` and the service alike)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from prsm_health.core.run import Run

#: Derived channel → the channel it is derived from.
DERIVED_FROM = {"screw_speed": "screw_angle"}


def derive_channels(run: Run) -> tuple[Run, tuple[str, ...]]:
    """``run`` with the derivable channels it lacks, and their names.

    ``screw_speed`` [rad/s] is the time derivative of ``screw_angle`` (central differences,
    ``numpy.gradient``): the contract's screw speed is the drive's estimate from its angle
    sensor, which is what a drive computes too (docs/import.md). A run that has every channel
    it could derive, or too few samples for a derivative, comes back as is (same object).
    """
    added = {}
    if len(run) >= 2:
        for name, source in DERIVED_FROM.items():
            if name not in run.channels and source in run.channels:
                added[name] = np.gradient(np.asarray(run.channels[source], float), run.time)
    if not added:
        return run, ()
    channels = {**run.channels, **added}
    return replace(run, channels=channels), tuple(added)
