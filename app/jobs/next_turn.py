"""Work split over turns of the event loop, with what is due (timers, input) let in between.

A zero timer (QTimer.singleShot(0, ...)) is a posted event: the next step,
posted while the last one ran, is delivered in the next pass over the posted
events, often before the timers and the window system's input that fell due
meanwhile. Two 30 ms steps then hold the loop 60 ms, whatever the split. A
1 ms precise timer is a timer: the ones due earlier (a repaint, the user's
click, a stall meter's tick) run before it.

A step's cost does not end with it: a plot it changed is processed and painted
in events the step posted (its scene's), which run before any timer. Set at the
step's end, a 1 ms timer was often due before a timer that fell due during those
events (a late precise timer is due an interval after it last ran): a 3 ms step,
its 6 ms paint and the next 3 ms step held the loop as one. The timer is set once
the events posted so far have run (a zero timer first), so that what fell due
while the step and its paint ran comes first.
"""
from __future__ import annotations

from collections.abc import Iterator
from typing import Callable

from PySide6.QtCore import QObject, QTimer

LATER_MS = 1


def in_a_later_turn(context: QObject, step: Callable[[], None]) -> None:
    """Run `step` in a later turn of the event loop, after the events posted so far (the paint what ran just now
    set off) and the timers due by then; never once `context` is deleted."""
    QTimer.singleShot(0, context, lambda: QTimer.singleShot(LATER_MS, context, step))


_DONE = object()


def in_turns(context: QObject, steps: Iterator[None], going_on: Callable[[], bool] = lambda: True,
             then: Callable[[], None] = lambda: None) -> None:
    """Run `steps` (a generator, each step up to its next `yield`): the first now, each next in a later turn, while
    going_on() (a newer value took over: the steps left are dropped). `then()` once the steps end, however they
    end (done, dropped, or a step that raised: what waits for them is never lost)."""
    def step() -> None:
        try:
            more = going_on() and next(steps, _DONE) is not _DONE
        except Exception:
            then()          # Qt logs the error
            raise
        if more:
            in_a_later_turn(context, step)
        else:
            then()
    step()
