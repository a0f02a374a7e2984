"""A job's fits on worker processes below the window, the wait on them cancellable.

A fit holds the GIL nearly all its time (numpy on arrays of a few hundred lines). Run in a thread of the
GUI process it takes the GIL from the GUI thread in turns of sys.getswitchinterval() (5 ms), and every
Qt call of a paint that lets the GIL go waits that long to have it back: a paint of 10-18 ms of CPU took
35-110 ms while the model part's refits ran beside a diagnosis. On worker processes (analysis.parallel,
background=True: niced) the job's thread only waits; the GUI process holds the GIL for what it draws.

A worker process cannot see the job's cancel flag, so the wait on each result wakes up every
CANCEL_POLL_S to look at it: a cancelled job drops the calls not yet started and ends at once.
"""
from __future__ import annotations

import concurrent.futures
import contextlib
import threading
from typing import Iterator

from analysis.parallel import fit_executor

CANCEL_POLL_S = 0.1     # how often a job waiting on the pool looks at its cancel flag


class PoolCancelled(Exception):
    """Deliberately not a FitError: the diagnosis records those as failed candidates and goes on."""


class _PollingFuture:
    """A pool future whose result() wakes up to look at the cancel flag.

    rank_candidates waits on each refit with result() and no timeout, and an
    Event cannot be sent to the worker processes: without this a cancelled
    job would run every remaining refit to the end.
    """

    def __init__(self, future: concurrent.futures.Future, owner: "CancellableExecutor"):
        self._future = future
        self._owner = owner

    def result(self, timeout=None):
        while True:
            try:
                return self._future.result(timeout=CANCEL_POLL_S)
            except concurrent.futures.TimeoutError:
                self._owner.check()

    def done(self) -> bool:
        """Whether the result is back (analysis.diagnosis.jobs.as_ready takes those first)."""
        return self._future.done()


class CancellableExecutor:
    """`pool`'s submit, each result's wait ended by `cancel` (PoolCancelled)."""

    def __init__(self, pool: concurrent.futures.Executor, cancel: threading.Event):
        self._pool = pool
        self._cancel = cancel

    def check(self) -> None:
        if self._cancel.is_set():
            # Calls not yet started are dropped; the one or two running finish in well under a second.
            self._pool.shutdown(wait=False, cancel_futures=True)
            raise PoolCancelled("cancelled")

    def submit(self, fn, *args, **kwargs) -> _PollingFuture:
        self.check()
        return _PollingFuture(self._pool.submit(fn, *args, **kwargs), self)


@contextlib.contextmanager
def background_pool(cancel: threading.Event) -> Iterator[CancellableExecutor | None]:
    """Worker processes below the window for a job whose flag is `cancel` (None on a machine of one core:
    the job then fits in its own thread)."""
    with fit_executor(background=True) as pool:
        yield None if pool is None else CancellableExecutor(pool, cancel)
