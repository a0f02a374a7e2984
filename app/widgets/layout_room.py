"""Widgets that come and go without moving the rest of the page."""
from __future__ import annotations

from PySide6.QtCore import QSize, Qt
from PySide6.QtWidgets import QLabel, QSizePolicy, QWidget


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


class LinesLabel(QLabel):
    """A word-wrapped label `lines` tall whatever it says: a longer text is cut, and (unless the page gives the
    label a tooltip of its own) the tooltip has the whole of it. Squeezed (a window at its smallest), it gives way
    down to one line: it asks for its lines without adding them to the window's minimum size.

    A text that wrapped to one line more or less than the one before changed its row's height and so resized
    every plot below it: after each refit of the Model lab its header (56 -> 112 px and back), the words over the
    residual plots and the chart's list of versions (a line more each time) moved the chart and the residual
    plots, which pyqtgraph then laid out and redrew, ~30 ms of the GUI thread each.
    """

    def __init__(self, lines: int, whole_in_tooltip: bool = True, parent=None):
        super().__init__(parent)
        self.whole_in_tooltip = whole_in_tooltip
        self.lines = lines
        self.setWordWrap(True)
        self.setAlignment(Qt.AlignLeft | Qt.AlignTop)      # a short text where a long one starts, not mid-box
        self.setSizePolicy(QSizePolicy.Preferred, QSizePolicy.Maximum)
        self.setMaximumHeight(self._line_height() * lines)

    def _line_height(self) -> int:
        return self.fontMetrics().lineSpacing()

    def hasHeightForWidth(self) -> bool:
        return False            # the text's wrapping never asks the layout for another height

    def sizeHint(self) -> QSize:
        return QSize(super().sizeHint().width(), self._line_height() * self.lines)

    def minimumSizeHint(self) -> QSize:
        return QSize(super().minimumSizeHint().width(), self._line_height())

    def setText(self, text: str) -> None:
        super().setText(text)
        if self.whole_in_tooltip:
            self.setToolTip(text)
