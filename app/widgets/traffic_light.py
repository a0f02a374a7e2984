"""Traffic lights: a coloured lamp, a channel's light with its findings, and a validity summary.

The lamp is painted, not a stylesheet: a round lamp of any size, with the
state also in its tooltip and accessible name (colour alone must not carry the
meaning: the text next to it names the state too).
"""
from __future__ import annotations

import html
from typing import Iterable

from PySide6.QtCore import QRectF, QSize, Qt
from PySide6.QtGui import QBrush, QColor, QPainter, QPen
from PySide6.QtWidgets import QGridLayout, QHBoxLayout, QLabel, QSizePolicy, QVBoxLayout, QWidget

from app.widgets import style

LAMP_COLOURS = {"green": "#2e9d3a", "yellow": "#f2b90f", "red": "#d32f2f", "unknown": "#b0b0b0",
                "absent": "#ffffff"}
STATE_WORDS = {"green": "valid", "yellow": "doubtful", "red": "invalid", "unknown": "not judged yet",
               "absent": "not measured"}
CHANNEL_TITLES = {"voltage": "Voltage", "current": "Current", "displacement": "Displacement"}
CHANNELS = ("voltage", "current", "displacement")


class TrafficLight(QWidget):
    def __init__(self, diameter: int = 18, parent=None):
        super().__init__(parent)
        self.diameter = diameter
        self.status = "unknown"
        self.shown: str | None = None          # the status last set, as given
        self.setSizePolicy(QSizePolicy.Fixed, QSizePolicy.Fixed)
        self.set_status("unknown")

    def sizeHint(self) -> QSize:
        return QSize(self.diameter + 4, self.diameter + 4)

    def minimumSizeHint(self) -> QSize:
        return self.sizeHint()

    def set_status(self, status: str) -> None:
        if status == self.shown:       # the live panels set it with every frame: a repaint only when it changes
            return
        self.shown = status
        self.status = status if status in LAMP_COLOURS else "unknown"
        words = STATE_WORDS.get(self.status, status)
        self.setToolTip(f"{status}: {words}")
        self.setAccessibleName(f"{status} light")
        self.update()

    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.Antialiasing)
        colour = QColor(LAMP_COLOURS[self.status])
        painter.setPen(QPen(colour.darker(150) if self.status != "absent" else QColor("#808080"), 1.5))
        painter.setBrush(QBrush(colour))
        d = float(self.diameter)
        painter.drawEllipse(QRectF((self.width() - d) / 2, (self.height() - d) / 2, d, d))


def findings_html(findings: Iterable, empty: str = "") -> str:
    """Each finding's (analysis.validity.findings.Finding) message, and its remedy in italics (what to do matters
    as much as what is wrong)."""
    items = []
    for finding in findings:
        severity, message, remedy = str(finding.severity), finding.message, finding.remedy
        colour = style.validity_colours(severity)[1]
        text = f"<span style='color:{colour}'>●</span> {html.escape(message)}"
        code = finding.code
        if code:        # the stable code: the user guide, the report and the CLI's JSON name it too
            text += f" <span style='color:#666666'>[{html.escape(str(code))}]</span>"
        if remedy:
            text += f" — <i>{html.escape(remedy)}</i>"
        items.append(text)
    return "<br>".join(items) if items else html.escape(empty)


class ChannelLight(QWidget):
    """One channel: its lamp, its name and state, and its findings with their remedies."""

    def __init__(self, channel: str, diameter: int = 18, parent=None, compact: bool = False):
        super().__init__(parent)
        self.channel = channel
        self.compact = compact          # name, state and findings in one paragraph (the live panels)
        self.light = TrafficLight(diameter)
        self.title = QLabel()
        self.title.setTextFormat(Qt.RichText)
        self.details = QLabel()
        self.details.setTextFormat(Qt.RichText)
        self.details.setWordWrap(True)
        self.details.setTextInteractionFlags(Qt.TextSelectableByMouse)
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 2, 0, 2)
        grid.setHorizontalSpacing(8)
        grid.setVerticalSpacing(1)
        grid.addWidget(self.light, 0, 0, 2, 1, Qt.AlignTop)
        grid.addWidget(self.title, 0, 1)
        grid.addWidget(self.details, 1, 1)
        self.title.setVisible(not compact)
        grid.setColumnStretch(1, 1)
        self.set_state("unknown", ())

    def set_state(self, status: str, findings: Iterable) -> None:
        findings = tuple(findings)
        self.light.set_status(status)
        self.title.setText(f"<b>{CHANNEL_TITLES.get(self.channel, self.channel)}</b>: "
                           f"{html.escape(STATE_WORDS.get(status, status))}")
        empty = {"green": "every check passed", "absent": "no such channel in this measurement",
                 "unknown": "needs two periods for a noise estimate"}.get(status, "")
        if self.compact:
            self.details.setText(self.title.text() + " — " + findings_html(findings, empty))
        else:
            self.details.setText(findings_html(findings, empty))

    @property
    def text(self) -> str:
        return self.details.text() if self.compact else self.title.text() + " " + self.details.text()


class ValiditySummary(QWidget):
    """The overall light, what it means, and a ChannelLight per channel (a result's validity)."""

    def __init__(self, overall_diameter: int = 28, channel_diameter: int = 16, parent=None):
        super().__init__(parent)
        self.overall_light = TrafficLight(overall_diameter)
        self.overall_text = QLabel()
        self.overall_text.setTextFormat(Qt.RichText)
        self.overall_text.setWordWrap(True)
        top = QHBoxLayout()
        top.setContentsMargins(0, 0, 0, 0)
        top.addWidget(self.overall_light, 0, Qt.AlignTop)
        top.addWidget(self.overall_text, 1)
        self.channels = {name: ChannelLight(name, channel_diameter) for name in CHANNELS}
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(top)
        for light in self.channels.values():
            layout.addWidget(light)
        self.set_validity(None)

    def set_validity(self, validity) -> None:
        """validity: an analysis.validity.result.ResultValidity, or None (not judged yet)."""
        overall = "unknown" if validity is None else str(validity.overall)
        self.overall_light.set_status(overall)
        meaning = style.VALIDITY_TEXT.get(overall, "a state this version does not know")
        peak = None if validity is None else validity.peak_displacement_m
        peak_text = f" Peak excursion {peak * 1e3:.3g} mm." if peak is not None else ""
        self.overall_text.setText(f"<b>Measurement {html.escape(STATE_WORDS.get(overall, overall))}</b> "
                                  f"({html.escape(overall)}): {html.escape(meaning)}.{peak_text}")
        channels = {} if validity is None else validity.channels
        for name, light in self.channels.items():
            entry = channels.get(name)
            light.set_state("unknown" if entry is None else str(entry.status or "unknown"),
                            () if entry is None else entry.findings)
