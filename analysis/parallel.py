"""Where refits run: a process pool on both cores when there is more than one.

Fits of a few hundred lines are short and hold the GIL (numpy on small
arrays), so threads do not help; processes do. The pool is started with
'forkserver' so that a GUI process with threads can use it safely.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
from concurrent.futures import Executor, ProcessPoolExecutor
from typing import Iterator

from analysis.worker_errors import call_sending_errors


# How much lower than its caller a background pool's workers run (os.nice). The GUI diagnoses on a pool
# as wide as the machine: at equal priority the workers took the cores from the GUI thread, which then
# waited up to ~50 ms for one though it needed ~20 ms of CPU. Lower, they still use every idle core.
BACKGROUND_NICENESS = 10


def worker_count() -> int:
    return max(1, min(os.cpu_count() or 1, 4))


def run_in_the_background() -> None:
    """A worker's initializer: lower than its caller (BACKGROUND_NICENESS)."""
    os.nice(BACKGROUND_NICENESS)


def pool_context() -> multiprocessing.context.BaseContext:
    """'forkserver', its server preloaded with what every fit builds first (analysis.pool_preload): one server,
    whoever starts a pool."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["analysis.pool_preload"])
    return context


class WorkerPool(ProcessPoolExecutor):
    """A process pool whose calls' exceptions always reach the caller (analysis.worker_errors): one that pickle
    could not rebuild had broken the whole pool."""

    def submit(self, fn, /, *args, **kwargs):
        return super().submit(call_sending_errors, fn, *args, **kwargs)


@contextlib.contextmanager
def fit_executor(workers: int | None = None, *, background: bool = False) -> Iterator[Executor | None]:
    """A pool of `workers` processes (None: worker_count()), or None for one. `background`: the workers run at
    a lower priority than the caller, so that a window stays responsive while they fit."""
    n = workers or worker_count()
    if n <= 1:
        yield None
        return
    with WorkerPool(max_workers=n, mp_context=pool_context(),
                    initializer=run_in_the_background if background else None) as pool:
        yield pool
