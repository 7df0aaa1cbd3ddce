"""The worker pool: diagnoses run a bounded number at once — in threads of this process, or in
diagnosis processes that each load the model once — and a bounded number of requests are
admitted (the rest get ``503``)."""

from __future__ import annotations

import asyncio
import contextlib
import multiprocessing
import os
import secrets
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from functools import partial
from multiprocessing.shared_memory import SharedMemory

import anyio

from .limits import ServiceLimits
from .responses import HTTPError

#: The model bundle of a diagnosis process, loaded once by :func:`_start_process`.
_process_bundle = None

#: Bodies at least this large [bytes] cross to a diagnosis process through shared memory.
SHARED_BODY_MIN_BYTES = 64 * 2**10

#: Name prefix of the shared memory segments (``/dev/shm/prsm-health-body-*`` on Linux).
SHARED_BODY_PREFIX = "prsm-health-body-"


def _start_process(bundle) -> None:
    """Initialiser of a diagnosis process: keep the model, walk the diagnosis once (JIT
    caches, compiled trees) so its first request does not pay for it."""
    from .diagnosing import warm_up

    # Ctrl-C reaches the whole process group: the server stops these processes itself
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    global _process_bundle
    _process_bundle = bundle
    warm_up(bundle)


@dataclass(frozen=True)
class SharedBody:
    """A request body placed in the shared memory segment ``name`` (its first ``size`` bytes):
    what is pickled to a diagnosis process instead of the body itself."""

    name: str
    size: int


#: Segments a diagnosis process has attached, by name (kept: the server reuses its segments).
_attached: dict[str, SharedMemory] = {}
_MAX_ATTACHED = 4


def _body_from(shared: SharedBody) -> bytes:
    """In a diagnosis process: the body's bytes, copied out of the segment."""
    segment = _attached.pop(shared.name, None)
    if segment is None:
        # attaching registers the name with the server's resource tracker again, a no-op
        segment = SharedMemory(shared.name)
    _attached[shared.name] = segment  # most recently used last
    while len(_attached) > _MAX_ATTACHED:  # the server replaced or removed the oldest
        _attached.pop(next(iter(_attached))).close()
    return bytes(segment.buf[: shared.size])


def _in_process(fn, *args):
    args = [_body_from(a) if isinstance(a, SharedBody) else a for a in args]
    return fn(_process_bundle, *args)


