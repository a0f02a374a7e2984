"""The Model lab's refits on one worker process that lives as long as the lab.

A refit is 15-400 ms of numpy on arrays of a few hundred lines, and holds the GIL all along. In a thread of the
GUI process it took the GIL from the GUI thread in turns of sys.getswitchinterval() (5 ms): a paint that let
the GIL go waited for it, and a refit asked for by a checkbox stalled the window 58-83 ms on a quiet two-core
machine (`make bench gui`, "a refit in the Model lab", target 50 ms). On a process of its own the job's thread
only waits. The process is started when the lab is shown (start) or at its first refit, and kept (a pool per
refit, as a diagnosis has, paid its start each time), niced like a diagnosis's workers (analysis.parallel).

The worker cannot see a job's threading.Event. A counter shared with it says up to which refit the lab has
cancelled; the fit in the worker reads it at each of its checks, so a refit overtaken by a newer one stops
within one iteration and the newer one does not wait behind it. "Up to" holds because each refit takes its
number (ticket) in the GUI thread as its job is made, after the lab has cancelled the one it replaces: numbers
taken in the jobs' threads could come in either order, and cancelling the older refit then cancelled the newer.
"""
from __future__ import annotations

import concurrent.futures
import itertools
import logging
import threading
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.reduction import ForkingPickler

from analysis.diagnosis.refit import refit
from analysis.fit.least_squares import FitData, FitResult
from analysis.model.composed import Model
from analysis.parallel import WorkerPool, pool_context, run_in_the_background, worker_count
from app.jobs.background_pool import CANCEL_POLL_S, PoolCancelled

log = logging.getLogger(__name__)

_cancelled_up_to = None         # in the worker: the shared counter (RefitProcess._cancelled_up_to)


def _start_worker(cancelled_up_to) -> None:
    global _cancelled_up_to
    _cancelled_up_to = cancelled_up_to
    run_in_the_background()


class _CancelledFrom:
    """fit_model's cancel flag in the worker: set once the lab has cancelled refit `number` or a later one."""

    def __init__(self, number: int):
        self.number = number

    def is_set(self) -> bool:
        return _cancelled_up_to.value >= self.number


def _fit_in_worker(number: int, data: FitData, model: Model, current: FitResult) -> FitResult:
    return refit(data, model, current, cancel=_CancelledFrom(number))


def _travels(*objects) -> bool:
    """Whether `objects` (a model, the fit it is refitted from) can be sent to the worker (pickled as the pool sends
    its calls). A package's effect may be an object pickle cannot send (its class made inside the factory its entry
    point names, a lambda among its fields): that refit fits in the caller's thread, as all did before the worker,
    instead of failing as an internal error. 0.05 ms for lr3,creep-log."""
    try:
        ForkingPickler.dumps(objects)
    except Exception:  # noqa: BLE001 - whatever stops the pickler (PicklingError, TypeError, AttributeError ...)
        return False
    return True


class RefitProcess:
    """A lab's refit (analysis.diagnosis.refit) on the lab's worker process, the wait cancellable; in the caller's
    thread on a one-core machine."""

    def __init__(self) -> None:
        self._lock = threading.Lock()       # the lab's refits run one at a time, but a shutdown may come from the GUI
        self._pool: WorkerPool | None = None
        self._cancelled_up_to = None
        self._numbers = itertools.count(1)
        self._closed = False                # shut down: no process is started again (a refit then fits here)

    def start(self) -> None:
        """Have the process running before the first refit is asked for. In a thread of its own: a process pool
        forks its worker in the thread of its first call, which waits for the fork server (7-8 ms; 0.57 s when
        the server has yet to start and load what it preloads), and this is called from the GUI thread."""
        if self._pool is None and not self._closed:
            threading.Thread(target=self._fork_worker, name="refit process start", daemon=True).start()

    def _fork_worker(self) -> None:
        pool = self._running()
        if pool is not None:
            try:
                pool.submit(int)        # a process pool forks its worker at its first call
            except RuntimeError:        # shut down meanwhile ("cannot schedule new futures after shutdown")
                pass

    def ticket(self) -> int:
        """The next refit's number; taken where the refits are asked for, one after the other (the GUI thread)."""
        return next(self._numbers)

    def fit(self, number: int, data: FitData, model: Model, current: FitResult,
            cancel: threading.Event) -> FitResult:
        """Refit `number` (a ticket): `model` refitted from `current`, the version it changes; PoolCancelled once
        `cancel` is set."""
        if cancel.is_set():
            raise PoolCancelled("refit cancelled")
        pool = self._running()
        if pool is None or not _travels(model, current):
            return refit(data, model, current, cancel=cancel)
        try:
            try:
                future = pool.submit(_fit_in_worker, number, data, model, current)
            except RuntimeError:            # "cannot schedule new futures after shutdown": the lab closed meanwhile
                if not self._closed:
                    raise
                return refit(data, model, current, cancel=cancel)
            while True:
                try:
                    return future.result(timeout=CANCEL_POLL_S)
                except concurrent.futures.TimeoutError:
                    if cancel.is_set():
                        self._cancel(number)
                        raise PoolCancelled("refit cancelled") from None
        except BrokenProcessPool:
            # The worker died (killed, out of memory): the next refit starts another; this one fits here.
            log.warning("the Model lab's refit process ended unexpectedly; refitting in the window's process")
            self._drop(pool)
            return refit(data, model, current, cancel=cancel)

    def shutdown(self) -> None:
        """Stop the worker: a refit still running is cancelled at its next check; the caller does not wait."""
        with self._lock:
            pool, self._pool, self._closed = self._pool, None, True
            if pool is not None:
                self._cancelled_up_to.value = self.ticket()     # every refit so far
                pool.shutdown(wait=False, cancel_futures=True)

    def _running(self) -> WorkerPool | None:
        with self._lock:
            if self._pool is None and not self._closed and worker_count() > 1:
                context = pool_context()
                # Shared memory without a lock: only this side writes (under self._lock), the worker only reads
                # an aligned 8-byte integer. A lock would be a named semaphore, gone once this side drops it:
                # a worker still starting then failed to open it (a traceback on the terminal).
                self._cancelled_up_to = context.Value("q", 0, lock=False)
                self._pool = WorkerPool(max_workers=1, mp_context=context, initializer=_start_worker,
                                        initargs=(self._cancelled_up_to,))
            return self._pool

    def _cancel(self, number: int) -> None:
        with self._lock:
            if self._cancelled_up_to is not None:
                self._cancelled_up_to.value = max(self._cancelled_up_to.value, number)

    def _drop(self, pool: WorkerPool) -> None:
        with self._lock:
            if self._pool is pool:
                self._pool = None
        pool.shutdown(wait=False, cancel_futures=True)
