"""Live view: a recording played in real time to Foxglove over its WebSocket protocol.

:class:`LivePlayer` starts a Foxglove WebSocket server (the official ``foxglove-sdk``), advertises
the recording's topics with the MCAP contract's schemas (:mod:`prsm_health.io.mcap.schema`: same
topics, schema names, JSON schemas and field names as a ``.mcap`` file) and publishes one JSON
message per sample and topic — every ``decimate``-th sample — paced so that the recording's log
time advances ``rate`` times as fast as the wall clock. The diagnosis of each window (by a
model bundle, :func:`window_diagnoser`, or any ``diagnose`` function the caller gives) is
published on :data:`~prsm_health.core.channels.TOPIC_DIAGNOSIS` once the window has been played, at
``log_time`` = the window's end, with the payload and schema of the MCAP replay writer
(:func:`~prsm_health.io.mcap.diagnosis_topic.diagnosis_payload`,
:func:`~prsm_health.io.mcap.schema.diagnosis_schema`).

Messages carry the recording's own time base (``log_time`` = run start + sample time, in ns,
as in the MCAP file), not the wall clock. The live stream is a view: the MCAP contract (one
message per sample) is unchanged; decimation only thins what is sent to the viewer (no
anti-alias filter: a decimated acceleration shows the waveform's envelope, not its spectrum).

The Foxglove WebSocket protocol has no authentication: the server binds 127.0.0.1 unless told
otherwise. See docs/live.md.
"""

from __future__ import annotations

import math
import os
import queue
import threading
import time as _time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from itertools import chain
from pathlib import Path

import foxglove
import numpy as np
from foxglove.websocket import ServerListener

from prsm_health.core.channels import TOPIC_DIAGNOSIS, TOPIC_FIELDS, TOPIC_TRUTH
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run, window_span
from prsm_health.io.mcap.diagnosis_topic import diagnosis_payload
from prsm_health.io.mcap.replay import Window, iter_windows, window_origin_ns, window_reached_ns
from prsm_health.io.mcap.schema import (
    DIAGNOSIS_SCHEMA_NAME,
    SCHEMA_NAMES,
    diagnosis_schema,
    encode_schema,
    topic_schema,
)
from prsm_health.io.mcap.writer import sample_payloads

__all__ = [
    "DEFAULT_HOST",
    "DEFAULT_PORT",
    "MESSAGE_BUDGET",
    "LivePlayer",
    "LiveStats",
    "play_live",
    "window_diagnoser",
]

#: Bind address: this machine only (the protocol has no authentication).
DEFAULT_HOST = "127.0.0.1"
#: Foxglove's default WebSocket port.
DEFAULT_PORT = 8765
#: Messages per second the default decimation aims at (all topics together): a third of the
#: 60 000 messages/s (20 kHz × 3 topics, real time) that the SDK delivered without loss to one
#: local client on the reference machine, leaving CPU to the Foxglove app (docs/live.md →
#: Decimation). A 20 kHz recording is sent every 2nd sample (measured topics) or every 3rd
#: (with the truth topic).
MESSAGE_BUDGET = 20_000
#: Pacing granularity [s]: samples due are published in bursts at most this far apart.
TICK = 0.01
#: Wait after the first subscription before playing [s], so that the rest of the client's
#: subscriptions (one per panel topic) are in place for the first sample.
SETTLE = 0.25
# Bounds of the per-client message backlog of the server (the SDK drops a client's oldest
# data message when its backlog is full): two seconds of messages at real-time pacing, the
# upper bound (262 144 messages, up to about 100 MB of JSON) when playing as fast as possible.
_BACKLOG_MIN, _BACKLOG_MAX = 1024, 1 << 18

#: A window's diagnosis as the Diagnosis contract's per-window JSON object (``to_json()``).
Diagnose = Callable[[Window], dict]


