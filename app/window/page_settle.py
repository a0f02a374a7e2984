"""A page shown in one paint: what Qt would settle over several turns of the event loop, settled at the switch.

Showing a page invalidates layouts in it (each splitter and tab widget asks its parent for room when shown), and Qt
walks such a request up one widget per turn of the event loop: QLayout::activate posts the next request to the
parent. The main window's QTabWidget repaints itself whole at each request it receives, so a click on a page's tab
painted the page two to four times in the next 200 ms. Qt also posts an "update later" to every widget it shows,
and each plot's scene posts its own updates: when the page is painted at once, these arrive afterwards and paint
it again. settle() delivers those posted events at the switch, before the page's first paint, so that the page
is laid out once and painted once.
"""
from __future__ import annotations

from PySide6.QtCore import QCoreApplication, QEvent, QObject
from PySide6.QtWidgets import QAbstractItemView, QGraphicsView, QTabWidget, QWidget

MAX_PASSES = 64         # a layout request climbs one widget per pass; the pages are ~15 widgets deep


class _Counter(QObject):
    """Counts the layout requests delivered (an application-wide filter, installed only while settling)."""

    def __init__(self):
        super().__init__()
        self.count = 0

    def eventFilter(self, watched, event) -> bool:
        if event.type() == QEvent.LayoutRequest:
            self.count += 1
        return False


def settle(page: QWidget) -> int:
    """Deliver the layout requests, the page's plots' scene updates and the update-laters posted so far; returns
    how many passes the layout requests took."""
    app = QCoreApplication.instance()
    counter = _Counter()
    app.installEventFilter(counter)
    try:
        for passes in range(1, MAX_PASSES + 1):
            counter.count = 0
            QCoreApplication.sendPostedEvents(None, QEvent.LayoutRequest)
            if counter.count == 0:
                break
    finally:
        app.removeEventFilter(counter)
    for view in page.findChildren(QAbstractItemView):
        view.executeDelayedItemsLayout()        # laid out now, not by its timer just after the first paint
    for view in page.findChildren(QGraphicsView):
        if view.scene() is not None:
            QCoreApplication.sendPostedEvents(view.scene(), QEvent.MetaCall)     # the scene's own queued updates
    QCoreApplication.sendPostedEvents(None, QEvent.UpdateLater)
    return passes


def settle_on_switch(tabs: QTabWidget) -> None:
    """Settle each page of `tabs` as it is switched to."""
    tabs.currentChanged.connect(lambda _index: settle(tabs.currentWidget()) if tabs.currentWidget() else None)
