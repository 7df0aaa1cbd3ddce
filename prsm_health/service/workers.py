"""The worker pool: diagnoses run a bounded number at once — in threads of this process, or in
diagnosis processes that each load the model once — and a bounded number of requests are
admitted (the rest get ``503``)."""

from __future__ import annotations

import asyncio
import contextlib
import multiprocessing
import os
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import anyio

from .limits import ServiceLimits
from .responses import HTTPError

#: The model bundle of a diagnosis process, loaded once by :func:`_start_process`.
_process_bundle = None


def _start_process(bundle) -> None:
    """Initialiser of a diagnosis process: keep the model, walk the diagnosis once (JIT
    caches, compiled trees) so its first request does not pay for it."""
    from .diagnosing import warm_up

    # Ctrl-C reaches the whole process group: the server stops these processes itself
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    global _process_bundle
    _process_bundle = bundle
    warm_up(bundle)


def _in_process(fn, *args):
    return fn(_process_bundle, *args)


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

    async def diagnose(self, fn, *args):
        """``fn(bundle, *args)`` in a worker thread or a diagnosis process (with that
        process's model), waiting for a free worker."""
        async with self._limiter:
            if self._processes is None:
                return await anyio.to_thread.run_sync(fn, self._bundle, *args)
            try:
                return await asyncio.wrap_future(self._processes.submit(_in_process, fn, *args))
            except BrokenProcessPool:
                # a diagnosis process died (killed, out of memory): a new pool for the next
                # requests; this one is told to come back
                broken, self._processes = self._processes, self._new_pool()
                broken.shutdown(wait=False, cancel_futures=True)
                raise HTTPError(
                    503, "a diagnosis process stopped; retry in a few seconds", {"Retry-After": "2"}
                ) from None

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
