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


def worker_count() -> int:
    return max(1, min(os.cpu_count() or 1, 4))


@contextlib.contextmanager
def fit_executor(workers: int | None = None) -> Iterator[Executor | None]:
    n = workers or worker_count()
    if n <= 1:
        yield None
        return
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["analysis.fit.least_squares", "analysis.diagnosis.candidates",
                                     "analysis.pool_preload"])
    with ProcessPoolExecutor(max_workers=n, mp_context=context) as pool:
        yield pool
