"""A plot view hidden and shown again leaves its scene alone, and its items keep what they drew
(app/widgets/still_scene.py)."""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QEvent
from PySide6.QtGui import QImage, QPixmapCache
from PySide6.QtWidgets import QApplication, QGraphicsItem, QGraphicsWidget, QLabel, QTabWidget

from app.results.curves import ChannelCurves
from app.widgets import style
from app.widgets.plots import TransferPlot
from app.widgets.still_scene import DRAWING_ITEMS, PIXMAP_ROOM_KIB, StillScene
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


def _impedance_curves() -> ChannelCurves:
    """A driver's impedance with a resonance and an inductive rise, residuals of unit size."""
    freqs, dense = np.geomspace(5, 2e4, 300), np.geomspace(5, 2e4, 1000)

    def z(f):
        return 6 + 20 / (1 + 1j * (f / 40 - 40 / f)) + 1j * f * 3e-4
    real, imag = np.random.default_rng(1).normal(size=(2, freqs.size))
    return ChannelCurves("impedance", freqs, z(freqs), np.full(freqs.size, 0.05), real + 1j * imag, 1.1, dense, z(dense))


def _impedance_plot() -> TransferPlot:
    plot = TransferPlot("|Z| (Ω)", 1.0, log_y=False)
    plot.set_curves(_impedance_curves(), "impedance")
    return plot


def _shown_on_a_tab(qtbot, plot, size: tuple[int, int] | None = None) -> QTabWidget:
    """`plot` on the second tab of a tab widget of `size`, shown with that tab current (the first is another
    page)."""
    tabs = QTabWidget()
    qtbot.addWidget(tabs)
    tabs.addTab(QLabel("another page"), "other")
    tabs.addTab(plot, "plot")
    if size is not None:
        tabs.resize(*size)
    tabs.show()
    tabs.setCurrentIndex(1)
    QApplication.processEvents()
    return tabs


def _pixels(widget) -> np.ndarray:
    image = widget.grab().toImage().convertToFormat(QImage.Format_RGB32)
    rows = np.frombuffer(image.constBits(), np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, :4 * image.width()].reshape(image.height(), image.width(), 4).astype(int)


def test_a_shown_plot_is_drawn_from_its_items_pixmaps_and_looks_as_drawn_directly(qtbot):
    style.configure_pyqtgraph()
    plot = _impedance_plot()
    tabs = _shown_on_a_tab(qtbot, plot, (900, 650))

    items = plot.scene().items()
    drawing = [item for item in items if isinstance(item, DRAWING_ITEMS)]
    assert len(drawing) >= 20          # axes, curves, points, error bars, guides, titles
    assert all(item.cacheMode() == QGraphicsItem.DeviceCoordinateCache for item in drawing)
    # Containers draw nothing: no pixmap as large as the plot for them.
    assert all(item.cacheMode() == QGraphicsItem.NoCache for item in items if not isinstance(item, DRAWING_ITEMS))
    assert QPixmapCache.cacheLimit() >= PIXMAP_ROOM_KIB

    tabs.setCurrentIndex(0)
    QApplication.processEvents()
    tabs.setCurrentIndex(1)
    QApplication.processEvents()
    from_pixmaps = _pixels(plot)
    for item in drawing:
        item.setCacheMode(QGraphicsItem.NoCache)
    drawn = _pixels(plot)
    # Qt truncates a pixmap's exposed rectangle to whole pixels: an axis may lose the pixel at its end.
    visibly_different = (np.abs(from_pixmaps - drawn).max(axis=2) > 8).sum()
    assert visibly_different <= 4, f"{visibly_different} pixels differ"
    assert (drawn[..., :3] < 128).sum() > 5000       # the plot has lines and points to compare


def test_an_item_added_after_the_first_show_keeps_what_it_drew_from_the_next_show(qtbot):
    plot = _impedance_plot()
    tabs = _shown_on_a_tab(qtbot, plot)
    plot.set_reference(np.geomspace(5, 2e4, 50), np.full(50, 7.0), "the other tool's fit")
    added = plot.magnitude_reference.curve
    assert added.cacheMode() == QGraphicsItem.NoCache
    tabs.setCurrentIndex(0)
    tabs.setCurrentIndex(1)
    assert added.cacheMode() == QGraphicsItem.DeviceCoordinateCache