def window_diagnoser(bundle) -> Diagnose:
    """Window → its Diagnosis JSON object by a model ``bundle``
    (:func:`~prsm_health.diagnostics.diagnosis.load_bundle`): the window's measured channels
    diagnosed as a run (:func:`~prsm_health.diagnostics.diagnosis.diagnose_window`), the object
    ``replay --out`` writes on ``/prsm/diagnosis`` (the contract's JSON and what a plot may
    draw of it, :func:`~prsm_health.diagnostics.not_observable.diagnosis_message`). Truth
    signals are never an input."""
    # Imported here: playing without a model does not load the estimators.
    from prsm_health.diagnostics.diagnosis import diagnose_window
    from prsm_health.diagnostics.not_observable import diagnosis_message

    def diagnose(w: Window) -> dict:
        return diagnosis_message(
            diagnose_window(
                Run(w.time, w.channels, w.sample_rate, w.labels, operating=w.operating), bundle
            ).to_json()
        )

    return diagnose


@dataclass
class LiveStats:
    """What a :meth:`LivePlayer.play` published.

    Attributes
    ----------
    samples : int
        Samples played (all of them, before decimation).
    published : int
        Samples published per topic (every ``decimate``-th).
    windows : int
        Windows played; ``diagnoses`` of them were diagnosed and published (complete windows,
        when a ``diagnose`` function was given).
    diagnoses : int
    log_span : float [s]
        Log time from the first to the last sample played.
    wall_time : float [s]
        Wall time the play took.
    """

    samples: int = 0
    published: int = 0
    windows: int = 0
    diagnoses: int = 0
    log_span: float = 0.0
    wall_time: float = 0.0


class _Listener(ServerListener):
    """Server listener: notes the first subscription (the other callbacks do nothing)."""

    def __init__(self) -> None:
        self.subscribed = threading.Event()

    def on_subscribe(self, client, channel) -> None:
        self.subscribed.set()


class _DiagnosisWorker:
    """One daemon thread diagnosing played windows in order, publishing each result, so the
    pacing does not wait for the estimators. A daemon: Ctrl-C never waits for it."""

    def __init__(self, diagnose: Diagnose, publish: Callable[[int, dict], None]):
        self._diagnose = diagnose
        self._publish = publish
        self._queue: queue.Queue = queue.Queue()
        self.error: BaseException | None = None
        self.done = 0
        self._thread = threading.Thread(target=self._run, name="prsm-live-diagnosis", daemon=True)
        self._thread.start()

    def submit(self, window: Window) -> None:
        self._queue.put(window)

    def _run(self) -> None:
        while True:
            window = self._queue.get()
            try:
                if window is None or self.error is not None:
                    return
                self._publish(window.end_ns, self._diagnose(window))
                self.done += 1
            except BaseException as exc:  # reported by check() in the playing thread
                self.error = exc
            finally:
                self._queue.task_done()

    def check(self) -> None:
        if self.error is not None:
            raise self.error

    def finish(self) -> None:
        """Wait until every submitted window is diagnosed and published (interruptible)."""
        self._queue.put(None)
        while self._thread.is_alive():
            self._thread.join(0.1)
        self.check()


def _run_windows(run: Run, window: float) -> Iterator[Window]:
    """A run cut into windows exactly as :func:`~prsm_health.io.mcap.replay.iter_windows` cuts
    its MCAP recording, by the same log-time rules (run start = log time 0): window ``k`` is
    ``window_span(k, window, origin=window_origin_ns(0, first sample))``, the last one
    possibly incomplete."""
    log = np.round(np.asarray(run.time, dtype=np.float64) * 1e9).astype(np.int64)
    n = len(log)
    if n == 0:
        raise PRSMHealthError("the run has no samples")
    length = int(round(window * 1e9))
    first = window_origin_ns(0, log[0])
    a, k = 0, 0
    while a < n:
        start, end = window_span(k, length, origin=first)
        b = int(np.searchsorted(log, end))
        if b > a:
            yield Window(
                index=k,
                start=start / 1e9,
                end=end / 1e9,
                start_ns=start,
                end_ns=end,
                time=run.time[a:b],
                channels={name: v[a:b] for name, v in run.channels.items()},
                labels=run.labels,
                operating=run.operating,
                sample_rate=float(run.sample_rate),
                truth={name: v[a:b] for name, v in run.truth.items()},
            )
        a, k = b, k + 1


