"""Measurements a crash cut short (app.window.unfinished): each choice does what it says, and a failure to recover one
is shown without stopping the others. The recovery itself (instruments.measurement.recovery) is replaced by a
record of what was asked of it; tests/reliability/test_gui_recovery.py runs the real one through the window."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

import instruments.measurement.recovery as recovery
from app.window.unfinished import offer_unfinished


@dataclass(frozen=True)
class Unfinished:
    name: str


@pytest.fixture
def journals(monkeypatch, tmp_path):
    done = []
    found = [Unfinished("a"), Unfinished("b"), Unfinished("c"), Unfinished("d")]

    def recover(unfinished):
        if unfinished.name == "c":
            raise OSError("disk full")
        done.append(("recovered", unfinished.name))
        return tmp_path / f"{unfinished.name}.wav"

    monkeypatch.setattr(recovery, "find_unfinished", lambda directory: found if directory == tmp_path else [])
    monkeypatch.setattr(recovery, "recover", recover)
    monkeypatch.setattr(recovery, "discard", lambda unfinished: done.append(("discarded", unfinished.name)))
    return done


def test_each_choice_is_done_and_a_failure_is_shown_without_stopping_the_rest(journals, tmp_path):
    answers = {"a": "analyse", "b": "discard", "c": "keep", "d": "later"}
    opened, said, errors = [], [], []
    choices = offer_unfinished(tmp_path, ask=lambda u: answers[u.name], open_path=opened.append, say=said.append,
                               show_error=lambda title, message: errors.append((title, message)))
    assert choices == ["analyse", "discard", "keep", "later"]
    assert journals == [("recovered", "a"), ("discarded", "b")]            # 'later' leaves d for the next start
    assert opened == [Path(tmp_path / "a.wav")] and said == [f"Kept the unfinished measurement as {tmp_path / 'a.wav'}"]
    (title, message), = errors
    assert title == "Cannot recover c" and "disk full" in message


def test_nothing_unfinished_asks_nothing(journals, tmp_path):
    asked = []
    assert offer_unfinished(tmp_path / "elsewhere", ask=asked.append, open_path=print, say=print,
                            show_error=print) == []
    assert asked == [] and journals == []
