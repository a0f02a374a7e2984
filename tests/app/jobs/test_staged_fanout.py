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


def _turn_by_turn(monkeypatch) -> list:
    """The fan-out's later turns, kept to be run one by one by the test (no event loop, no timing)."""
    import app.jobs.staged_fanout as staged_fanout
    turns: list = []
    monkeypatch.setattr(staged_fanout, "in_a_later_turn", lambda context, step: turns.append(step))
    return turns


def _steps(calls: list, name: str):
    def receiver(value):
        calls.append(f"{name}1 {value}")
        yield
        calls.append(f"{name}2 {value}")
    return receiver


def test_a_generator_receiver_fills_one_step_a_turn_before_the_next_receiver(monkeypatch):
    turns, calls = _turn_by_turn(monkeypatch), []
    fan = StagedFanOut([_steps(calls, "lab"), calls.append])
    fan.send("v", then=lambda: calls.append("shown"))
    seen = []
    while turns:
        turns.pop(0)()
        seen.append(list(calls))
    assert seen == [["lab1 v"], ["lab1 v", "lab2 v"], ["lab1 v", "lab2 v", "v"], ["lab1 v", "lab2 v", "v", "shown"]]
    assert not fan.pending


def test_a_newer_value_drops_the_steps_left_of_an_older_one(monkeypatch):
    turns, calls, shown = _turn_by_turn(monkeypatch), [], []
    fan = StagedFanOut([_steps(calls, "lab")])
    fan.send("old", then=lambda: shown.append("old"))
    turns.pop(0)()                                  # the lab's first step with the old value
    fan.send("new", then=lambda: shown.append("new"))
    while turns:
        turns.pop(0)()
    assert calls == ["lab1 old", "lab1 new", "lab2 new"]
    assert shown == ["old", "new"]
