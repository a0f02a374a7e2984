"""Widgets that come and go without moving the rest of the page."""
from __future__ import annotations

from PySide6.QtWidgets import QWidget


def keep_room_when_hidden(*widgets: QWidget) -> None:
    """Hidden widgets keep their place in the layout.

    A busy indicator that appeared and vanished would change the height of its
    row and so resize every plot below it; pyqtgraph then redraws them all in
    one go, a stall of the event loop of 50 ms or more (bench/gui_bench.py).
    """
    for widget in widgets:
        policy = widget.sizePolicy()
        policy.setRetainSizeWhenHidden(True)
        widget.setSizePolicy(policy)
