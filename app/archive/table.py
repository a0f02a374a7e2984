"""The table of stored measurements: validity light, date, who and what, and the key parameters.

One row per analysis.archive.Entry, newest first as the index lists them;
a click on a header sorts (numbers as numbers: the sort role holds the raw
value). Parameters are stored in SI and shown in the customary unit.
"""
from __future__ import annotations

import html
import math

from PySide6.QtCore import QAbstractTableModel, QModelIndex, QSortFilterProxyModel, Qt
from PySide6.QtGui import QColor, QIcon, QPainter, QPixmap
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableView

from app.widgets import style
from app.widgets.traffic_light import LAMP_COLOURS

SORT_ROLE = Qt.UserRole
# (name, header, scale from SI to the display unit)
PARAMETERS = (("RE", "RE (Ω)", 1.0), ("fs", "fs (Hz)", 1.0), ("Qts", "Qts", 1.0), ("Bl", "Bl (T·m)", 1.0),
              ("Mms", "Mms (g)", 1e3))
TEXT_COLUMNS = (("validity", "Validity"), ("measured_at", "Measured (UTC)"), ("driver", "Driver"),
                ("serial", "Serial"), ("operator", "Operator"), ("station", "Station"))
HEADERS = tuple(h for _, h in TEXT_COLUMNS) + tuple(h for _, h, _ in PARAMETERS)
VALIDITY, DATE = 0, 1
FIRST_PARAMETER = len(TEXT_COLUMNS)
LAMP_SIZE = 12


def lamp_icon(state: str, cache: dict[str, QIcon] = {}) -> QIcon:  # noqa: B006 - a deliberate cache
    """A round lamp in the traffic lights' colour of `state`."""
    if state not in cache:
        pixmap = QPixmap(LAMP_SIZE + 2, LAMP_SIZE + 2)
        pixmap.fill(Qt.transparent)
        painter = QPainter(pixmap)
        painter.setRenderHint(QPainter.Antialiasing)
        colour = QColor(LAMP_COLOURS.get(state, LAMP_COLOURS["unknown"]))
        painter.setPen(colour.darker(150))
        painter.setBrush(colour)
        painter.drawEllipse(1, 1, LAMP_SIZE, LAMP_SIZE)
        painter.end()
        cache[state] = QIcon(pixmap)
    return cache[state]


def date_text(iso: str) -> str:
    """'2024-05-01T10:00:00Z' -> '2024-05-01 10:00:00'."""
    return iso.replace("T", " ").removesuffix("Z")


def parameter_value(entry, name: str, scale: float) -> tuple[float | None, float | None]:
    """(value, std) in the display unit; None where the index has no number."""
    p = entry.parameters.get(name) or {}
    value, std = p.get("value"), p.get("std")
    value = value * scale if isinstance(value, (int, float)) and math.isfinite(value) else None
    std = std * abs(scale) if isinstance(std, (int, float)) and math.isfinite(std) else None
    return value, std


class ArchiveModel(QAbstractTableModel):
    def __init__(self, parent=None):
        super().__init__(parent)
        self._entries: list = []

    def set_entries(self, entries) -> None:
        self.beginResetModel()
        self._entries = list(entries)
        self.endResetModel()

    def entry(self, row: int):
        return self._entries[row]

    @property
    def entries(self) -> list:
        return list(self._entries)

    def rowCount(self, parent=QModelIndex()) -> int:
        return 0 if parent.isValid() else len(self._entries)

    def columnCount(self, parent=QModelIndex()) -> int:
        return 0 if parent.isValid() else len(HEADERS)

    def headerData(self, section, orientation, role=Qt.DisplayRole):
        if orientation == Qt.Horizontal and role == Qt.DisplayRole:
            return HEADERS[section]
        return None

    def data(self, index: QModelIndex, role=Qt.DisplayRole):
        if not index.isValid():
            return None
        e = self._entries[index.row()]
        col = index.column()
        if col < FIRST_PARAMETER:
            key = TEXT_COLUMNS[col][0]
            text = getattr(e, key)
            if role == Qt.DisplayRole:
                return date_text(text) if col == DATE else text
            if role == SORT_ROLE:
                return text
            if role == Qt.DecorationRole and col == VALIDITY:
                return lamp_icon(e.validity)
            if role == Qt.ToolTipRole:
                return self._tooltip(e)
            return None
        name, _, scale = PARAMETERS[col - FIRST_PARAMETER]
        value, std = parameter_value(e, name, scale)
        if role == Qt.DisplayRole:
            return "–" if value is None else f"{value:.4g}"
        if role == SORT_ROLE:
            return -math.inf if value is None else value
        if role == Qt.ToolTipRole:
            if value is None:
                return f"{name} not stored"
            text = f"{name} = {value:.6g}" + ("" if std is None else f" ± {std:.2g}") + " (±1σ)"
            return text + ("\nThe measurement is invalid (red): not to be trusted" if e.validity == "red" else "")
        if role == Qt.TextAlignmentRole:
            return int(Qt.AlignRight | Qt.AlignVCenter)
        if role == Qt.ForegroundRole and (value is None or e.validity == "red"):
            return QColor(style.MISSING_TEXT)     # a red measurement's parameters are not to be trusted
        return None

    @staticmethod
    def _tooltip(e) -> str:
        meaning = style.VALIDITY_TEXT.get(e.validity, "a state this version does not know")
        model = ", ".join(e.effects) or "textbook (no effects)"
        return (f"<b>{html.escape(e.id)}</b><br>validity {html.escape(e.validity)}: {html.escape(meaning)}"
                f"<br>model: {html.escape(model)}<br>stored {html.escape(date_text(e.stored_at))} UTC"
                f"<br>folder: {html.escape(e.folder)}")


class ArchiveTable(QTableView):
    """The view, sorted through a proxy; `selected_entries()` in the order shown."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.archive_model = ArchiveModel(self)
        self.proxy = QSortFilterProxyModel(self)
        self.proxy.setSourceModel(self.archive_model)
        self.proxy.setSortRole(SORT_ROLE)
        self.setModel(self.proxy)
        self.setSortingEnabled(True)
        self.sortByColumn(DATE, Qt.DescendingOrder)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setSelectionMode(QAbstractItemView.ExtendedSelection)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.setAlternatingRowColors(True)
        self.setWordWrap(False)
        self.verticalHeader().setVisible(False)
        self.verticalHeader().setDefaultSectionSize(self.fontMetrics().height() + 8)
        header = self.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeToContents)
        header.setSectionResizeMode(TEXT_COLUMNS.index(("driver", "Driver")), QHeaderView.Stretch)

    def set_entries(self, entries) -> None:
        self.archive_model.set_entries(entries)

    def entry_at(self, view_row: int):
        return self.archive_model.entry(self.proxy.mapToSource(self.proxy.index(view_row, 0)).row())

    def selected_entries(self) -> list:
        rows = sorted(index.row() for index in self.selectionModel().selectedRows())
        return [self.entry_at(row) for row in rows]

    def current_entry(self):
        """The one measurement Open means: the current row if it is selected, else the first selected."""
        current = self.currentIndex()
        if current.isValid() and self.selectionModel().isRowSelected(current.row(), QModelIndex()):
            return self.entry_at(current.row())
        selected = self.selected_entries()
        return selected[0] if selected else None
