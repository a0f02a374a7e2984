"""Work split over turns of the event loop, with what is due (timers, input) let in between.

A zero timer (QTimer.singleShot(0, ...)) is a posted event: the next step,
posted while the last one ran, is delivered in the next pass over the posted
events, often before the timers and the window system's input that fell due
meanwhile. Two 30 ms steps then hold the loop 60 ms, whatever the split. A
1 ms precise timer is a timer: the ones due earlier (a repaint, the user's
click, a stall meter's tick) run before it.
"""
from __future__ import annotations

from collections.abc import Iterator
from typing import Callable

from PySide6.QtCore import QObject, QTimer

LATER_MS = 1


def in_a_later_turn(context: QObject, step: Callable[[], None]) -> None:
    """Run `step` in a later turn of the event loop, after the timers already due; never once `context` is
    deleted."""
    QTimer.singleShot(LATER_MS, context, step)


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