def _log_times(window: Window) -> np.ndarray:
    """Log times [ns] of a window's samples (run start + sample time, as in the file)."""
    origin = window.start_ns - int(round(window.start * 1e9))
    return origin + np.round(np.asarray(window.time, dtype=np.float64) * 1e9).astype(np.int64)


def _complete(window: Window, log: np.ndarray) -> bool:
    """The window reaches its end (its last sample is at most one sample period before it) —
    the rule by which the MCAP replay releases a window (:func:`window_reached_ns`)."""
    if not len(log):
        return False
    return int(log[-1]) >= window_reached_ns(window.end_ns, window.sample_rate)


def _topics(window: Window) -> dict[str, list[tuple[str, str]]]:
    """Signal topics of a window and their (field, name) pairs, in contract order: those of the
    channels (and truth signals) it has, as the MCAP writer declares them."""
    out = {}
    for topic, pairs in TOPIC_FIELDS.items():
        source = window.truth if topic == TOPIC_TRUTH else window.channels
        present = [(f, name) for f, name in pairs if name in source]
        if present:
            out[topic] = present
    return out


def _url(host: str, port: int) -> str:
    return f"ws://[{host}]:{port}" if ":" in host else f"ws://{host}:{port}"


class LivePlayer:
    """A recording (an MCAP file or a :class:`Run`) played live to Foxglove.

    Construction opens the recording, reads its first window (and diagnoses it, which also
    gives the diagnosis topic its schema), starts the WebSocket server and advertises the
    topics; :meth:`wait_for_client` waits for a viewer, :meth:`play` plays the recording,
    :meth:`close` (or leaving the ``with`` block) stops the server.

    Parameters
    ----------
    source : str, path-like or Run
        MCAP recording (streamed window by window, never held whole) or a run in memory.
    window : float [s]
        Window length (the diagnosis model's window; also the unit in which the file is read).
    diagnose : callable, optional
        Window → the per-window Diagnosis JSON object; called for every complete window in a
        background thread, its result published on ``/prsm/diagnosis`` at the window's end.
        None: no diagnosis topic (unless ``bundle``).
    bundle : ModelBundle, optional
        Diagnose by this model (:func:`window_diagnoser`): what ``replay --out`` writes on
        ``/prsm/diagnosis``. Not with ``diagnose``.
    host : str
        Bind address (default 127.0.0.1: this machine only).
    port : int
        TCP port (0: any free port; :attr:`port` tells which).
    rate : float or None
        Real-time factor (1: real time); None: as fast as possible (a client whose backlog
        fills loses the oldest messages).
    decimate : int or None
        Publish every ``decimate``-th sample (1: all); None: the smallest that keeps the
        messages of all topics at or under :data:`MESSAGE_BUDGET` per second of wall time.
    name : str, optional
        Server name shown by Foxglove.

    Raises
    ------
    PRSMHealthError
        A recording that cannot be read, bad parameters (``diagnose`` and ``bundle`` both), a
        port that cannot be bound, or an error of the diagnosis on the first window.
    """

    def __init__(
        self,
        source: str | os.PathLike | Run,
        *,
        window: float = 1.0,
        diagnose: Diagnose | None = None,
        bundle=None,
        host: str = DEFAULT_HOST,
        port: int = DEFAULT_PORT,
        rate: float | None = 1.0,
        decimate: int | None = None,
        name: str | None = None,
    ):
        if not (isinstance(window, (int, float)) and 0 < window < math.inf):
            raise PRSMHealthError(f"window = {window!r} must be a finite number > 0 [s]")
        if rate is not None and not (isinstance(rate, (int, float)) and 0 < rate < math.inf):
            raise PRSMHealthError(f"rate = {rate!r} must be a finite number > 0, or None")
        if decimate is not None and (
            isinstance(decimate, bool)
            or not isinstance(decimate, (int, np.integer))
            or decimate < 1
        ):
            raise PRSMHealthError(f"decimate = {decimate!r} must be an integer >= 1, or None")
        if not isinstance(port, (int, np.integer)) or not 0 <= port <= 65535:
            raise PRSMHealthError(f"port = {port!r} must be an integer in 0…65535")
        if bundle is not None:
            if diagnose is not None:
                raise PRSMHealthError("give LivePlayer a diagnose function or a bundle, not both")
            diagnose = window_diagnoser(bundle)
        self.rate = rate
        self._server = None
        self._diagnose = diagnose
        if isinstance(source, Run):
            self._windows: Iterator[Window] = _run_windows(source, window)
            label = "run"
        else:
            self._windows = iter_windows(source, window, partial=True)
            label = Path(source).name
        self._stream = self._windows
        try:
            first = next(self._windows)
        except StopIteration:
            raise PRSMHealthError("the recording has no samples") from None
        except BaseException:
            self._close_stream()
            raise
        self._first = first
        #: Signal topics advertised and their (field, channel or truth name) pairs.
        self.topics = _topics(first)
        self._first_diagnosis = None
        if diagnose is not None and _complete(first, _log_times(first)):
            try:
                self._first_diagnosis = diagnose(first)
            except BaseException:
                self._close_stream()
                raise
        self._played = False
        full = len(self.topics) * first.sample_rate * (rate or 1.0)  # messages/s undecimated
        #: Every how many samples one is published.
        self.decimate = int(decimate) if decimate else max(1, math.ceil(full / MESSAGE_BUDGET))
        if rate is None:  # bursts: as much backlog as allowed
            backlog = _BACKLOG_MAX
        else:
            backlog = int(min(max(2 * full / self.decimate, _BACKLOG_MIN), _BACKLOG_MAX))
        self._start_server(host, int(port), name or f"prsm-health live: {label}", backlog)

    # ------------------------------------------------------------------ server
    def _start_server(self, host: str, port: int, name: str, backlog: int) -> None:
        self._context = foxglove.Context()
        self._listener = _Listener()
        try:
            self._server = foxglove.start_server(
                name=name,
                host=host,
                port=port,
                context=self._context,
                server_listener=self._listener,
                message_backlog_size=backlog,
            )
        except (RuntimeError, OverflowError, ValueError) as exc:
            self._close_stream()
            reason = str(exc).removeprefix("FoxgloveError: ")
            raise PRSMHealthError(
                f"cannot start the Foxglove WebSocket server on {host}:{port}: {reason}"
            ) from None
        self.host = host
        #: The port the server listens on.
        self.port = int(self._server.port)
        self._channels = {}
        for topic, pairs in self.topics.items():
            schema = encode_schema(topic_schema(topic, pairs))
            self._channels[topic] = self._channel(topic, SCHEMA_NAMES[topic], schema)
        if self._first_diagnosis is not None:
            schema = encode_schema(diagnosis_schema(self._first_diagnosis))
            self._channels[TOPIC_DIAGNOSIS] = self._channel(
                TOPIC_DIAGNOSIS, DIAGNOSIS_SCHEMA_NAME, schema
            )

    def _channel(self, topic: str, schema_name: str, schema: bytes):
        return foxglove.Channel(
            topic,
            schema=foxglove.Schema(name=schema_name, encoding="jsonschema", data=schema),
            message_encoding="json",
            context=self._context,
        )

    @property
    def url(self) -> str:
        """``ws://host:port`` to open in Foxglove (Open connection → Foxglove WebSocket)."""
        return _url(self.host, self.port)

    @property
    def diagnosing(self) -> bool:
        """Whether diagnoses are published: a ``diagnose`` function was given and the first
        window is complete (a recording shorter than one window gets none)."""
        return TOPIC_DIAGNOSIS in self._channels

    @property
    def sample_rate(self) -> float:
        """Sample rate of the recording [Hz]."""
        return self._first.sample_rate

    def wait_for_client(self, timeout: float | None = None) -> bool:
        """Block until a client subscribes to a topic (then :data:`SETTLE` s more, for its other
        subscriptions); False when ``timeout`` [s] passes first. Ctrl-C interrupts it."""
        deadline = None if timeout is None else _time.monotonic() + timeout
        while not self._listener.subscribed.wait(0.1):
            if deadline is not None and _time.monotonic() >= deadline:
                return False
        _time.sleep(SETTLE)
        return True

    # ------------------------------------------------------------------ playing
    def _publish_diagnosis(self, log_time_ns: int, diagnosis: dict) -> None:
        self._channels[TOPIC_DIAGNOSIS].base.log(diagnosis_payload(diagnosis), int(log_time_ns))

    def play(self) -> LiveStats:
        """Play the recording once, paced at :attr:`rate`; returns when every sample and every
        diagnosis has been published. Ctrl-C interrupts it (KeyboardInterrupt)."""
        if self._played:
            raise PRSMHealthError("this recording has already been played")
        self._played = True
        stats = LiveStats()
        worker = None
        if self._diagnose is not None and TOPIC_DIAGNOSIS in self._channels:
            worker = _DiagnosisWorker(self._diagnose, self._publish_diagnosis)
        t0: int | None = None
        last = 0
        wall0 = _time.monotonic()
        try:
            for window in chain([self._first], self._windows):
                log = _log_times(window)
                if not len(log):
                    continue
                if t0 is None:
                    t0 = int(log[0])
                keep = (stats.samples + np.arange(len(log))) % self.decimate == 0
                stats.samples += len(log)
                stats.windows += 1
                last = int(log[-1])
                self._play_samples(window, log, np.flatnonzero(keep), t0, wall0)
                stats.published += int(keep.sum())
                if self._diagnose is not None and TOPIC_DIAGNOSIS in self._channels:
                    if _complete(window, log):
                        if window is self._first:
                            self._publish_diagnosis(window.end_ns, self._first_diagnosis)
                            stats.diagnoses += 1
                        else:
                            worker.submit(window)
                    worker.check()
            if worker is not None:
                worker.finish()
                stats.diagnoses += worker.done
        finally:
            self._close_stream()
        stats.log_span = (last - t0) / 1e9 if t0 is not None else 0.0
        stats.wall_time = _time.monotonic() - wall0
        return stats

    def _play_samples(self, window: Window, log, idx, t0: int, wall0: float) -> None:
        """Publish the selected samples ``idx`` of a window, interleaved sample by sample like
        the MCAP writer, each when its log time is due."""
        columns = {}
        for topic, pairs in self.topics.items():
            source = window.truth if topic == TOPIC_TRUTH else window.channels
            if all(n in source for _, n in pairs):  # a topic that stopped: nothing to send
                columns[topic] = ([f for f, _ in pairs], [np.asarray(source[n]) for _, n in pairs])
        times = log[idx]
        i, n = 0, len(idx)
        while i < n:
            if self.rate is None:
                j = min(n, i + 4096)
            else:
                due = t0 + (_time.monotonic() - wall0) * self.rate * 1e9
                j = int(np.searchsorted(times, due, side="right"))
                if j <= i:
                    wait = (int(times[i]) - t0) / 1e9 / self.rate - (_time.monotonic() - wall0)
                    _time.sleep(max(wait, TICK))
                    continue
            rows = idx[i:j]
            senders = []
            for topic, (fields, values) in columns.items():
                channel = self._channels[topic].base
                if channel.has_sinks():  # nobody subscribed: nothing to format
                    senders.append(
                        (channel.log, sample_payloads(fields, [v[rows] for v in values]))
                    )
            for k, t in enumerate(times[i:j].tolist()):
                for log_message, payloads in senders:
                    log_message(payloads[k], t)
            i = j

    # ------------------------------------------------------------------ closing
    def hold(self) -> None:
        """Keep the server up (the viewer keeps its connection) until Ctrl-C
        (KeyboardInterrupt)."""
        while True:
            _time.sleep(1.0)

    def _close_stream(self) -> None:
        close = getattr(self._stream, "close", None)
        if close is not None:
            close()

    def close(self) -> None:
        """Stop the server and release the recording."""
        self._close_stream()
        if self._server is not None:
            self._server.stop()
            self._server = None
            for channel in self._channels.values():
                channel.close()

    def __enter__(self) -> LivePlayer:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()


def play_live(source, *, wait: bool = True, timeout: float | None = None, **options) -> LiveStats:
    """Play ``source`` live once and stop the server: :class:`LivePlayer` (``options`` are its
    parameters), waiting for a client first when ``wait`` (at most ``timeout`` s)."""
    with LivePlayer(source, **options) as player:
        if wait and not player.wait_for_client(timeout):
            raise PRSMHealthError(f"no Foxglove client subscribed to {player.url} in {timeout} s")
        return player.play()