class SharedBodies:
    """Shared memory segments that carry request bodies to the diagnosis processes: copying
    a body into a segment and out of it costs less than pickling it through the pool's pipe
    (docs/service.md, Performance). Used on the event loop thread only.

    A segment serves one request at a time, from :meth:`put` until :meth:`give_back`, which
    comes when the diagnosis process is done with it (not when an awaiting request is
    cancelled). Up to ``keep`` free segments stay for reuse (their pages already mapped in
    the diagnosis processes); :meth:`close` removes every segment. Segments are created by
    this process only and registered with multiprocessing's resource tracker, which removes
    any left over if the server process dies without closing.
    """

    def __init__(self, keep: int):
        self.keep = keep
        self._free: list[SharedMemory] = []
        self._in_use: set[SharedMemory] = set()
        self._closed = False

    def put(self, body: bytes) -> tuple[SharedMemory, SharedBody]:
        """A segment holding ``body``, and the handle a diagnosis process reads it with."""
        if self._closed:
            raise RuntimeError("the worker pool is closed")
        size = len(body)
        fitting = [s for s in self._free if s.size >= size]
        if fitting:
            segment = min(fitting, key=lambda s: s.size)
            self._free.remove(segment)
        else:
            if self._free and len(self._free) + len(self._in_use) >= self.keep:
                _remove(self._free.pop(0))  # too small for this body: replaced
            # whole MiB, so that bodies of about the same size reuse the segment
            capacity = max(2**20, -(-size // 2**20) * 2**20)
            segment = SharedMemory(
                SHARED_BODY_PREFIX + secrets.token_hex(8), create=True, size=capacity
            )
        self._in_use.add(segment)
        try:
            segment.buf[:size] = body
        except BaseException:
            self.give_back(segment)
            raise
        return segment, SharedBody(segment.name, size)

    def give_back(self, segment: SharedMemory) -> None:
        if segment not in self._in_use:  # removed by close() already
            return
        self._in_use.discard(segment)
        if self._closed or len(self._free) >= self.keep:
            _remove(segment)
        else:
            self._free.append(segment)

    def close(self) -> None:
        """Remove every segment (call when no diagnosis process can read them any more)."""
        self._closed = True
        for segment in [*self._free, *self._in_use]:
            _remove(segment)
        self._free.clear()
        self._in_use.clear()

    @property
    def names(self) -> list[str]:
        """Names of the segments that exist now (free or in use)."""
        return [s.name for s in [*self._free, *self._in_use]]


def _remove(segment: SharedMemory) -> None:
    segment.close()
    with contextlib.suppress(FileNotFoundError):
        segment.unlink()


def _ready() -> int:
    # held a moment, so that one warm process cannot take every start-up probe alone
    time.sleep(0.1)
    return os.getpid()


class WorkerPool:
    """At most ``limits.workers`` diagnoses at once (:meth:`diagnose`), and at most
    ``limits.max_pending`` diagnose requests admitted (:meth:`admitted`).

    With ``limits.processes`` = 0 a diagnosis runs in a worker thread of this process. A
    diagnosis holds the GIL much of the time, so threads add little beyond one; with
    ``processes`` ≥ 1 it runs in one of that many diagnosis processes (spawned, each with its
    own copy of the model, loaded once), which use the cores in parallel (docs/service.md).

    Attributes
    ----------
    active : int
        Diagnose requests admitted now (receiving, waiting for a worker or running).
    """

    def __init__(self, limits: ServiceLimits, bundle):
        self.max_pending = limits.max_pending
        self.active = 0
        self._bundle = bundle
        self._n_processes = limits.processes
        self._processes = self._new_pool() if limits.processes else None
        self._bodies = SharedBodies(keep=limits.processes)
        self._limiter = anyio.CapacityLimiter(limits.processes or limits.workers)

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            self._n_processes,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_start_process,
            initargs=(self._bundle,),
        )

    def start(self) -> None:
        """Start every diagnosis process now (each loads and warms the model), not at the
        first requests; returns when all are ready. Nothing to do with threads."""
        if self._processes is not None:
            # probes submitted together start every process; rounds until each has answered
            # (its initialiser, hence its warm-up, done)
            seen: set[int] = set()
            for _ in range(600):
                probes = [self._processes.submit(_ready) for _ in range(self._n_processes)]
                seen |= {probe.result() for probe in probes}
                if len(seen) >= self._n_processes:
                    return

    def close(self) -> None:
        if self._processes is not None:
            self._processes.shutdown(wait=True, cancel_futures=True)
        self._bodies.close()

    async def diagnose(self, fn, *args):
        """``fn(bundle, *args)`` in a worker thread or a diagnosis process (with that
        process's model), waiting for a free worker. A large ``bytes`` argument (a request
        body) crosses to a diagnosis process through shared memory."""
        async with self._limiter:
            if self._processes is None:
                return await anyio.to_thread.run_sync(fn, self._bundle, *args)
            try:
                return await asyncio.wrap_future(self._submit(fn, args))
            except BrokenProcessPool:
                # a diagnosis process died (killed, out of memory): a new pool for the next
                # requests; this one is told to come back
                broken, self._processes = self._processes, self._new_pool()
                broken.shutdown(wait=False, cancel_futures=True)
                raise HTTPError(
                    503, "a diagnosis process stopped; retry in a few seconds", {"Retry-After": "2"}
                ) from None

    def _submit(self, fn, args):
        """The diagnosis process's future of ``fn(bundle, *args)``; large ``bytes`` arguments
        in shared memory segments, given back once the process is done with them (not when an
        awaiting request is cancelled: a diagnosis already running goes on reading)."""
        segments = []
        try:
            sent = list(args)
            for i, arg in enumerate(args):
                if isinstance(arg, bytes) and len(arg) >= SHARED_BODY_MIN_BYTES:
                    segment, sent[i] = self._bodies.put(arg)
                    segments.append(segment)
            future = self._processes.submit(_in_process, fn, *sent)
        except BaseException:
            for segment in segments:
                self._bodies.give_back(segment)
            raise
        if segments:
            future.add_done_callback(
                partial(_give_back_later, asyncio.get_running_loop(), self._bodies, segments)
            )
        return future

    @contextlib.contextmanager
    def admitted(self):
        """Count one diagnose request while the block runs; ``503`` when too many are."""
        # Runs on the event loop thread only: no lock needed around the counter.
        if self.active >= self.max_pending:
            raise HTTPError(
                503,
                f"busy: {self.max_pending} diagnoses in progress; retry in a few seconds",
                {"Retry-After": "2"},
            )
        self.active += 1
        try:
            yield
        finally:
            self.active -= 1


def _give_back_later(loop, bodies: SharedBodies, segments, _future) -> None:
    """Done callback of a diagnosis (a pool thread): the segments go back on the event loop."""
    for segment in segments:
        try:
            loop.call_soon_threadsafe(bodies.give_back, segment)
        except RuntimeError:  # the loop has closed (server stopped): no race with it left
            bodies.give_back(segment)
