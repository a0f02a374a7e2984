"""The bookkeeping every Qt worker of the GUI shares: which jobs run, cancel them, wait for them.

A worker (a QObject of the GUI thread) owns a QThreadPool and hands it jobs:
plain callables with an `id` and a `cancel()` method. The worker's "done"
signals (finished, failed, cancelled: each carrying the job id) tell this
book to forget the job, so `cancel_all` and `shutdown` only touch the live ones.

`failure_text` is the GUI's one error boundary (analysis.errors): every job
hands whatever it raised to it and shows the line it returns. A user error
is its own message; anything else is a bug: "internal error while ...: ...
(details in FILE)", with a crash report written (app.crash_report).
"""
from __future__ import annotations

import itertools
import logging
from typing import Iterable

from PySide6.QtCore import QObject, QThreadPool, SignalInstance

from analysis.errors import is_user_error, user_message

log = logging.getLogger(__name__)


def failure_text(exc: BaseException, doing: str) -> str:
    """The one line the GUI shows for a job that raised `exc` while `doing` ("analysing x.wav")."""
    if is_user_error(exc):
        return user_message(exc)
    from app.crash_report import internal_error_line
    log.error("%s failed", doing, exc_info=exc)
    return internal_error_line(exc, doing)


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
