"""The parameter table: name, value, 1-sigma and unit in customary units.

The Thiele-Small parameters come first, in the order a speaker engineer reads
them; the model's own quantities (CMES, LCES, RES, L2, ...) follow under a
section row that folds them away. Values are rounded to what their
uncertainty supports, at most 4 significant digits unless "All digits" is on.

Parameters that could not be determined stay in the table (a missing row
would look like an oversight): greyed, with the reason in place of the value
and in full in the tooltip.
"""
from __future__ import annotations

import functools
import math
from typing import Mapping

import numpy as np

from PySide6.QtCore import QModelIndex, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont, QStandardItem, QStandardItemModel
from PySide6.QtWidgets import (QAbstractItemView, QCheckBox, QHBoxLayout, QHeaderView, QLabel, QTableView,
                               QVBoxLayout, QWidget)

from analysis.derived import NO_SD, ParameterValue
from analysis.parameter_names import DISPLAY_NAMES, THIELE_SMALL, display_name  # noqa: F401 (shared)
from analysis.report.numbers import pretty_unit, short_number
from app.widgets import style
from app.widgets.column_widths import fit_to_contents, sized_when_filled

COLUMNS = ("Parameter", "Value", "±1σ", "Unit")
NAME, VALUE, STD, UNIT = range(4)
SIZED_COLUMNS = (NAME, STD, UNIT)       # as wide as their contents (the name gives way when room is short)
MIN_NAME_WIDTH = 40                     # px: a name never elides to less than its first letters

INTERNAL_TITLE = "Model's internal quantities"
DEFAULT_DIGITS = 4          # significant digits shown unless "All digits" is on

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
    "Sd": "effective radiating area of the diaphragm (given, not measured)",
}


def ordered_rows(parameters: Mapping[str, ParameterValue], sd_m2: float | None = None) -> list:
    """Thiele-Small parameters first, then a section title (a str) and the model's internal quantities."""
    named = dict(parameters)
    if sd_m2:
        named["Sd"] = ParameterValue(name="Sd", value=sd_m2, std=None, unit="m^2", display_unit="cm²",
                                     display_scale=1e4)
    rows: list = [named[n] for n in THIELE_SMALL if n in named]
    internal = [p for n, p in named.items() if n not in THIELE_SMALL]
    if internal:
        rows.append(INTERNAL_TITLE)
        rows.extend(internal)
    return rows


def format_value(p: ParameterValue, all_digits: bool = True) -> tuple[str, str]:
    """(value, 1-sigma) in display units, the value rounded to the second digit of its sigma.

    all_digits=False: at most DEFAULT_DIGITS significant digits, fewer when the sigma allows fewer.
    """
    if p.value is None:
        return "", ""
    if not all_digits:
        return short_value(p)
    value = p.value * p.display_scale
    std = None if p.std is None else p.std * abs(p.display_scale)
    if std is None or not math.isfinite(std) or std <= 0:
        return f"{value:.5g}", "–"
    decimals = max(0, -math.floor(math.log10(std)) + 1)
    if decimals > 9 or abs(value) >= 1e6:
        return f"{value:.6g}", f"{std:.2g}"
    return f"{value:.{decimals}f}", f"{std:.{decimals}f}"


def uncertainty_parts(p: ParameterValue) -> str:
    """"±0.12 g noise, ±0.9 g model": the two parts of the uncertainty where the analysis estimated them, or ""."""
    unit = pretty_unit(p.display_unit)
    unit = "" if unit in ("", "-", "1") else f" {unit}"
    parts = [f"±{std * abs(p.display_scale):.2g}{unit} {what}" for std, what in ((p.std_noise, "noise"),
                                                                                (p.std_model, "model"))
             if std is not None and math.isfinite(std)]
    return ", ".join(parts)


# The parameters whose two parts the line under the table names (every row's are in its tooltip).
PARTS_NAMED = ("RE", "Bl", "Mms", "Kms", "fs", "Qts")


def parts_summary(parameters: Mapping[str, ParameterValue]) -> str:
    """"Of each ±1σ (noise and model): Mms ±0.12 g noise, ±0.9 g model; ...", or "" when no part was estimated."""
    named = [f"{display_name(name)} {uncertainty_parts(parameters[name])}" for name in PARTS_NAMED
             if name in parameters and parameters[name].value is not None and parameters[name].std_model is not None]
    return ("Of each ±1σ, the noise's part and the model's (what the model misses): " + "; ".join(named)
            if named else "")


