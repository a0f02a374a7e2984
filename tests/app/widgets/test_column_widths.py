"""Columns sized to their contents when filled, and not measured again when shown (app/widgets/column_widths.py)."""
from __future__ import annotations

import pytest
from PySide6.QtGui import QStandardItem, QStandardItemModel
from PySide6.QtWidgets import QApplication, QHeaderView, QLabel, QListView, QTableView, QTabWidget, QTreeView

from app.widgets.column_widths import fit_to_contents, header_of, sized_when_filled


class MeasuredTable(QTableView):
    """Counts how often Qt measures a column's contents."""

    def __init__(self):
        super().__init__()
        self.measured = 0

    def sizeHintForColumn(self, column: int) -> int:
        self.measured += 1
        return super().sizeHintForColumn(column)


def _filled(table: QTableView, rows: list[list[str]]) -> None:
    model = QStandardItemModel(0, 3, table)
    model.setHorizontalHeaderLabels(["Name", "Value", "Unit"])
    for row in rows:
        model.appendRow([QStandardItem(text) for text in row])
    table.setModel(model)


def _shown_and_hidden(qtbot, table, times: int) -> None:
    tabs = QTabWidget()
    qtbot.addWidget(tabs)           # and the table with it
    tabs.addTab(QLabel("another page"), "other")
    tabs.addTab(table, "table")
    tabs.show()
    for _ in range(times):
        tabs.setCurrentIndex(1)
        QApplication.processEvents()
        tabs.setCurrentIndex(0)
        QApplication.processEvents()


@pytest.mark.parametrize("mode", ["resize-to-contents", "sized-when-filled"])
def test_a_table_sized_when_filled_is_not_measured_again_each_time_it_is_shown(qtbot, mode):
    table = MeasuredTable()
    _filled(table, [["Re", "6.02", "Ω"], ["a rather long parameter name", "1.5", "mH"]])
    if mode == "resize-to-contents":        # Qt's way, for contrast: the test must see the measuring there
        table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
    else:
        sized_when_filled(table, (0, 2))
        fit_to_contents(table, (0, 2))
    before = table.measured
    _shown_and_hidden(qtbot, table, 4)
    if mode == "resize-to-contents":
        assert table.measured >= before + 4
    else:
        assert table.measured == before


def test_fit_to_contents_makes_a_column_as_wide_as_its_widest_cell_or_title(qtbot):
    table = QTableView()
    qtbot.addWidget(table)
    _filled(table, [["Re", "6.02", "Ω"], ["a rather long parameter name", "1.5", "mH"]])
    sized_when_filled(table, (0, 2))
    fit_to_contents(table, (0, 2))
    header = table.horizontalHeader()
    assert header.sectionResizeMode(0) == QHeaderView.Interactive
    assert table.columnWidth(0) >= table.sizeHintForColumn(0) > table.fontMetrics().horizontalAdvance("a rather")
    assert table.columnWidth(2) >= header.sectionSizeHint(2)       # "Unit" is wider than "Ω" and "mH"
    table.model().item(0, 2).setText("a unit wider than its title")
    fit_to_contents(table, (2,))
    assert table.columnWidth(2) >= table.fontMetrics().horizontalAdvance("a unit wider than its title")


def test_the_header_of_a_table_a_tree_and_nothing_else(qtbot):
    table, tree = QTableView(), QTreeView()
    assert header_of(table) is table.horizontalHeader()
    assert header_of(tree) is tree.header()
    with pytest.raises(TypeError, match="QListView"):
        header_of(QListView())
