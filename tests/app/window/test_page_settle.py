"""A page switched to is laid out and painted once (app/window/page_settle.py).

Counted, not timed: the paints the page and its impedance plot receive from the click until the event loop has
nothing left to do, with the page painted at once as the GUI bench does (window.repaint()). Before the fix the
Results page was painted twice in that span and again twice in the next 200 ms.
"""
from __future__ import annotations

from PySide6.QtCore import QEvent, QObject
from PySide6.QtWidgets import QApplication

from app.window.page_settle import MAX_PASSES, settle
from tests.app.conftest import open_and_wait
from tests.pace import wait_ms

QUIET_TURNS = 20        # turns of the event loop after the switch in which nothing may paint again


class PaintCounter(QObject):
    def __init__(self, *widgets):
        super().__init__()
        self.counts = {id(w): 0 for w in widgets}
        for w in widgets:
            w.installEventFilter(self)

    def eventFilter(self, watched, event) -> bool:
        if event.type() == QEvent.Paint and id(watched) in self.counts:
            self.counts[id(watched)] += 1
        return False

    def of(self, widget) -> int:
        return self.counts[id(widget)]


def _drain(turns: int = QUIET_TURNS) -> None:
    for _ in range(turns):
        QApplication.processEvents()


def test_the_results_page_and_the_model_lab_are_painted_once_per_switch(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["paper"], signal="model_part_shown")
    qtbot.waitUntil(lambda: not window.busy and window.model_lab.current is not None, timeout=wait_ms(30))
    pages = {window.results: window.results.impedance_plot.viewport(),
             window.model_lab: window.model_lab.residual_panel.impedance.viewport()}
    for page, plot in pages.items():
        window.pages.setCurrentWidget(page)     # a page's first showing also polishes it and sizes its splitters
        _drain()
        for _ in range(2):
            window.pages.setCurrentWidget(window.wizard)
            _drain()
            counter = PaintCounter(page, plot)
            window.pages.setCurrentWidget(page)
            window.repaint()
            _drain()
            assert (counter.of(page), counter.of(plot)) == (1, 1), type(page).__name__


def test_settling_ends_when_no_layout_request_is_left(qtbot, window):
    window.pages.setCurrentWidget(window.results)
    _drain()
    assert settle(window.results) == 1          # nothing was pending: one pass that found nothing
    window.pages.setCurrentWidget(window.model_lab)
    window.model_lab.updateGeometry()           # a request that climbs to the window
    assert 1 < settle(window.model_lab) < MAX_PASSES
