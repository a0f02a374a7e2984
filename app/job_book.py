"""The bookkeeping every Qt worker of the GUI shares: which jobs run, cancel them, wait for them.

A worker (a QObject of the GUI thread) owns a QThreadPool and hands it jobs:
plain callables with an `id` and a `cancel()` method. The worker's "done"
signals (finished, failed, cancelled: each carrying the job id) tell this
book to forget the job, so `cancel_all` and `shutdown` only touch the live ones.
"""
from __future__ import annotations

import itertools
from typing import Iterable

from PySide6.QtCore import QObject, QThreadPool, SignalInstance


class JobBook:
    """Mixin for the GUI's workers; call `_init_jobs` from the worker's __init__."""

    def _init_jobs(self, owner: QObject, done_signals: Iterable[SignalInstance], max_threads: int | None = None):
        self.pool = QThreadPool(owner)
        if max_threads is not None:
            self.pool.setMaxThreadCount(max_threads)
        self._ids = itertools.count(1)
        self._jobs: dict[int, object] = {}
        for signal in done_signals:
            signal.connect(self._forget)

    def _next_id(self) -> int:
        return next(self._ids)

    def _start(self, job):
        self._jobs[job.id] = job
        self.pool.start(job)
        return job

    def cancel_all(self) -> None:
        for job in list(self._jobs.values()):
            job.cancel()

    def shutdown(self, wait_ms: int) -> bool:
        """Cancel every job and wait for the pool; True when all stopped in time."""
        self.cancel_all()
        return self.pool.waitForDone(wait_ms)

    def _forget(self, job: int, *_args) -> None:
        self._jobs.pop(job, None)
