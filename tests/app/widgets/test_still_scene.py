"""A plot view hidden and shown again leaves its scene alone (app/widgets/still_scene.py)."""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent
from PySide6.QtWidgets import QApplication, QGraphicsWidget, QLabel, QTabWidget

from app.widgets.plots import TransferPlot
from app.widgets.still_scene import StillScene
from tests.pace import wait_ms


class ActivationWitness(QGraphicsWidget):
    """An item that notes the (de)activations its scene passes on."""

    def __init__(self):
        super().__init__()
        self.seen = []

    def event(self, event) -> bool:
        if event.type() in (QEvent.WindowActivate, QEvent.WindowDeactivate):
            self.seen.append(event.type())
        return super().event(event)


class PlainPlot(pg.PlotWidget):
    """pyqtgraph's own view, for contrast: the witness must see something there, or the test proves nothing."""


def _switch_back_and_forth(qtbot, view, times: int = 3) -> ActivationWitness:
    witness = ActivationWitness()
    view.scene().addItem(witness)
    tabs = QTabWidget()
    qtbot.addWidget(tabs)
    tabs.addTab(QLabel("another page"), "other")
    tabs.addTab(view, "plot")
    tabs.show()
    tabs.activateWindow()
    qtbot.waitUntil(tabs.isActiveWindow, timeout=wait_ms(10))
    for _ in range(times):
        tabs.setCurrentIndex(1)
        QApplication.processEvents()
        tabs.setCurrentIndex(0)
        QApplication.processEvents()
    return witness


def test_showing_a_still_scene_view_does_not_activate_its_scene(qtbot):
    plot = TransferPlot("|Z| (Ω)", 1.0, log_y=False)
    plot.magnitude_measured.setData(np.geomspace(5, 1e4, 50), np.linspace(3, 30, 50))
    assert isinstance(plot, StillScene)
    assert _switch_back_and_forth(qtbot, plot).seen == []


def test_pyqtgraphs_own_view_does_activate_its_scene(qtbot):
    assert _switch_back_and_forth(qtbot, PlainPlot()).seen != []
