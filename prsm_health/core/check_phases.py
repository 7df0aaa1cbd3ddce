"""The phases of a health-check recording: :class:`CheckPhases` (the check's name and each
phase's span and commanded condition), carried by :attr:`Run.check
<prsm_health.core.run.Run.check>` beside the per-sample ``check_phase`` column.

The controller commands the phases, so this is measured-side information a rig's recording
may carry too; the diagnosis finds a phase by its condition, not its name. In files it is the
``health_check`` record (docs/formats.md): :meth:`CheckPhases.as_record` writes it,
:meth:`CheckPhases.from_record` reads it (files written before the condition was recorded
have none: ``motion``, ``speed`` and ``load`` are then None).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PhaseSpan:
    """One phase of a health check as a recording knows it.

    Parameters
    ----------
    index : int
        The phase's number in the check, from 0 (the value of ``check_phase`` in its samples).
    name : str
    start, end : float [s]
        Its settled part from the run start, ``start ≤ t < end`` (the ramp before ``start``
        belongs to no phase).
    motion : {"constant", "reversing", "rest"} or None
        Commanded motion; None when the recording does not say.
    speed : float or None [rad/s of the screw, signed]
        Commanded speed (a reversal: its amplitude); None when not said.
    load : float or None [N, resisting the motion]
        Commanded load; None when not said or left as a share of a rating.
    """

    index: int
    name: str
    start: float
    end: float
    motion: str | None = None
    speed: float | None = None
    load: float | None = None

    def as_dict(self) -> dict:
        """The phase as the ``health_check`` record lists it."""
        return {
            "index": self.index,
            "name": self.name,
            "start": self.start,
            "end": self.end,
            "motion": self.motion,
            "speed": self.speed,
            "load": self.load,
        }


@dataclass(frozen=True)
class CheckPhases:
    """A health check's name and its phases, in check order."""

    name: str
    phases: tuple[PhaseSpan, ...]

    def names(self) -> dict[int, str]:
        """Phase index → name."""
        return {p.index: p.name for p in self.phases}

    def of_samples(self, time) -> np.ndarray:
        """The phase index of each sample time [s] (:func:`phase_of_samples`)."""
        return phase_of_samples(time, self.phases)

    def as_record(self) -> dict:
        """``{"name", "phases": [{"index", "name", "start", "end", "motion", "speed",
        "load"}]}``: what files store (the Parquet ``prsm_health.health_check`` metadata, the
        MCAP ``health_check`` record, a dataset run's ``check_phases`` label)."""
        return {"name": self.name, "phases": [p.as_dict() for p in self.phases]}

    @classmethod
    def from_record(cls, record) -> CheckPhases | None:
        """The check of a stored record (:meth:`as_record`); None when there is none (absent,
        empty, no phases).

        Raises
        ------
        ValueError, TypeError, KeyError
            A record whose phases lack their index, name, start or end, or hold values of
            another type: the caller names the file.
        """
        if not isinstance(record, Mapping) or not record.get("phases"):
            return None

        def number(value):
            return None if value is None else float(value)

        phases = tuple(
            PhaseSpan(
                int(p["index"]),
                str(p["name"]),
                float(p["start"]),
                float(p["end"]),
                None if p.get("motion") is None else str(p["motion"]),
                number(p.get("speed")),
                number(p.get("load")),
            )
            for p in record["phases"]
        )
        return cls(str(record.get("name", "")), phases)


def phase_of_samples(time, phases) -> np.ndarray:
    """Health-check phase index of each sample time [s]: the ``index`` of the phase (a
    :class:`PhaseSpan`) whose ``start`` ≤ t < ``end``, −1 outside any; int16. The one rule
    that turns phase boundaries into the ``check_phase`` column (the simulator and the file
    readers use it)."""
    time = np.asarray(time, dtype=float)
    out = np.full(time.shape, -1, dtype=np.int16)
    for p in phases:
        out[(time >= p.start) & (time < p.end)] = p.index
    return out
