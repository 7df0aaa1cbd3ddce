"""MCAP recordings of runs: writer, tolerant reader, streaming replay and diagnosis output.

The files follow the MCAP contract documented in docs/formats.md, so Foxglove plots every
channel with no custom code:

- JSON schema encoding (``jsonschema``, draft-07) and JSON message encoding, one message per
  sample and topic, each message a flat object of numbers;
- topics and fields from the channel contract (:mod:`prsm_health.core.channels`,
  :data:`TOPIC_FIELDS`): the measured channels on :data:`TOPIC_NUT_ACCEL` (fields ``axial``,
  ``tangential``, ``radial_x``, ``radial_y``) and :data:`TOPIC_DRIVE` (``screw_angle``,
  ``screw_speed``, ``nut_position``, ``drive_torque``, ``axial_load``), each with the fields
  of the channels the run has; the simulator's truth signals on :data:`TOPIC_TRUTH` (one field
  per truth signal, named like it; only in simulated runs); and :data:`TOPIC_DIAGNOSIS`
  (written by :class:`DiagnosisWriter`); SI units, given in each field's schema description;
- ``log_time`` = ``publish_time`` = run start + sample time, in nanoseconds;
- zstd-compressed chunks, message indexes, and a summary section (schemas, channels,
  statistics, chunk/attachment/metadata indexes, summary offsets) with its CRC;
- the run labels in a Metadata record named ``labels``, what the reader needs to rebuild the
  run exactly in a Metadata record named ``prsm_health``, and the scenario (JSON) as an
  attachment (``application/json``).

Modules:

- :mod:`.schema` — topic and diagnosis JSON schemas, metadata names and value encoding;
- :mod:`.writer` — :func:`write_mcap` (and :func:`~.writer.sample_payloads`, the signal
  message payloads it writes); :mod:`.reader` — :func:`read_mcap`;
- :mod:`.replay` — :func:`iter_windows`, :class:`Window`, :func:`window_statistics`;
- :mod:`.diagnosis_topic` — :class:`DiagnosisWriter`, :func:`write_diagnosis_mcap` (and
  :func:`~.diagnosis_topic.diagnosis_payload`, the diagnosis message payload);
- private: ``_container`` (the fast hand-framed writer), ``_scan`` (the tolerant record
  scanner), ``_samples`` (log-time clock, topic batches, alignment), ``_framing`` (opcodes).

The tests read the files back with :mod:`mcap`'s own readers.
"""

from __future__ import annotations

from prsm_health.core.channels import (
    TOPIC_DIAGNOSIS,
    TOPIC_DRIVE,
    TOPIC_FIELDS,
    TOPIC_NUT_ACCEL,
    TOPIC_TRUTH,
)
from prsm_health.core.errors import TruncatedRecordingWarning

from ._container import DEFAULT_CHUNK_SIZE
from .diagnosis_topic import DiagnosisWriter, write_diagnosis_mcap
from .reader import read_mcap
from .replay import Window, WindowStream, iter_windows, window_statistics
from .writer import write_mcap

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "TOPIC_DIAGNOSIS",
    "TOPIC_DRIVE",
    "TOPIC_FIELDS",
    "TOPIC_NUT_ACCEL",
    "TOPIC_TRUTH",
    "DiagnosisWriter",
    "TruncatedRecordingWarning",
    "Window",
    "WindowStream",
    "iter_windows",
    "read_mcap",
    "window_statistics",
    "write_diagnosis_mcap",
    "write_mcap",
]
