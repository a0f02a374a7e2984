"""StagedFanOut: one value to several receivers, one turn of the event loop each, then the callbacks."""
from __future__ import annotations

from app.jobs.staged_fanout import StagedFanOut
from tests.pace import wait_ms


def test_each_receiver_gets_the_value_in_a_later_turn_then_the_callbacks_run(qtbot):
    calls = []
    fan = StagedFanOut([lambda v: calls.append(("lab", v)), lambda v: calls.append(("qa", v))])
    fan.send(1, then=lambda: calls.append(("shown", None)))
    fan.after(lambda: calls.append(("after", None)))
    assert calls == [] and fan.pending                  # nothing in the sender's own turn
    qtbot.waitUntil(lambda: len(calls) == 4, timeout=wait_ms(10))
    assert calls == [("lab", 1), ("qa", 1), ("shown", None), ("after", None)]
    assert not fan.pending


def test_a_newer_value_replaces_one_on_its_way_and_no_callback_is_lost(qtbot):
    got, shown = [], []
    fan = StagedFanOut([got.append, got.append])
    fan.send("old", then=lambda: shown.append("old"))
    fan.send("new", then=lambda: shown.append("new"))
    qtbot.waitUntil(lambda: len(shown) == 2, timeout=wait_ms(10))
    assert got == ["new", "new"]
    assert shown == ["old", "new"]


def test_after_runs_at_once_when_nothing_is_on_its_way(qtbot):
    fan = StagedFanOut([lambda v: None])
    ran = []
    fan.after(lambda: ran.append(True))
    assert ran == [True]


def test_a_receiver_that_fails_does_not_stop_the_others_or_the_callbacks(qtbot):
    got, shown = [], []

    def broken(value):
        raise RuntimeError("a page failed")

    fan = StagedFanOut([broken, got.append])
    fan.send(7, then=lambda: shown.append(True))
    with qtbot.captureExceptions() as exceptions:
        qtbot.waitUntil(lambda: bool(shown), timeout=wait_ms(10))
    assert got == [7] and shown == [True]
    assert [str(e[1]) for e in exceptions] == ["a page failed"]


def test_a_callback_given_while_earlier_ones_wait_runs_after_them(qtbot):
    order = []
    fan = StagedFanOut([lambda v: fan.after(lambda: order.append("late"))])
    fan.send(1, then=lambda: order.append("first"))
    qtbot.waitUntil(lambda: len(order) == 2, timeout=wait_ms(10))
    assert order == ["first", "late"]
