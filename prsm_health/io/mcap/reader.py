"""MCAP recording → Run (:func:`read_mcap`), tolerant of truncated and damaged files."""

from __future__ import annotations

import json
import os
import warnings

from prsm_health.core.channels import CHECK_METADATA, TOPIC_FIELDS
from prsm_health.core.check_phases import CheckPhases
from prsm_health.core.errors import PRSMHealthError, TruncatedRecordingWarning
from prsm_health.core.run import Run

from ._samples import _align, _Batch, _merge_topic, _sample_rate, _start_ns, _times
from ._scan import _chunk_batches, _Source, _unchunked_batches

__all__ = ["read_mcap"]


def read_mcap(path: str | os.PathLike) -> Run:
    """Read a run from an MCAP recording (the inverse of :func:`write_mcap`).

    Reads files with or without a summary section, chunked or not, by scanning the records in
    order. Floats come back exactly; ``time`` is exactly ``arange(n) / sample_rate`` when the
    file was written from such a run, else ``(log_time - start) / 1e9`` [s].

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Run
        Measured channels of the topics present, truth signals of ``/prsm/truth`` (if any) in
        ``Run.truth``; labels from the ``labels`` metadata, the operating point from the
        ``operating`` metadata (files written before it: from the labels), scenario from its
        attachment, sample rate and energy from the ``prsm_health`` metadata (the sample rate
        is estimated from the log-time spacing when that record is missing); a health check's
        name and boundaries from the ``health_check`` metadata in ``Run.check``, and
        ``Run.check_phase`` rebuilt from those boundaries on the time axis (the rule the
        writer's phase topic was made with, :func:`~prsm_health.core.check_phases.phase_of_samples`).

    Warns
    -----
    TruncatedRecordingWarning
        The file is truncated or damaged (an interrupted recording): the samples before the
        damage are returned, the incomplete tail dropped.

    Raises
    ------
    PRSMHealthError
        Missing, empty or non-MCAP file; no ``/prsm/*`` signal topic; no sample readable.
    """
    with _Source(path) as source:
        per_topic: dict[str, list[_Batch]] = {}
        loose: list = []
        for kind, *rest in source.scan():
            if kind == "chunk":
                for batch in _chunk_batches(source, rest[1]):
                    per_topic.setdefault(batch.topic, []).append(batch)
            elif kind == "message":
                loose.append(rest[0])
        for batch in _unchunked_batches(source, loose):
            per_topic.setdefault(batch.topic, []).append(batch)
        if not source.wanted:
            raise source.no_topics_error()
        batches = {
            topic: _merge_topic(per_topic[topic]) for topic in TOPIC_FIELDS if topic in per_topic
        }
        batches = {t: b for t, b in batches.items() if len(b.log_time) and b.fields}
        if not batches:
            where = f": {source.damage}" if source.damage else ""
            raise PRSMHealthError(f"{source.path}: no samples could be read{where}")
        grid, channels, truth = _align(batches, trim=source.damage is not None)
        info = source.info()
        rate = _sample_rate(info, grid, source.path)
        start = _start_ns(info, grid)
        time = _times(grid, start, rate, exact_grid="sample_rate" in info)
        try:
            energy = json.loads(info.get("energy", "{}"))
        except ValueError:
            energy = {}
        check = _check_record(source.metadata.get(CHECK_METADATA))
        run = Run(
            time,
            channels,
            rate,
            source.labels(),
            source.scenario(),
            energy,
            truth,
            check_phase=None if check is None else check.of_samples(time),
            check=check,
            operating=source.operating(),
        )
        if source.damage:
            warnings.warn(
                f"{source.path}: {source.damage}; read {len(time)} samples "
                f"({len(time) / rate:.6g} s) before the damage",
                TruncatedRecordingWarning,
                stacklevel=2,
            )
        return run


def _check_record(record: dict | None) -> CheckPhases | None:
    """The check of the ``health_check`` metadata record (its ``phases`` a JSON text); None
    when absent or unreadable (a recording without a check)."""
    if not record or "phases" not in record:
        return None
    try:
        return CheckPhases.from_record(
            {"name": record.get("name", ""), "phases": json.loads(record["phases"])}
        )
    except (ValueError, TypeError, KeyError):
        warnings.warn(
            "health_check metadata is not readable; check phases left out",
            UserWarning,
            stacklevel=3,
        )
        return None