def value_with_unit(p: ParameterValue) -> str:
    """"3.02 Ω": the value as the table rounds it (at most 4 digits) and its unit, for a page with one cell."""
    if p.value is None:
        return "not measured"
    unit = "" if p.display_unit in ("1", "-") else pretty_unit(p.display_unit)
    return f"{short_value(p)[0]} {unit}".rstrip()


def short_value(p: ParameterValue) -> tuple[str, str]:
    """(value, 1-sigma): as many significant digits as the sigma supports (its second digit), at most 4;
    the sigma with 2 significant digits, written out without an exponent."""
    value = p.value * p.display_scale
    std = None if p.std is None else p.std * abs(p.display_scale)
    known = std is not None and math.isfinite(std) and std > 0
    std_text = (np.format_float_positional(std, precision=2, unique=False, fractional=False, trim="-")
                if known else "–")
    return short_number(value, std if known else None, DEFAULT_DIGITS), std_text


def shared_reason(rows) -> str:
    """The one reason every parameter row went unmeasured for (a broken lead: nothing fitted), or "": the table
    says it once instead of in each row's cell, truncated."""
    reasons = {p.reason or "" for p in rows if not isinstance(p, str) and p.name != "Sd"}
    unmeasured = all(p.value is None for p in rows if not isinstance(p, str) and p.name != "Sd")
    return reasons.pop() if unmeasured and len(reasons) == 1 else ""


# PySide's enums are looked up and combined in Python (~1 us each): worked out once here, not for each of ~90
# cells at every fill.
READ_ONLY = Qt.ItemIsSelectable | Qt.ItemIsEnabled         # as a read-only table model's cells
RIGHT = int(Qt.AlignRight | Qt.AlignVCenter)
DISPLAY, TOOLTIP, FONT, FOREGROUND, ALIGNMENT = (Qt.DisplayRole, Qt.ToolTipRole, Qt.FontRole, Qt.ForegroundRole,
                                                 Qt.TextAlignmentRole)


@functools.cache
def _bold() -> QFont:
    """The bold font of fitted parameters and section titles (one, made when first needed: after the QApplication)."""
    font = QFont()
    font.setBold(True)
    return font


def _item(roles: dict) -> QStandardItem:
    item = QStandardItem()
    item.setFlags(READ_ONLY)
    for role, value in roles.items():
        item.setData(value, role)
    return item


def _row_shape(p) -> tuple:
    """What of a row decides more than its numbers: its kind, font, colour, alignment and span."""
    return (p,) if isinstance(p, str) else (p.name, p.fitted, p.value is None)


