"""Run → MCAP recording (:func:`write_mcap`).

One JSON message per sample and topic, interleaved sample by sample as a live recorder would
write them. A health check's phase (``run.check_phase``) goes to
:data:`~prsm_health.core.channels.TOPIC_CHECK_PHASE`, one message per phase change (at the
first sample and wherever the phase changes), and the check's name and phase boundaries to the
Metadata record :data:`~prsm_health.core.channels.CHECK_METADATA`. Payloads are written with :func:`repr` of each float (shortest string that parses
back to the same double) — byte for byte what ``json.dumps(..., separators=(",", ":"))`` writes
for finite values. JSON has no NaN or infinity: non-finite samples are written as ``null`` (and
read back as NaN).
"""

from __future__ import annotations

import math
import os
from itertools import chain
from pathlib import Path

import numpy as np

from prsm_health.core.channels import (
    CHANNEL_NAMES,
    CHECK_METADATA,
    CHECK_PHASE,
    TOPIC_CHECK_PHASE,
    TOPIC_FIELDS,
    TOPIC_TRUTH,
    TRUTH_NAMES,
    UNITS,
)
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.jsonable import dumps
from prsm_health.core.operating_point import OPERATING_METADATA
from prsm_health.core.run import Run

from ._container import DEFAULT_CHUNK_SIZE, _AtomicFile, _FileWriter, _library, _MessageBlock
from ._samples import _require_positive, _to_ns
from .schema import (
    CHECK_PHASE_SCHEMA_NAME,
    FORMAT_VERSION,
    INFO_METADATA,
    LABELS_METADATA,
    SCHEMA_NAMES,
    check_phase_schema,
    encode_metadata_value,
    encode_schema,
    topic_schema,
)

__all__ = ["sample_payloads", "write_mcap"]

# Samples formatted at a time by write_mcap (~10 MB of JSON for the measured topics, ~30 MB
# with the truth topic).
_WRITE_BLOCK = 1 << 16


def sample_payloads(fields: list[str], columns: list[np.ndarray]) -> list[bytes]:
    """Message payloads of one signal topic: one compact JSON object per sample (row), with the
    keys ``fields`` and the values of ``columns``, floats as ``repr`` (exact), non-finite as
    ``null``. Used by :func:`write_mcap` and by the live view (:mod:`prsm_health.apps.live`)."""
    rows = zip(*[column.tolist() for column in columns])
    if all(np.isfinite(column).all() for column in columns):
        template = ("{" + ",".join(f'"{name}":%r' for name in fields) + "}").encode()
        return [template % row for row in rows]
    template = "{" + ",".join(f'"{name}":%s' for name in fields) + "}"
    finite = math.isfinite
    return [
        (template % tuple(repr(v) if finite(v) else "null" for v in row)).encode() for row in rows
    ]


def _phase_messages(run: Run, n: int) -> tuple[np.ndarray | None, list[bytes]]:
    """Sample indices where the check phase changes (the first sample included) and the
    message of each, ``{"index": k, "name": …}`` (name "" outside any phase); (None, []) when
    the run is no check."""
    if run.check_phase is None:
        return None, []
    phase = np.asarray(run.check_phase)
    if phase.shape != (n,):
        raise PRSMHealthError(f"{CHECK_PHASE} has shape {phase.shape}; expected ({n},) like time")
    names = run.check.names() if run.check is not None else {}
    changes = np.flatnonzero(np.concatenate(([True], phase[1:] != phase[:-1])))
    payloads = [
        dumps({"index": int(phase[i]), "name": names.get(int(phase[i]), "")}).encode()
        for i in changes
    ]
    return changes, payloads


