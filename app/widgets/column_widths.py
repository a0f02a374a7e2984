"""Columns as wide as their contents, measured when the contents change rather than each time they are shown.

A column in QHeaderView.ResizeToContents mode is measured again, row by row through the item delegate, each time
its header is shown: every switch to the Model lab measured the candidates, the parameters and the catalogue's
ids again (0.7-1.2 ms of the GUI thread per table, with the relayout it set off, for widths that had not
changed). Such columns are Interactive instead, and the code that fills the view sizes them to what it put in.
The user may drag them wider or narrower.
"""
from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableView, QTreeView


def header_of(view: QAbstractItemView) -> QHeaderView:
    """The header whose sections are the view's columns."""
    if isinstance(view, QTableView):
        return view.horizontalHeader()
    if isinstance(view, QTreeView):
        return view.header()
    raise TypeError(f"{type(view).__name__} has no column header")


def sized_when_filled(view: QAbstractItemView, columns: Iterable[int]) -> None:
    """`columns` of `view` are sized by fit_to_contents when filled, never measured again by Qt on a show."""
    header = header_of(view)
    for column in columns:
        header.setSectionResizeMode(column, QHeaderView.Interactive)


def fit_to_contents(view: QAbstractItemView, columns: Iterable[int]) -> None:
    """Each of `columns` as wide as its widest cell or its header's title: what ResizeToContents made it."""
    for column in columns:
        view.resizeColumnToContents(column)
