"""Measurements a crash cut short, offered when the workstation starts: keep, analyse, discard, or later.

instruments.measurement.recovery finds them (a journal whose process is gone) and turns one into a
recording marked partial; this module asks the user (a message box) and does what they chose. The main
window calls `offer_unfinished` once at start-up, with its own ways to open a recording and to say things.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from PySide6.QtWidgets import QMessageBox, QWidget

from app.jobs.book import failure_text

CHOICES = ("analyse", "keep", "discard", "later")


def offer_unfinished(directory: Path, ask: Callable[[object], str], open_path: Callable[[Path], None],
                     say: Callable[[str], None], show_error: Callable[[str, str], None]) -> list[str]:
    """Ask about each unfinished measurement in `directory` (`ask` returns one of CHOICES) and do it: a kept
    one is written as a recording (said), an analysed one is also opened. Returns the choices, in order."""
    from instruments.measurement.recovery import discard, find_unfinished, recover
    choices = []
    for unfinished in find_unfinished(directory):
        choice = ask(unfinished)
        choices.append(choice)
        try:
            if choice in ("keep", "analyse"):
                path = recover(unfinished)
                say(f"Kept the unfinished measurement as {path}")
                if choice == "analyse":
                    open_path(path)
            elif choice == "discard":
                discard(unfinished)
        except Exception as exc:  # noqa: BLE001 - the GUI's error boundary (job_book.failure_text)
            show_error(f"Cannot recover {unfinished.name}", failure_text(exc, f"recovering {unfinished.name}"))
    return choices


def ask_unfinished(parent: QWidget, unfinished) -> str:
    """'analyse', 'keep', 'discard' or 'later' (asked again at the next start), from a message box."""
    box = QMessageBox(QMessageBox.Question, "Unfinished measurement",
                      "A measurement was cut short (the program stopped before writing it):\n\n"
                      f"{unfinished.describe()}", parent=parent)
    buttons = {}
    if not unfinished.problem:
        buttons[box.addButton("Keep and analyse", QMessageBox.AcceptRole)] = "analyse"
        buttons[box.addButton("Keep", QMessageBox.ApplyRole)] = "keep"
    buttons[box.addButton("Discard", QMessageBox.DestructiveRole)] = "discard"
    later = box.addButton("Later", QMessageBox.RejectRole)
    buttons[later] = "later"
    box.setDefaultButton(later)
    box.exec()
    return buttons.get(box.clickedButton(), "later")