def write_mcap(
    run: Run,
    path: str | os.PathLike,
    *,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    scenario_name: str = "scenario.json",
    start_time_ns: int = 0,
) -> Path:
    """Write a run as an MCAP recording that Foxglove plots directly.

    Parameters
    ----------
    run : Run
        Only the contract channels present in ``run.channels`` are written (a recording may
        lack some), each measured topic with the fields of those channels; other channels are
        ignored. The truth signals of ``run.truth`` go to :data:`TOPIC_TRUTH`, which is left
        out when the run has none.
    path : str or path-like
        Destination. Written atomically: a temporary file in the same directory, renamed onto
        ``path`` once complete, so an interrupted write never leaves a half file under it.
    chunk_size : int [bytes]
        Uncompressed size above which a chunk is closed.
    scenario_name : str
        Name of the scenario attachment (``application/json``).
    start_time_ns : int [ns]
        Log time of the run start; message ``log_time`` = ``publish_time`` =
        ``start_time_ns + round(time · 1e9)``. Use a Unix time to place the run on a clock.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    PRSMHealthError
        The run has no contract channel, channel lengths differ from ``time``, ``time`` is not
        finite and non-decreasing, or the destination directory does not exist.
    """
    path = Path(path)
    time = np.asarray(run.time, dtype=np.float64)
    n = time.size
    if time.ndim != 1 or n == 0:
        raise PRSMHealthError("run.time must be a non-empty 1-D array [s]")
    if not np.isfinite(time).all() or (n > 1 and np.any(np.diff(time) < 0)):
        raise PRSMHealthError("run.time must be finite and non-decreasing [s]")
    if not isinstance(start_time_ns, (int, np.integer)) or start_time_ns < 0:
        raise PRSMHealthError(f"start_time_ns = {start_time_ns!r} must be an integer >= 0 [ns]")
    if not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise PRSMHealthError(f"chunk_size = {chunk_size!r} must be an integer >= 1 [bytes]")
    rate = run.sample_rate
    _require_positive("run.sample_rate", rate, "[Hz]")
    if not scenario_name or not isinstance(scenario_name, str):
        raise PRSMHealthError("scenario_name must be a non-empty string")
    if float(time[-1]) * 1e9 + start_time_ns >= 2**63 or float(time[0]) * 1e9 + start_time_ns < 0:
        raise PRSMHealthError("start_time_ns + time does not fit the MCAP 64-bit ns clock")
    for kind, signals, names in (
        ("channel", run.channels, CHANNEL_NAMES),
        ("truth", run.truth, TRUTH_NAMES),
    ):
        for name, values in signals.items():
            if name in names and np.shape(values) != (n,):
                raise PRSMHealthError(
                    f"{kind} {name!r} has shape {np.shape(values)}; expected ({n},) like time"
                )

    def source(topic: str) -> dict:
        return run.truth if topic == TOPIC_TRUTH else run.channels

    topics = {}
    for topic, pairs in TOPIC_FIELDS.items():
        present = [(field, name) for field, name in pairs if name in source(topic)]
        if present:
            topics[topic] = present
    if not set(topics) - {TOPIC_TRUTH}:
        raise PRSMHealthError(
            f"run has none of the contract channels ({', '.join(CHANNEL_NAMES)}); nothing to write"
        )

    phase_changes, phase_payloads = _phase_messages(run, n)
    log_time = start_time_ns + _to_ns(time)
    columns = {
        topic: [np.asarray(source(topic)[name], dtype=np.float64) for _, name in pairs]
        for topic, pairs in topics.items()
    }

    try:
        info = {
            "format": FORMAT_VERSION,
            "sample_rate": repr(float(rate)),
            "start_time_ns": str(int(start_time_ns)),
            "scenario_attachment": scenario_name,
            "units": dumps(UNITS),
            "energy": dumps(run.energy),
        }
        scenario = dumps(run.scenario, indent=1).encode()
        labels = {str(k): encode_metadata_value(v) for k, v in run.labels.items()}
        operating = {k: encode_metadata_value(v) for k, v in run.operating.as_dict().items()}
        check = (
            {"name": run.check.name, "phases": dumps(run.check.as_record()["phases"])}
            if run.check is not None
            else None
        )
    except (TypeError, ValueError) as exc:
        raise PRSMHealthError(
            f"run labels, scenario or energy not JSON-serialisable: {exc}"
        ) from None

    target = _AtomicFile(path)
    try:
        writer = _FileWriter(target.stream, chunk_size=chunk_size)
        writer.start(_library())
        channel_ids = []
        for topic, pairs in topics.items():
            schema = encode_schema(topic_schema(topic, pairs))
            schema_id = writer.add_schema(SCHEMA_NAMES[topic], "jsonschema", schema)
            channel_ids.append(writer.add_channel(topic, "json", schema_id))
        phase_id = None
        if phase_changes is not None:
            schema = encode_schema(check_phase_schema())
            schema_id = writer.add_schema(CHECK_PHASE_SCHEMA_NAME, "jsonschema", schema)
            phase_id = writer.add_channel(TOPIC_CHECK_PHASE, "json", schema_id)
        writer.add_metadata(LABELS_METADATA, labels)
        writer.add_metadata(OPERATING_METADATA, operating)
        writer.add_metadata(INFO_METADATA, info)
        if check is not None:
            writer.add_metadata(CHECK_METADATA, check)
        writer.add_attachment(
            scenario_name, "application/json", scenario, log_time=int(start_time_ns)
        )
        # One message per topic and sample, interleaved sample by sample as a live recorder
        # would write them, so every chunk covers one time span of all topics. Formatted
        # block by block to bound the memory of long runs.
        k = len(channel_ids)
        for a in range(0, n, _WRITE_BLOCK):
            b = min(a + _WRITE_BLOCK, n)
            payloads = [
                sample_payloads([name for name, _ in pairs], [c[a:b] for c in columns[t]])
                for t, pairs in topics.items()
            ]
            ids = np.tile(np.asarray(channel_ids), b - a)
            samples = np.repeat(np.arange(a, b), k)
            messages = list(chain.from_iterable(zip(*payloads)))
            here = (
                np.flatnonzero((phase_changes >= a) & (phase_changes < b))
                if phase_id is not None
                else ()
            )
            if len(here):
                # the phase messages of this block after the samples they belong to
                order = np.argsort(np.concatenate([samples, phase_changes[here]]), kind="stable")
                ids = np.concatenate([ids, np.full(here.size, phase_id)])[order]
                samples = np.concatenate([samples, phase_changes[here]])[order]
                messages += [phase_payloads[i] for i in here]
                messages = [messages[i] for i in order]
            block = _MessageBlock.from_payloads(
                ids, samples, log_time[samples], log_time[samples], messages
            )
            writer.add_messages(block, more=True)
        writer.finish()
    except BaseException:
        target.abort()
        raise
    return target.commit()
