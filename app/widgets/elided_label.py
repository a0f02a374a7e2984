"""One line of plain text cut with "…" to the room it is given, the whole of it in the tooltip: the status bar's
words. A word-wrapped label there wrapped a long file name onto a third line the bar had no room for, and a plain
one asked the window for the whole text's width."""
from __future__ import annotations

from PySide6.QtCore import QSize, Qt
from PySide6.QtWidgets import QLabel, QSizePolicy


class ElidedLabel(QLabel):
    """`text()` is the whole text; what is painted is as much of it as fits, ending in "…" when cut."""

    def __init__(self, text: str = "", parent=None):
        super().__init__(parent)
        self.setTextFormat(Qt.PlainText)      # file names and messages: never markup
        self.setWordWrap(False)
        # It asks for its whole text but takes what the row leaves it, down to nothing (minimumSizeHint).
        self.setSizePolicy(QSizePolicy.Preferred, QSizePolicy.Fixed)
        self._whole = ""
        self.setText(text)

    def setText(self, text: str) -> None:
        self._whole = text
        self.setToolTip(text)
        self.updateGeometry()
        self._elide()

    def text(self) -> str:
        return self._whole

    def shown_text(self) -> str:
        """What is painted: the whole text, or its start and "…"."""
        return super().text()

    def sizeHint(self) -> QSize:
        # Of the whole text, not of the cut one: the hint does not change when the label is resized, so eliding
        # never asks the layout for another round.
        margins = self.contentsMargins()
        width = self.fontMetrics().horizontalAdvance(self._whole) + margins.left() + margins.right() + 2
        return QSize(width, super().minimumSizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(0, super().minimumSizeHint().height())

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        room = max(0, self.contentsRect().width())
        super().setText(self.fontMetrics().elidedText(self._whole, Qt.ElideRight, room))
