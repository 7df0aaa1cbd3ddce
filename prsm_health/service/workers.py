"""The worker pool: diagnoses run in threads, a bounded number at once, and a bounded number of
requests are admitted (the rest get ``503``)."""

from __future__ import annotations

import contextlib

import anyio

from .limits import ServiceLimits
from .responses import HTTPError


class WorkerPool:
    """At most ``limits.workers`` jobs in threads at once (:meth:`run`), and at most
    ``limits.max_pending`` diagnose requests admitted (:meth:`admitted`).

    Attributes
    ----------
    active : int
        Diagnose requests admitted now (receiving, waiting for a worker or running).
    """

    def __init__(self, limits: ServiceLimits):
        self.max_pending = limits.max_pending
        self.active = 0
        self._limiter = anyio.CapacityLimiter(limits.workers)

    async def run(self, fn, *args):
        """``fn(*args)`` in a worker thread, waiting for a free worker."""
        return await anyio.to_thread.run_sync(fn, *args, limiter=self._limiter)

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
