"""Request bodies handed to diagnosis processes through shared memory
(:class:`prsm_health.apps.service.workers.SharedBodies`): reuse, replacement, removal, and a segment
kept until the diagnosis reading it is done, even when the awaiting request is cancelled.

The end-to-end path (spawned diagnosis processes, one killed) is in test_service.py."""

import asyncio
import threading
from concurrent.futures import ThreadPoolExecutor
from multiprocessing.shared_memory import SharedMemory

import pytest

from prsm_health.apps.service import ServiceLimits
from prsm_health.apps.service import workers as workers_module
from prsm_health.apps.service.workers import (
    SHARED_BODY_MIN_BYTES,
    SHARED_BODY_PREFIX,
    SharedBodies,
    SharedBody,
    WorkerPool,
)


def _exists(name: str) -> bool:
    try:
        segment = SharedMemory(name)
    except FileNotFoundError:
        return False
    segment.close()
    return True


def _read(handle: SharedBody) -> bytes:
    segment = SharedMemory(handle.name)
    try:
        return bytes(segment.buf[: handle.size])
    finally:
        segment.close()


@pytest.fixture
def attached():
    """Segments attached by ``_in_process`` in this process (a thread stands in for a
    diagnosis process) are closed afterwards."""
    yield workers_module._attached
    while workers_module._attached:
        workers_module._attached.popitem()[1].close()


def test_segments_are_reused_replaced_and_removed():
    bodies = SharedBodies(keep=1)
    first = b"a" * 100_000
    segment, handle = bodies.put(first)
    assert handle.name.startswith(SHARED_BODY_PREFIX) and handle.size == len(first)
    assert _read(handle) == first
    bodies.give_back(segment)
    assert bodies.names == [handle.name]
    # a body of about the same size: the same segment, its old bytes beyond the size unread
    second = b"b" * 90_000
    again, handle2 = bodies.put(second)
    assert handle2.name == handle.name and _read(handle2) == second
    bodies.give_back(again)
    # a larger body than the free segment holds: that segment is replaced (keep = 1)
    large = bytes(range(256)) * (3 * 2**20 // 256 + 1)
    bigger, handle3 = bodies.put(large)
    assert handle3.name != handle.name and _read(handle3) == large
    assert not _exists(handle.name) and bodies.names == [handle3.name]
    # a second request while the first holds its segment: a second segment; only `keep`
    # of them stay once both are given back
    other, handle4 = bodies.put(first)
    bodies.give_back(other)
    bodies.give_back(bigger)
    assert len(bodies.names) == 1
    bodies.give_back(bigger)  # twice: no effect
    names = [handle3.name, handle4.name]
    bodies.close()
    assert bodies.names == [] and not any(_exists(n) for n in names)
    with pytest.raises(RuntimeError):
        bodies.put(first)


def test_close_removes_segments_still_in_use():
    bodies = SharedBodies(keep=2)
    segment, handle = bodies.put(b"x" * 70_000)
    bodies.close()
    assert not _exists(handle.name)
    bodies.give_back(segment)  # the diagnosis ends after the pool closed: nothing left to do


def _wait_then_size(bundle, body, started, release):
    started.set()
    assert release.wait(60)
    return bundle, len(body), body[:3]


def test_segment_held_until_the_diagnosis_is_done_even_if_the_request_is_cancelled(attached):
    # a thread pool stands in for the diagnosis processes: the same submit path, the body
    # read back by _in_process in that thread
    pool = WorkerPool(ServiceLimits(workers=1), bundle=None)
    pool._processes = ThreadPoolExecutor(1)
    pool._bodies = SharedBodies(keep=1)
    body = b"abc" + bytes(SHARED_BODY_MIN_BYTES)
    started, release = threading.Event(), threading.Event()

    async def scenario():
        loop = asyncio.get_running_loop()
        task = asyncio.ensure_future(pool.diagnose(_wait_then_size, body, started, release))
        assert await loop.run_in_executor(None, started.wait, 60)
        (name,) = pool._bodies.names
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task
        # the diagnosis still runs: its segment is not free for another request
        assert pool._bodies._free == [] and len(pool._bodies._in_use) == 1
        release.set()
        for _ in range(6000):
            if pool._bodies._free:
                break
            await asyncio.sleep(0.01)
        assert pool._bodies.names == [name] and len(pool._bodies._free) == 1
        # the next request reuses it and gets its own body
        assert await pool.diagnose(_wait_then_size, body, threading.Event(), release) == (
            None,
            len(body),
            b"abc",
        )
        # small arguments are passed as they are
        assert await pool.diagnose(_wait_then_size, b"abc", threading.Event(), release) == (
            None,
            3,
            b"abc",
        )
        return name

    name = asyncio.run(scenario())
    pool._processes.shutdown(wait=True)
    pool._processes = None
    pool.close()
    attached.pop(name).close()
    assert not _exists(name)
