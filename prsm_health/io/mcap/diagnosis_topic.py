"""Diagnosis output: a copy of a recording with diagnosis messages added on a topic
(:class:`DiagnosisWriter`, :func:`write_diagnosis_mcap`), so Foxglove shows the diagnosis
next to the signals it was made from.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from prsm_health.core.channels import TOPIC_DIAGNOSIS
from prsm_health.core.errors import PRSMHealthError, TruncatedRecordingWarning
from prsm_health.core.jsonable import dumps

from ._container import (
    _HEADER_SIZE,
    DEFAULT_CHUNK_SIZE,
    _AtomicFile,
    _FileWriter,
    _library,
    _MessageBlock,
)
from ._scan import _Source
from .schema import DIAGNOSIS_SCHEMA_NAME, diagnosis_schema, encode_schema

__all__ = ["DiagnosisWriter", "diagnosis_payload", "write_diagnosis_mcap"]


def diagnosis_payload(diagnosis: dict) -> bytes:
    """Payload of one diagnosis message: compact JSON (numpy values allowed; NaN/inf as null).

    Used by :class:`DiagnosisWriter` and by the live view (:mod:`prsm_health.apps.live`).

    Raises
    ------
    PRSMHealthError
        ``diagnosis`` is not JSON-serialisable.
    """
    try:
        return dumps(diagnosis, compact=True).encode()
    except TypeError as exc:
        raise PRSMHealthError(f"diagnosis is not JSON-serialisable: {exc}") from None


class DiagnosisWriter:
    """Copy a recording and add diagnosis messages to it, one at a time.

    The source's schemas, channels, metadata, attachments and chunks are copied unchanged
    (chunks without recompression); each :meth:`add` appends one JSON message on ``topic``
    (on the source's channel of that topic if it has one, else on a new channel). The
    destination is written atomically on :meth:`close` (a context manager closes it; an
    exception inside the ``with`` block discards it).

    Parameters
    ----------
    src, dst : str or path-like
        Source recording and destination (may be the same path).
    topic : str
        Diagnosis topic.
    schema : dict, optional
        JSON schema of the diagnosis messages; default inferred from the first message
        (nested objects allowed, clearance fields documented in m).
    chunk_size : int [bytes]
        Uncompressed size of the diagnosis chunks.

    Warns
    -----
    TruncatedRecordingWarning
        The source is damaged; what precedes the damage is copied.
    """

    def __init__(
        self,
        src: str | os.PathLike,
        dst: str | os.PathLike,
        *,
        topic: str = TOPIC_DIAGNOSIS,
        schema: dict | None = None,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
    ):
        self.topic = topic
        self._schema = schema
        self._channel_id: int | None = None
        self._pending: list[tuple[int, bytes]] = []
        self._pending_bytes = 0
        self._chunk_size = int(chunk_size)
        self._sequence = 0
        self._closed = False
        self._target = _AtomicFile(Path(dst))
        try:
            self._writer = _FileWriter(self._target.stream, chunk_size=chunk_size)
            self._writer.start(_library())
            self._copy(src)
        except BaseException:
            self._target.abort()
            raise

    def _copy(self, src) -> None:
        writer = self._writer
        with _Source(src, topics=()) as source:
            loose = []
            done = set()
            for kind, *rest in source.scan(index_only=True):
                self._sync_definitions(source, done)
                if kind == "chunk":
                    chunk, walked = rest
                    if walked:
                        writer.copy_chunk(chunk, walked)
                elif kind == "message":
                    loose.append(rest[0])
                elif kind == "metadata":
                    writer.add_metadata(rest[0].name, rest[0].metadata)
                elif kind == "attachment":
                    a = rest[0]
                    writer.add_attachment(
                        a.name, a.media_type, a.data, log_time=a.log_time, create_time=a.create_time
                    )
            self._sync_definitions(source, done)
            if loose:
                writer.add_messages(
                    _MessageBlock.from_payloads(
                        [m.channel_id for m in loose],
                        [m.sequence for m in loose],
                        [m.log_time for m in loose],
                        [m.publish_time for m in loose],
                        [m.data for m in loose],
                    )
                )
            if source.damage:
                warnings.warn(
                    f"{source.path}: {source.damage}; copied what precedes it",
                    TruncatedRecordingWarning,
                    stacklevel=3,
                )

    def _sync_definitions(self, source: _Source, done: set) -> None:
        for sid, schema in source.schemas.items():
            if ("s", sid) not in done:
                self._writer.add_schema(schema.name, schema.encoding, schema.data, schema_id=sid)
                done.add(("s", sid))
        for cid, channel in source.channels.items():
            if ("c", cid) not in done:
                self._writer.add_channel(
                    channel.topic,
                    channel.message_encoding,
                    channel.schema_id,
                    channel.metadata,
                    channel_id=cid,
                )
                done.add(("c", cid))

    def _register(self, example: dict | None) -> None:
        for channel in self._writer.channels.values():
            if channel.topic == self.topic and channel.message_encoding == "json":
                # Diagnosing a diagnosed file again: one channel per topic, as Foxglove expects.
                self._channel_id = channel.id
                return
        schema = self._schema if self._schema is not None else diagnosis_schema(example)
        schema_id = self._writer.add_schema(
            DIAGNOSIS_SCHEMA_NAME, "jsonschema", encode_schema(schema)
        )
        self._channel_id = self._writer.add_channel(self.topic, "json", schema_id)

    def add(self, log_time_ns: int, diagnosis: dict) -> None:
        """Append one diagnosis message.

        Parameters
        ----------
        log_time_ns : int [ns]
            Log time of the message (e.g. the end of the diagnosed window, ``Window.end_ns``).
        diagnosis : dict
            JSON-serialisable (numpy values allowed; NaN/inf are written as null).
        """
        if self._closed:
            raise PRSMHealthError("DiagnosisWriter is closed")
        if not isinstance(log_time_ns, (int, np.integer)) or not 0 <= log_time_ns < 2**64:
            raise PRSMHealthError(f"log_time_ns = {log_time_ns!r} must be an integer >= 0 [ns]")
        if not isinstance(diagnosis, dict):
            raise PRSMHealthError(f"diagnosis must be a dict, not {type(diagnosis).__name__}")
        if self._channel_id is None:
            self._register(diagnosis)
        payload = diagnosis_payload(diagnosis)
        self._pending.append((int(log_time_ns), payload))
        self._pending_bytes += len(payload) + _HEADER_SIZE
        if self._pending_bytes >= self._chunk_size:
            self._flush()

    def _flush(self) -> None:
        if not self._pending:
            return
        n = len(self._pending)
        log_time = [t for t, _ in self._pending]
        self._writer.add_messages(
            _MessageBlock.from_payloads(
                np.full(n, self._channel_id),
                np.arange(self._sequence, self._sequence + n),
                log_time,
                log_time,
                [p for _, p in self._pending],
            )
        )
        self._sequence += n
        self._pending = []
        self._pending_bytes = 0

    def close(self) -> Path:
        """Finish the file and move it onto ``dst``."""
        if self._closed:
            return self._target.path
        try:
            if self._channel_id is None:
                self._register(None)
            self._flush()
            self._writer.finish()
        except BaseException:
            self._target.abort()
            raise
        finally:
            self._closed = True
        return self._target.commit()

    def abort(self) -> None:
        """Discard the output."""
        if not self._closed:
            self._closed = True
            self._target.abort()

    def __enter__(self) -> DiagnosisWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def write_diagnosis_mcap(
    src: str | os.PathLike,
    dst: str | os.PathLike,
    diagnoses: Iterable[tuple[int, dict]],
    *,
    topic: str = TOPIC_DIAGNOSIS,
    schema: dict | None = None,
) -> Path:
    """Copy ``src`` to ``dst`` with diagnosis messages added on ``topic``.

    Parameters
    ----------
    src, dst : str or path-like
    diagnoses : iterable of (int [ns], dict)
        Log time and diagnosis (e.g. the Diagnosis contract dict) of each message.
    topic : str
    schema : dict, optional
        See :class:`DiagnosisWriter`.

    Returns
    -------
    Path
        ``dst``.
    """
    with DiagnosisWriter(src, dst, topic=topic, schema=schema) as writer:
        for log_time_ns, diagnosis in diagnoses:
            writer.add(log_time_ns, diagnosis)
    return writer._target.path
