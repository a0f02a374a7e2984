"""The Archive page's filter bar: driver, serial and operator text, validity, a date range -> analysis.archive.Filter.

`changed` fires on every edit; the page waits for the typing to stop before
it lists again. One row in a wide window, two in a narrow one: the bar must
not set the window's minimum width.
"""
from __future__ import annotations

from PySide6.QtCore import QDate, QSize, Signal
from PySide6.QtWidgets import QBoxLayout, QComboBox, QDateEdit, QHBoxLayout, QLabel, QLineEdit, QWidget

from analysis.archive import Filter

NO_DATE = QDate(2000, 1, 1)     # a date edit at its minimum shows "any"
VALIDITIES = (("any validity", None), ("green", "green"), ("yellow", "yellow"), ("red", "red"),
              ("unknown", "unknown"))


def _text_edit(placeholder: str) -> QLineEdit:
    edit = QLineEdit()
    edit.setPlaceholderText(placeholder)
    edit.setClearButtonEnabled(True)
    return edit


def date_edit(tooltip: str) -> QDateEdit:
    """A day, or “any” (no limit): the archive's filter and the Production page's selection."""
    edit = QDateEdit()
    edit.setCalendarPopup(True)
    edit.setDisplayFormat("yyyy-MM-dd")
    edit.setMinimumDate(NO_DATE)
    edit.setSpecialValueText("any")
    edit.setDate(NO_DATE)
    edit.setToolTip(tooltip + " (UTC); at 2000-01-01 it shows “any”: no limit")
    return edit


class FilterBar(QWidget):
    changed = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.driver_edit = _text_edit("driver contains…")
        self.serial_edit = _text_edit("serial contains…")
        self.operator_edit = _text_edit("operator contains…")
        self.validity_combo = QComboBox()
        for text, value in VALIDITIES:
            self.validity_combo.addItem(text, value)
        self.since_edit = date_edit("Measured on or after this day")
        self.until_edit = date_edit("Measured on or before this day")
        self.text_row, self.choice_row = QHBoxLayout(), QHBoxLayout()
        for row, label, widget, stretch in (
                (self.text_row, "Driver", self.driver_edit, 3), (self.text_row, "Serial", self.serial_edit, 2),
                (self.text_row, "Operator", self.operator_edit, 2), (self.choice_row, "", self.validity_combo, 0),
                (self.choice_row, "Measured from", self.since_edit, 0), (self.choice_row, "to", self.until_edit, 0)):
            if label:
                row.addWidget(QLabel(label))
            row.addWidget(widget, stretch)
        self.choice_row.addStretch(1)           # on a row of its own, the choices stay compact, left
        self.box = QBoxLayout(QBoxLayout.LeftToRight, self)
        self.box.setContentsMargins(0, 0, 0, 0)
        self.box.addLayout(self.text_row, 1)
        self.box.addLayout(self.choice_row, 0)
        for edit in (self.driver_edit, self.serial_edit, self.operator_edit):
            edit.textChanged.connect(self.changed)
        self.validity_combo.currentIndexChanged.connect(self.changed)
        for edit in (self.since_edit, self.until_edit):
            edit.dateChanged.connect(self.changed)

    def _one_row_width(self) -> int:
        return self.text_row.minimumSize().width() + self.box.spacing() + self.choice_row.minimumSize().width()

    def minimumSizeHint(self) -> QSize:
        """As narrow as two rows can be; as high as the rows are now."""
        width = max(self.text_row.minimumSize().width(), self.choice_row.minimumSize().width())
        return QSize(width, super().minimumSizeHint().height())

    def resizeEvent(self, event) -> None:
        wide = event.size().width() >= self._one_row_width()
        direction = QBoxLayout.LeftToRight if wide else QBoxLayout.TopToBottom
        if self.box.direction() != direction:
            self.box.setDirection(direction)
        super().resizeEvent(event)

    @property
    def rows(self) -> int:
        return 1 if self.box.direction() == QBoxLayout.LeftToRight else 2

    def filter(self, limit: int | None = None) -> Filter:
        def text(edit):
            return edit.text().strip() or None

        def day(edit):
            return None if edit.date() == NO_DATE else edit.date().toString("yyyy-MM-dd")
        return Filter(driver=text(self.driver_edit), serial=text(self.serial_edit),
                      operator=text(self.operator_edit), validity=self.validity_combo.currentData(),
                      since=day(self.since_edit), until=day(self.until_edit), limit=limit)

    @property
    def active(self) -> bool:
        return self.filter() != Filter()
