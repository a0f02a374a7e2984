"""A text over an empty plot: "no data yet: start the level check", instead of meaningless 0-1 axes.

A label laid over the whole plot widget (axes included), in the plots' white, that follows the
widget's size. `show_text` puts it up; `hide` takes it down when the data arrive.
"""
from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QLabel, QWidget

PLACEHOLDER_STYLE = "QLabel { background: white; color: #666; border: 1px solid #d8d8d8; padding: 12px; }"


class PlotPlaceholder(QLabel):
    def __init__(self, plot: QWidget, text: str = ""):
        super().__init__(plot)
        self.setAlignment(Qt.AlignCenter)
        self.setWordWrap(True)
        self.setStyleSheet(PLACEHOLDER_STYLE)
        self.setAttribute(Qt.WA_TransparentForMouseEvents)
        self._plot = plot
        plot.installEventFilter(self)
        self.show_text(text)

    def show_text(self, text: str) -> None:
        self.setText(text)
        self.setGeometry(self._plot.rect())
        self.setVisible(bool(text))
        self.raise_()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self._plot and event.type() == QEvent.Resize:
            self.setGeometry(self._plot.rect())
        return False
