"""Plot views whose scene stays as it is when the page holding them is hidden and shown again.

QGraphicsView tells its scene "window activated" each time its viewport is shown and "deactivated" each time it is
hidden. The scene passes that on to every item, and every pyqtgraph item (plot, view box, axes, legend) repaints
and measures its bounds again, in Python: 20-25 ms of the GUI thread's CPU each time the Results page or the
Model lab was shown, before anything was drawn. The plots have no item that takes focus or paints in the
palette's active colours, so nothing changes for them with the scene's activation: the view keeps Show and Hide
to itself.
"""
from __future__ import annotations

import pyqtgraph as pg
from PySide6.QtCore import QEvent
from PySide6.QtWidgets import QAbstractScrollArea


class StillScene:
    """Mix into a pyqtgraph view class, before it: class Plot(StillScene, pg.PlotWidget)."""

    def viewportEvent(self, event) -> bool:
        if event.type() in (QEvent.Show, QEvent.Hide):
            return QAbstractScrollArea.viewportEvent(self, event)     # what QGraphicsView adds is the activation
        return super().viewportEvent(event)


class StillPlotWidget(StillScene, pg.PlotWidget):
    """pg.PlotWidget with a StillScene."""
