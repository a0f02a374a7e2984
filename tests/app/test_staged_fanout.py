"""StagedFanOut: one value to several receivers, one turn of the event loop each, then the callbacks."""
from __future__ import annotations

from app.staged_fanout import StagedFanOut


def test_each_receiver_gets_the_value_in_a_later_turn_then_the_callbacks_run(qtbot):
    calls = []
    fan = StagedFanOut([lambda v: calls.append(("lab", v)), lambda v: calls.append(("qa", v))])
    fan.send(1, then=lambda: calls.append(("shown", None)))
    fan.after(lambda: calls.append(("after", None)))
    assert calls == [] and fan.pending                  # nothing in the sender's own turn
    qtbot.waitUntil(lambda: len(calls) == 4, timeout=1000)
    assert calls == [("lab", 1), ("qa", 1), ("shown", None), ("after", None)]
    assert not fan.pending


def test_a_newer_value_replaces_one_on_its_way_and_no_callback_is_lost(qtbot):
    got, shown = [], []
    fan = StagedFanOut([got.append, got.append])
    fan.send("old", then=lambda: shown.append("old"))
    fan.send("new", then=lambda: shown.append("new"))
    qtbot.waitUntil(lambda: len(shown) == 2, timeout=1000)
    assert got == ["new", "new"]
    assert shown == ["old", "new"]


def test_after_runs_at_once_when_nothing_is_on_its_way(qtbot):
    fan = StagedFanOut([lambda v: None])
    ran = []
    fan.after(lambda: ran.append(True))
    assert ran == [True]
