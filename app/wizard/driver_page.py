"""Step 1: which driver is measured: name, serial number, Sd, nominal impedance and its class; who measures where."""
from __future__ import annotations

import socket

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (QComboBox, QDoubleSpinBox, QFormLayout, QHBoxLayout, QLabel, QLineEdit,
                               QVBoxLayout)

from app.wizard.base import WizardPage, rich_label
from app.wizard.plans import TEMPLATES, DriverInfo, sd_from_diameter

SD_AREA, SD_DIAMETER = 0, 1
TEMPLATE_KEY = "measure/template"
OPERATOR_KEY = "measure/operator"
STATION_KEY = "measure/station"


def default_station() -> str:
    """This computer's name: a station is usually one computer with its rig."""
    try:
        return socket.gethostname()
    except OSError:
        return ""


SD_UNKNOWN_TEXT = ("Sd unknown: Vas, the efficiency and the SPL will not be reported (it can be entered later on "
                   "the Results page).")
SD_DIAMETER_TEXT = "Sd = {sd_cm2:.1f} cm² (a piston of that diameter)"


class SteadyNote(QLabel):
    """A wrapped plain-text note as tall, at its width, as the tallest of the texts it may show."""

    def __init__(self, texts: tuple[str, ...]):
        super().__init__()
        self.setTextFormat(Qt.PlainText)
        self.setWordWrap(True)
        self.setAlignment(Qt.AlignLeft | Qt.AlignTop)
        self._measure = QLabel()            # never shown: wraps each text as this label would
        self._measure.setTextFormat(Qt.PlainText)
        self._measure.setWordWrap(True)
        self._texts = texts

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._measure.setFont(self.font())
        heights = []
        for text in self._texts:
            self._measure.setText(text)
            # The form gives a wrapped label its size hint's height, or more when its width needs more.
            heights.append(max(self._measure.sizeHint().height(), self._measure.heightForWidth(self.width())))
        if max(heights) != self.minimumHeight():
            self.setMinimumHeight(max(heights))


class DriverPage(WizardPage):
    title = "Driver"
    subtitle = "What is measured: the recording and the report are named after it."

    def __init__(self, state, session, parent=None):
        super().__init__(state, session, parent)
        self.name_edit = QLineEdit()
        self.name_edit.setPlaceholderText("required, e.g. W18-PAPER")
        self.serial_edit = QLineEdit()
        self.serial_edit.setPlaceholderText("optional, e.g. 0042")
        self.sd_mode = QComboBox()
        self.sd_mode.addItems(["Sd (cm²)", "effective diameter (cm)"])
        self.sd_value = QDoubleSpinBox()
        self.sd_value.setDecimals(2)
        self.sd_value.setRange(0.0, 5000.0)
        self.sd_value.setSpecialValueText("unknown")
        self.sd_value.setToolTip("The effective radiating area: needed for Vas, the efficiency and the SPL")
        sd_row = QHBoxLayout()
        sd_row.addWidget(self.sd_mode)
        sd_row.addWidget(self.sd_value, 1)
        # As tall as its longest text whatever it says, or when it says nothing: a note that came and went as Sd
        # was typed moved every row under it, under the mouse.
        self.sd_note = SteadyNote((SD_UNKNOWN_TEXT, SD_DIAMETER_TEXT.format(sd_cm2=9999.9)))
        self.impedance = QDoubleSpinBox()
        self.impedance.setRange(0.0, 100.0)
        self.impedance.setDecimals(1)
        self.impedance.setSuffix(" Ω")
        self.impedance.setSpecialValueText("unknown")
        self.impedance.setToolTip("The nominal impedance printed on the driver; it suggests the reference "
                                  "resistor of the calibration")
        self.template = QComboBox()
        for key, template in TEMPLATES.items():
            self.template.addItem(template.title, key)
        saved = state.settings.value(TEMPLATE_KEY, "woofer")
        self.template.setCurrentIndex(max(0, self.template.findData(saved)))
        self.template_note = rich_label()
        # Remembered: the same person measures a batch at the same station.
        self.operator_edit = QLineEdit(str(state.settings.value(OPERATOR_KEY, "") or ""))
        self.operator_edit.setPlaceholderText("optional: who measures (kept in the archive)")
        self.station_edit = QLineEdit(str(state.settings.value(STATION_KEY, default_station()) or ""))
        self.station_edit.setPlaceholderText("optional: which rig or bench (kept in the archive)")

        form = QFormLayout()
        form.addRow("Name", self.name_edit)
        form.addRow("Serial number", self.serial_edit)
        form.addRow("Radiating area", sd_row)
        form.addRow("", self.sd_note)
        form.addRow("Nominal impedance", self.impedance)
        form.addRow("Class (template)", self.template)
        form.addRow("", self.template_note)
        form.addRow("Operator", self.operator_edit)
        form.addRow("Station", self.station_edit)
        # A form as wide as the window reads badly: keep it to a column, left.
        row = QHBoxLayout()
        row.addLayout(form, 3)
        row.addStretch(2)
        layout = QVBoxLayout(self)
        layout.addLayout(row)
        layout.addStretch(1)

        self.name_edit.textChanged.connect(self.changed)
        for signal in (self.sd_mode.currentIndexChanged, self.sd_value.valueChanged,
                       self.template.currentIndexChanged):
            signal.connect(self.on_edited)
        self.on_edited()

    def sd_m2(self) -> float | None:
        value = self.sd_value.value()
        if value <= 0:
            return None
        if self.sd_mode.currentIndex() == SD_DIAMETER:
            return sd_from_diameter(value / 100.0)
        return value * 1e-4

    def on_edited(self, *_args) -> None:
        self.sd_value.setRange(0.0, 5000.0 if self.sd_mode.currentIndex() == SD_AREA else 80.0)
        sd = self.sd_m2()
        if sd is None:
            self.sd_note.setText(SD_UNKNOWN_TEXT)
        elif self.sd_mode.currentIndex() == SD_DIAMETER:
            self.sd_note.setText(SD_DIAMETER_TEXT.format(sd_cm2=sd * 1e4))
        else:
            self.sd_note.setText("")
        template = TEMPLATES[self.template.currentData()]
        self.template_note.setText(template.describe())
        self.changed.emit()

    def missing(self) -> str | None:
        if not self.name_edit.text().strip():
            return "Give the driver's name: it names the recording and the report."
        return None

    def commit(self) -> None:
        key = self.template.currentData()
        operator, station = self.operator_edit.text().strip(), self.station_edit.text().strip()
        self.state.settings.setValue(TEMPLATE_KEY, key)
        self.state.settings.setValue(OPERATOR_KEY, operator)
        self.state.settings.setValue(STATION_KEY, station)
        self.state.driver = DriverInfo(self.name_edit.text().strip(), self.serial_edit.text().strip(),
                                       self.sd_m2(), self.impedance.value() or None, key, operator, station)
