"""One value handed to several slow receivers, each in its own turn of the event loop."""
from __future__ import annotations

from collections.abc import Iterator
from typing import Callable

from PySide6.QtCore import QObject

from app.jobs.next_turn import in_a_later_turn

_DONE = object()


class StagedFanOut(QObject):
    """Calls each receiver with the value in a later turn of the event loop than the one before.

    A new result reaches the Results page, the Model lab and the QA view. One
    after the other in a single turn they held the GUI thread for 60-80 ms (the
    lab alone takes 30 ms to set up its plots); one per turn, the event loop
    runs, and the pages paint, in between (app/jobs/next_turn.py: not with zero
    timers, which let two receivers run back to back before anything due). `then` callbacks run after the last
    receiver, so "shown" signals still mean every page has the value.

    A value sent while an earlier one is still on its way replaces it: the
    receivers left get the newer one, and the receivers already served get it
    too, in the new round.

    A receiver that is a generator function fills in steps: each step (up to
    its next `yield`) in a turn of its own, the next receiver after its last
    (the lab's set-up alone held the loop 30-40 ms of CPU). A newer value drops
    the steps left, and the new round starts that receiver afresh.
    """

    def __init__(self, receivers: list[Callable[[object], Iterator[None] | None]], parent: QObject | None = None):
        super().__init__(parent)
        self._receivers = list(receivers)
        self._value = None
        self._left: list[Callable[[object], Iterator[None] | None]] = []
        self._then: list[Callable[[], None]] = []
        self._round = 0

    @property
    def pending(self) -> bool:
        """A value is on its way: a receiver, or a callback after them, has yet to run."""
        return bool(self._left or self._then)

    def send(self, value, then: Callable[[], None] | None = None) -> None:
        self._value = value
        self._left = list(self._receivers)
        if then is not None:
            self._then.append(then)
        self._round += 1
        self._schedule(self._round)

    def after(self, callback: Callable[[], None]) -> None:
        """`callback` once every receiver has the value on its way; at once when none is."""
        if self.pending:
            self._then.append(callback)
        else:
            callback()

    def _schedule(self, round_: int) -> None:
        in_a_later_turn(self, lambda: self._next(round_))

    def _next(self, round_: int) -> None:
        if round_ != self._round:
            return                      # a newer send() runs its own round
        if self._left:
            receiver = self._left.pop(0)
            try:
                steps = receiver(self._value)
                if isinstance(steps, Iterator) and next(steps, _DONE) is not _DONE:
                    self._left.insert(0, lambda _value: steps)      # its next step, in a later turn
            finally:
                # A page that fails must not keep the others (and the archive store after them) waiting:
                # the exception still reaches Qt's handler and the log, the round goes on.
                self._schedule(round_)
            return
        while self._then:
            self._then.pop(0)()
