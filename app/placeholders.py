"""Pages that other issues will fill. Each says what it will do and what to use until then;
none shows controls that do nothing."""
from __future__ import annotations

import html

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QHBoxLayout, QLabel, QVBoxLayout, QWidget

TEXT_WIDTH = 640

# Every page of PAGE_ORDER is built now (Measure: app.wizard; QA: app.qa_view); a future page
# that is not ready yet gets an entry here: name -> (what it will do, what to use until then).
PAGES: dict[str, tuple[str, str]] = {}


class PlaceholderPage(QWidget):
    def __init__(self, name: str, parent=None):
        super().__init__(parent)
        what, meanwhile = PAGES[name]
        self.label = QLabel(
            f"<h2>{html.escape(name)}: not available yet</h2>"
            f"<p>{html.escape(what)}</p><p>{html.escape(meanwhile)}</p>")
        self.label.setTextFormat(Qt.RichText)
        self.label.setWordWrap(True)
        self.label.setAlignment(Qt.AlignHCenter | Qt.AlignTop)
        # A fixed width: a word-wrapped label given only a maximum width is laid out
        # at its one-line height and its text gets clipped.
        self.label.setFixedWidth(TEXT_WIDTH)
        row = QHBoxLayout()
        row.addStretch(1)
        row.addWidget(self.label)
        row.addStretch(1)
        layout = QVBoxLayout(self)
        layout.addStretch(1)
        layout.addLayout(row)
        layout.addStretch(2)
