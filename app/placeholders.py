"""Pages that other issues will fill. Each says what it will do and what to use until then;
none shows controls that do nothing."""
from __future__ import annotations

import html

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QHBoxLayout, QLabel, QVBoxLayout, QWidget

TEXT_WIDTH = 640

PAGES = {
    "Measure": (
        "This page will run a measurement: choose the sound card and the laser (or the virtual rig), set the "
        "level and the number of periods, watch voltage, current and displacement with their signal and noise "
        "lines while the periods are averaged, and save the recording.",
        "Until then, open an existing recording (NAME.wav with its NAME.json) with File ▸ Open recording…",
    ),
    "QA": (
        "This page will check drivers against a reference: tolerance limits on the parameters, the validity "
        "of each measurement, and a pass/fail report per driver.",
        "Nothing replaces it yet.",
    ),
}


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