class ParameterModel(QStandardItemModel):
    """Every role of every cell worked out once and kept by Qt: a view asks for each of them on every repaint
    (some 1,700 calls to show the table). Formatting them each time made up half of the Results page's repaint;
    answering from Python still took 5-8 ms of it, the calls themselves."""

    numbers_changed = Signal()          # the same rows with new numbers (no modelReset): the widths may change

    def __init__(self, parent=None):
        super().__init__(0, len(COLUMNS), parent)
        self.setHorizontalHeaderLabels(list(COLUMNS))
        self._rows: list = []                      # ParameterValue, or a section title (str)
        self._descriptions: dict[str, str] = {}
        self._parameters: Mapping[str, ParameterValue] = {}
        self._sd_m2: float | None = None
        self.all_digits = False
        self.common_reason = ""         # every row unmeasured for one reason: said once above the table

    def set_parameters(self, parameters: Mapping[str, ParameterValue],
                       descriptions: Mapping[str, str] | None = None, sd_m2: float | None = None) -> None:
        rows = ordered_rows(parameters, sd_m2)
        descriptions = {**DERIVED_DESCRIPTIONS, **(descriptions or {})}
        shape = [_row_shape(p) for p in rows]
        same_shape = shape == [_row_shape(p) for p in self._rows] and shared_reason(rows) == self.common_reason
        self._parameters, self._sd_m2, self._rows, self._descriptions = parameters, sd_m2, rows, descriptions
        if same_shape and rows:
            self._set_numbers()
            return
        self.beginResetModel()
        self.common_reason = shared_reason(self._rows)
        # Filled inside the reset, quietly: the views hear of the new table once, by modelReset.
        quiet = self.blockSignals(True)
        try:
            self.setRowCount(0)
            for cells in (self._row_roles(p) for p in self._rows):
                self.appendRow([_item(roles) for roles in cells])
        finally:
            self.blockSignals(quiet)
        self.endResetModel()

    def set_all_digits(self, on: bool) -> None:
        self.all_digits = on
        self.set_parameters(self._parameters, self._descriptions, self._sd_m2)

    def _set_numbers(self) -> None:
        """The same rows with new numbers (a refit of the same model, the model part arrived, Sd edited): only the
        texts that changed are set, in the cells there are, and the views hear of it once (dataChanged). A new
        table of items and the reset that re-laid the view out held the GUI thread 6-8 ms at every refit."""
        quiet = self.blockSignals(True)
        try:
            for row, p in enumerate(self._rows):
                if isinstance(p, str):          # a section title: the same words
                    continue
                tooltip = self._tooltip(p)
                for column in range(len(COLUMNS)):
                    item = self.item(row, column)
                    for role, value in ((DISPLAY, self._display(p, column)), (TOOLTIP, tooltip)):
                        if item.data(role) != value:
                            item.setData(value, role)
        finally:
            self.blockSignals(quiet)
        self.dataChanged.emit(self.index(0, 0), self.index(self.rowCount() - 1, len(COLUMNS) - 1))
        self.numbers_changed.emit()

    def is_section(self, row: int) -> bool:
        return isinstance(self._rows[row], str)

    def _row_roles(self, p) -> list[dict]:
        if isinstance(p, str):          # a section title over the rows below it
            tip = ("What the model computes with: the Thiele-Small parameters above derive from them. "
                   "Click to fold them away or show them.")
            return [{DISPLAY: f"▾ {p}" if col == NAME else "", FONT: _bold(), TOOLTIP: tip}
                    for col in range(len(COLUMNS))]
        tooltip = self._tooltip(p)
        cells = []
        for col in range(len(COLUMNS)):
            roles = {DISPLAY: self._display(p, col), TOOLTIP: tooltip}
            if p.value is None:
                roles[FOREGROUND] = QBrush(QColor(style.MISSING_TEXT))
            if col == NAME and p.fitted:
                roles[FONT] = _bold()       # fitted parameters stand out from the derived ones
            if col in (VALUE, STD) and p.value is not None:
                roles[ALIGNMENT] = RIGHT
            cells.append(roles)
        return cells

    def parameter(self, row: int) -> ParameterValue | None:
        """The row's parameter (None for a section row)."""
        p = self._rows[row]
        return None if isinstance(p, str) else p

    def row_of(self, name: str) -> int:
        for row, p in enumerate(self._rows):
            if not isinstance(p, str) and p.name == name:
                return row
        raise KeyError(name)

    def _display(self, p: ParameterValue, col: int) -> str:
        if col == NAME:
            return display_name(p.name)
        if col == UNIT:
            return pretty_unit(p.display_unit)
        if p.value is None:
            if col != VALUE:
                return ""
            return "not measured" if self.common_reason else f"n/a: {p.reason}"
        value, std = format_value(p, self.all_digits)
        return value if col == VALUE else std

    def _tooltip(self, p: ParameterValue) -> str:
        kind = "given" if p.name == "Sd" else ("fitted" if p.fitted else "derived from the fitted values")
        text = f"{display_name(p.name)} ({kind})"
        description = self._descriptions.get(p.name)
        if description:
            text += f": {description}"
        if p.value is not None:
            value, std = format_value(p, all_digits=True)
            unit = pretty_unit(p.display_unit)
            spread = f" ± {std}" if std not in ("", "–") else ""
            text += f"\n= {value}{spread} {unit}".rstrip()
            parts = uncertainty_parts(p)
            if parts:
                text += f"\nof which {parts}"
            if spread:
                text += "\n± is one standard deviation: the true value lies within it with about 68 % probability."
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
        self.horizontalHeader().setSectionResizeMode(VALUE, QHeaderView.Stretch)
        sized_when_filled(self, SIZED_COLUMNS)       # measured at each fill, not at each show of the page
        self._name_width = self._value_width = 0     # what the names and values need, measured at each fill
        self._fit_columns()                          # empty: as wide as their titles
        self.internal_folded = False
        self.parts_label: QLabel | None = None      # the line under the table that names the parts (titled_...)
        self.parameter_model.modelReset.connect(self._apply_spans)
        self.parameter_model.numbers_changed.connect(self._fit_number_columns)
        self.clicked.connect(self._on_clicked)

    def set_parameters(self, parameters: Mapping[str, ParameterValue],
                       descriptions: Mapping[str, str] | None = None, sd_m2: float | None = None) -> None:
        self.parameter_model.set_parameters(parameters, descriptions, sd_m2)
        if self.parts_label is not None:
            summary = parts_summary(parameters)
            self.parts_label.setText(summary)
            self.parts_label.setVisible(bool(summary))

    def set_all_digits(self, on: bool) -> None:
        self.parameter_model.set_all_digits(on)

    def _apply_spans(self) -> None:
        self.clearSpans()
        model = self.parameter_model
        below_section = False
        for row in range(model.rowCount()):
            if model.is_section(row):
                self.setSpan(row, NAME, 1, len(COLUMNS))
                below_section = True
                continue
            self.setRowHidden(row, below_section and self.internal_folded)
            if model.parameter(row).value is None:
                self.setSpan(row, VALUE, 1, 2)
        self._fit_columns()                         # the rows shown changed: the widths they need, once

    def _fit_columns(self) -> None:
        """Measure what the names and values need (once per fill) and share the width by it."""
        fit_to_contents(self, SIZED_COLUMNS)
        self._name_width = self.columnWidth(NAME)
        self._value_width = max(self.sizeHintForColumn(VALUE), self.horizontalHeader().sectionSizeHint(VALUE))
        self._share_width()

    def _fit_number_columns(self) -> None:
        """_fit_columns for new numbers in the same rows: the names and units are as wide as they were."""
        fit_to_contents(self, (STD,))
        self._value_width = max(self.sizeHintForColumn(VALUE), self.horizontalHeader().sectionSizeHint(VALUE))
        self._share_width()

    def _share_width(self) -> None:
        """The names as wide as they need, unless the values would then not fit whole: then the names give way
        (eliding; the tooltip has them). The value column takes what is left, so a reason spanned over it and
        the sigma has the room there is. A value elided read "0.4…" for Qts in a narrow Model lab."""
        room = self.viewport().width() - self._value_width - self.columnWidth(STD) - self.columnWidth(UNIT)
        name = max(MIN_NAME_WIDTH, min(self._name_width, room))
        if name != self.columnWidth(NAME):
            self.setColumnWidth(NAME, name)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._share_width()

    def sizeHintForColumn(self, column: int) -> int:
        """The widest cell of the column that has it alone: a section title and the reason of a missing value
        span columns (and elide when the spanned columns are narrow; their tooltips hold them whole), so they
        do not widen the one they start in."""
        model = self.parameter_model
        widest = 0
        for row in range(model.rowCount()):
            if self.isRowHidden(row) or self.columnSpan(row, column) > 1 or self.rowSpan(row, column) > 1:
                continue
            widest = max(widest, self.sizeHintForIndex(model.index(row, column)).width())
        return widest + (1 if self.showGrid() else 0)       # as QTableView's own: the grid line

    def _on_clicked(self, index: QModelIndex) -> None:
        if index.isValid() and self.parameter_model.is_section(index.row()):
            self.internal_folded = not self.internal_folded
            self._apply_spans()


