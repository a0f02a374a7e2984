"""The diagnosis's refits and screens, on the process pool when there is one, in an order that keeps it busy.

A round's work is a few dozen fits of very unequal length: most take tens of milliseconds, a candidate
the data refuse can crawl to its budget for ten times as long. Handed to the pool in the catalogue's
order, such a fit can start last and leave one worker idle while the other ends it. So each hand-over
is sorted, the costliest first, by what the same effect cost the round before (the caller's estimate).
And the screens of a narrow mode's start values, which its refit must wait for, are handed over first,
with the refits that need no screen behind them: the pool works on those while the screens' results
come back, instead of waiting for the last screen.

Without a pool the calls run one after the other when their outcome is asked for: the same calls with
the same arguments, so the same numbers.
"""
from __future__ import annotations

import itertools
import threading
from concurrent.futures import Executor
from typing import Callable, Iterator, Sequence

from analysis.fit.least_squares import FitError, FitResult

Outcome = tuple[FitResult | None, str | None]
_TURNS = itertools.count()   # the order calls were handed to a pool in (next() on a count is atomic in CPython)
# (function, its arguments, its estimated cost): only the order of the costs matters.
Call = tuple[Callable, tuple, float]


def outcome(call: Callable[[], FitResult], cancel: threading.Event | None = None) -> Outcome:
    """(result, None), or (None, why) when the fit failed (a cancelled fit's error goes on up)."""
    try:
        return call(), None
    except (FitError, ValueError, ArithmeticError) as exc:
        if cancel is not None and cancel.is_set():
            raise
        return None, str(exc)


class _Deferred:
    """A call run when its outcome is first asked for (no pool)."""

    def __init__(self, fn: Callable, args: tuple, cancel: threading.Event | None):
        self.fn, self.args, self.cancel = fn, args, cancel
        self.done: Outcome | None = None

    def outcome(self) -> Outcome:
        if self.done is None:
            self.done = outcome(lambda: self.fn(*self.args), self.cancel)
        return self.done


class _Submitted:
    """A call handed to the pool, the `turn`-th handed over (by this process)."""

    def __init__(self, future, turn: int):
        self.future, self.turn = future, turn

    def outcome(self) -> Outcome:
        return outcome(self.future.result)

    def ready(self) -> bool:
        done = getattr(self.future, "done", None)
        return done is not None and done()


def submit(calls: Sequence[Call], executor: Executor | None, cancel: threading.Event | None) -> list:
    """Handles of `calls`, in their order; each handle's outcome() waits for its result. On the pool the
    calls are handed over at once, the costliest first (ties in their order)."""
    if executor is None:
        return [_Deferred(fn, args, cancel) for fn, args, _ in calls]
    handles: list = [None] * len(calls)
    for index in sorted(range(len(calls)), key=lambda i: -calls[i][2]):
        fn, args, _ = calls[index]
        handles[index] = _Submitted(executor.submit(fn, *args), next(_TURNS))
    return handles


def as_ready(handles: Sequence) -> Iterator[int]:
    """The indices of `handles` (of one or more hand-overs), each once, about as their outcomes come back.

    On the pool: every handle already done, then the earliest handed over of the rest (the pool starts them
    in that order) once it is done, and so on; the caller can act on an outcome while the pool works on the
    others. Without a pool: in their order, each run when its index is taken (the calls of before, in their
    order, so the same numbers).
    """
    if not all(isinstance(h, _Submitted) for h in handles):
        yield from range(len(handles))
        return
    waiting = sorted(range(len(handles)), key=lambda i: handles[i].turn)
    while waiting:
        done = [i for i in waiting if handles[i].ready()] or waiting[:1]
        for i in done:
            waiting.remove(i)
            yield i


def run(calls, executor: Executor | None, cancel: threading.Event | None) -> list[Outcome]:
    """The outcomes of (function, arguments) calls, in order, on the pool when there is one."""
    return [handle.outcome() for handle in submit([(fn, args, 0.0) for fn, args in calls], executor, cancel)]
