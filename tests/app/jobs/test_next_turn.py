"""in_a_later_turn: work split over turns lets the timers that fell due meanwhile run in between.

With zero timers (posted events), two 20 ms steps often ran back to back: a 5 ms timer, as a repaint or a
stall meter, waited 40 ms. The order checked here follows from the timers' timeouts, not from the host's pace:
a tick due during a step times out before the next step, scheduled at the step's end, and a tick due during
the events a step posted (a plot's paint) before the next step, scheduled once those have run.
"""
from __future__ import annotations

import time

from PySide6.QtCore import QCoreApplication, QEvent, QObject, Qt, QTimer

from app.jobs.next_turn import in_a_later_turn
from app.jobs.staged_fanout import StagedFanOut
from tests.pace import wait_ms

STEP_S = 0.02


def _busy(seconds: float) -> None:
    """A step that holds the GUI thread, as a page's fill does."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass


def _ticking(order: list) -> QTimer:
    tick = QTimer()
    tick.setTimerType(Qt.PreciseTimer)
    tick.setInterval(5)
    tick.timeout.connect(lambda: order.append("tick") if order and order[-1] != "tick" else None)
    return tick


def test_a_timer_runs_between_every_two_steps(qtbot):
    order = []
    context = QObject()
    tick = _ticking(order)

    def step(k):
        order.append(k)
        _busy(STEP_S)
        if k < 5:
            in_a_later_turn(context, lambda: step(k + 1))

    tick.start()
    in_a_later_turn(context, lambda: step(0))
    qtbot.waitUntil(lambda: 5 in order, timeout=wait_ms(10))
    tick.stop()
    steps = [i for i, entry in enumerate(order) if entry != "tick"]
    assert order[steps[0]:steps[-1] + 1] == [0, "tick", 1, "tick", 2, "tick", 3, "tick", 4, "tick", 5]


class _Scene(QObject):
    """What a step sets off in events of its own, as a plot's scene that processes and paints its change."""

    def event(self, event) -> bool:
        if event.type() == QEvent.User:
            _busy(STEP_S)
            return True
        return super().event(event)


def test_a_timer_runs_between_a_short_step_whose_posted_work_is_long_and_the_next_step(qtbot):
    order = []
    context, scene = QObject(), _Scene()
    tick = _ticking(order)

    def step(k):
        order.append(k)
        QCoreApplication.postEvent(scene, QEvent(QEvent.User))
        if k < 5:
            in_a_later_turn(context, lambda: step(k + 1))

    tick.start()
    in_a_later_turn(context, lambda: step(0))
    qtbot.waitUntil(lambda: 5 in order, timeout=wait_ms(10))
    tick.stop()
    steps = [i for i, entry in enumerate(order) if entry != "tick"]
    assert order[steps[0]:steps[-1] + 1] == [0, "tick", 1, "tick", 2, "tick", 3, "tick", 4, "tick", 5]


def test_the_fan_out_lets_a_timer_run_between_its_receivers(qtbot):
    order = []
    tick = _ticking(order)

    def receiver(name):
        def receive(value):
            order.append((name, value))
            _busy(STEP_S)
        return receive

    fan = StagedFanOut([receiver("results"), receiver("lab"), receiver("qa")])
    tick.start()
    fan.send(7, then=lambda: order.append("shown"))
    qtbot.waitUntil(lambda: "shown" in order, timeout=wait_ms(10))
    tick.stop()
    pages = [entry for entry in order if entry != "tick"]
    assert pages == [("results", 7), ("lab", 7), ("qa", 7), "shown"]
    first = order.index(("results", 7))
    assert order[first:first + 5] == [("results", 7), "tick", ("lab", 7), "tick", ("qa", 7)]