def titled_parameter_table(title_html: str) -> tuple[QWidget, "ParameterTable"]:
    """A ParameterTable under a bold title and its "All digits" switch, in a box for a splitter: (box, table)."""
    table = ParameterTable()
    box = QWidget()
    layout = QVBoxLayout(box)
    layout.setContentsMargins(0, 0, 0, 0)
    title = QLabel(title_html)
    title.setWordWrap(True)
    all_digits = QCheckBox("All digits")
    all_digits.setToolTip("Show every digit the uncertainty supports (to its second digit) instead of at most "
                          f"{DEFAULT_DIGITS} significant digits")
    all_digits.toggled.connect(table.set_all_digits)
    table.all_digits_box = all_digits
    note = QLabel()                     # the one reason nothing was measured, when that is so
    note.setWordWrap(True)
    note.setTextFormat(Qt.PlainText)
    note.hide()
    table.note = note

    def show_note():
        reason = table.parameter_model.common_reason
        note.setText(f"Not measured: {reason}" if reason else "")
        note.setVisible(bool(reason))
    table.parameter_model.modelReset.connect(show_note)
    top = QHBoxLayout()
    top.addWidget(title, 1)
    top.addWidget(all_digits)
    layout.addLayout(top)
    layout.addWidget(note)
    layout.addWidget(table, 1)
    parts = QLabel()
    parts.setWordWrap(True)
    parts.setTextFormat(Qt.PlainText)
    parts.hide()
    table.parts_label = parts
    layout.addWidget(parts)
    return box, table
