"""The parameter table: name, value, 1-sigma and unit in customary units.

Parameters that could not be determined stay in the table (a missing row
would look like an oversight): greyed, with the reason in place of the value
and in full in the tooltip.
"""
from __future__ import annotations

import math
from typing import Mapping

from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QLabel, QTableView, QVBoxLayout, QWidget

from analysis.derived import NO_SD, ParameterValue
from app import style

COLUMNS = ("Parameter", "Value", "±1σ", "Unit")
NAME, VALUE, STD, UNIT = range(4)

# Tooltips for the derived parameters (fitted ones carry their own description).
DERIVED_DESCRIPTIONS = {
    "fs": "resonance frequency, 1 / (2π √(Mms·Cms))",
    "Mms": "moving mass, CMES·Bl²",
    "Rms": "mechanical resistance, Bl² / RES",
    "Cms": "compliance of the suspension, LCES / Bl²",
    "Kms": "stiffness of the suspension, 1 / Cms",
    "Qes": "electrical Q at fs",
    "Qms": "mechanical Q at fs",
    "Qts": "total Q at fs, Qes·Qms / (Qes + Qms)",
    "Vas": "equivalent air volume of the compliance, ρc²Sd²Cms",
    "eta0": "reference efficiency (piston in half space)",
    "SPL_1W_1m": "sensitivity at 1 W into RE, 1 m, half space",
    "SPL_2.83V_1m": "sensitivity at 2.83 V, 1 m, half space",
}


def format_value(p: ParameterValue) -> tuple[str, str]:
    """(value, 1-sigma) in display units, the value rounded to the second digit of its sigma."""
    if p.value is None:
        return "", ""
    value = p.value * p.display_scale
    std = None if p.std is None else p.std * abs(p.display_scale)
    if std is None or not math.isfinite(std) or std <= 0:
        return f"{value:.5g}", "–"
    decimals = max(0, -math.floor(math.log10(std)) + 1)
    if decimals > 9 or abs(value) >= 1e6:
        return f"{value:.6g}", f"{std:.2g}"
    return f"{value:.{decimals}f}", f"{std:.{decimals}f}"

class ParameterModel(QAbstractTableModel):
    def __init__(self, parent=None):
        super().__init__(parent)
        self._rows: list[ParameterValue] = []
        self._descriptions: dict[str, str] = {}
        self._cells: list[list[dict]] = []         # per row and column: role -> value

    def set_parameters(self, parameters: Mapping[str, ParameterValue],
                       descriptions: Mapping[str, str] | None = None) -> None:
        self.beginResetModel()
        self._rows = list(parameters.values())
        self._descriptions = {**DERIVED_DESCRIPTIONS, **(descriptions or {})}
        # Every role of every cell, worked out once: a view asks for each of them on every repaint
        # (some 1,700 calls to show the table), and formatting them each time made up half of the
        # Results page's repaint.
        self._cells = [self._row_roles(p) for p in self._rows]
        self.endResetModel()

    def _row_roles(self, p: ParameterValue) -> list[dict]:
        tooltip = self._tooltip(p)
        cells = []
        for col in range(len(COLUMNS)):
            roles = {Qt.DisplayRole: self._display(p, col), Qt.ToolTipRole: tooltip}
            if p.value is None:
                roles[Qt.ForegroundRole] = QBrush(QColor(style.MISSING_TEXT))
            if col == NAME and p.fitted:
                font = QFont()
                font.setBold(True)      # fitted parameters stand out from the derived ones
                roles[Qt.FontRole] = font
            if col in (VALUE, STD) and p.value is not None:
                roles[Qt.TextAlignmentRole] = int(Qt.AlignRight | Qt.AlignVCenter)
            cells.append(roles)
        return cells

    def parameter(self, row: int) -> ParameterValue:
        return self._rows[row]

    def row_of(self, name: str) -> int:
        for row, p in enumerate(self._rows):
            if p.name == name:
                return row
        raise KeyError(name)

    def rowCount(self, parent=QModelIndex()) -> int:
        return 0 if parent.isValid() else len(self._rows)

    def columnCount(self, parent=QModelIndex()) -> int:
        return 0 if parent.isValid() else len(COLUMNS)

    def headerData(self, section, orientation, role=Qt.DisplayRole):
        if orientation == Qt.Horizontal and role == Qt.DisplayRole:
            return COLUMNS[section]
        return None

    def data(self, index: QModelIndex, role=Qt.DisplayRole):
        if not index.isValid():
            return None
        return self._cells[index.row()][index.column()].get(role)

    def _display(self, p: ParameterValue, col: int) -> str:
        if col == NAME:
            return p.name
        if col == UNIT:
            return p.display_unit
        if p.value is None:
            return f"n/a: {p.reason}" if col == VALUE else ""
        value, std = format_value(p)
        return value if col == VALUE else std

    def _tooltip(self, p: ParameterValue) -> str:
        kind = "fitted" if p.fitted else "derived from the fitted values"
        text = f"{p.name} ({kind})"
        description = self._descriptions.get(p.name)
        if description:
            text += f": {description}"
        if p.value is None:
            text += f"\nNot reported: {p.reason}"
            if p.reason == NO_SD:      # the analysis words it for the command line
                text += "\nIn this window: enter Sd on the Predicted SPL tab."
        return text


class ParameterTable(QTableView):
    """The view: spans the reason of a missing value over the value and sigma columns."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.parameter_model = ParameterModel(self)
        self.setModel(self.parameter_model)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.setAlternatingRowColors(True)
        self.setWordWrap(False)
        self.setTextElideMode(Qt.ElideRight)
        self.verticalHeader().setVisible(False)
        self.verticalHeader().setDefaultSectionSize(self.fontMetrics().height() + 8)
        header = self.horizontalHeader()
        header.setSectionResizeMode(NAME, QHeaderView.ResizeToContents)
        header.setSectionResizeMode(VALUE, QHeaderView.Stretch)
        header.setSectionResizeMode(STD, QHeaderView.ResizeToContents)
        header.setSectionResizeMode(UNIT, QHeaderView.ResizeToContents)
        self.parameter_model.modelReset.connect(self._apply_spans)

    def set_parameters(self, parameters: Mapping[str, ParameterValue],
                       descriptions: Mapping[str, str] | None = None) -> None:
        self.parameter_model.set_parameters(parameters, descriptions)

    def _apply_spans(self) -> None:
        self.clearSpans()
        for row in range(self.parameter_model.rowCount()):
            if self.parameter_model.parameter(row).value is None:
                self.setSpan(row, VALUE, 1, 2)


def titled_parameter_table(title_html: str) -> tuple[QWidget, "ParameterTable"]:
    """A ParameterTable under a bold title, in a box for a splitter: (box, table)."""
    table = ParameterTable()
    box = QWidget()
    layout = QVBoxLayout(box)
    layout.setContentsMargins(0, 0, 0, 0)
    title = QLabel(title_html)
    title.setWordWrap(True)
    layout.addWidget(title)
    layout.addWidget(table, 1)
    return box, table
