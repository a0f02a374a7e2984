"""Plot views whose scene stays as it is when the page holding them is hidden and shown again.

QGraphicsView tells its scene "window activated" each time its viewport is shown and "deactivated" each time it is
hidden. The scene passes that on to every item, and every pyqtgraph item (plot, view box, axes, legend) repaints
and measures its bounds again, in Python: 20-25 ms of the GUI thread's CPU each time the Results page or the
Model lab was shown, before anything was drawn. The plots have no item that takes focus or paints in the
palette's active colours, so nothing changes for them with the scene's activation: the view keeps Show and Hide
to itself.

What the items drew is kept, too. A page shown again is painted whole, and pyqtgraph drew every axis, curve,
point cloud, guide and title again in Python (the Results page's plots 11-12 ms of the GUI thread, the Model
lab's three 8-10 ms). The items that draw something keep it as a pixmap at the screen's resolution
(QGraphicsItem.DeviceCoordinateCache): shown unchanged, a plot is copied from its items' pixmaps. Qt drops an
item's pixmap when the item changes (new data, a zoom, a hover) and draws it again once; the pixmaps live in
QPixmapCache, whose room is raised so that the plots of every page fit in it at once.
"""
from __future__ import annotations

import functools

import pyqtgraph as pg
from PySide6.QtCore import QEvent
from PySide6.QtGui import QPixmapCache
from PySide6.QtWidgets import QAbstractScrollArea, QGraphicsItem, QGraphicsTextItem

# The items that draw: axes (with their grid lines), curves, point clouds, error bars, guides and the texts of
# titles, labels and legends. Containers (plot items, view boxes, layouts, label items) draw nothing of their own:
# a pixmap for them would be an empty one as large as the plot, copied at every paint.
DRAWING_ITEMS = (pg.AxisItem, pg.PlotCurveItem, pg.ScatterPlotItem, pg.ErrorBarItem, pg.InfiniteLine,
                 QGraphicsTextItem)
# Room for the pixmaps, in KiB (Qt's default is 10 MiB, shared with the style's own pixmaps). Each item keeps at
# most its part of the view: in a 1920 x 1080 window one of the Results page's transfer plots keeps ~26 MiB, the
# Model lab's plots ~8 MiB. Beyond the room, the pixmaps used longest ago are dropped and drawn again when needed.
PIXMAP_ROOM_KIB = 128 * 1024
NO_CACHE = QGraphicsItem.NoCache


@functools.cache
def _draws(kind: type) -> bool:
    return issubclass(kind, DRAWING_ITEMS)      # once per class: isinstance on Qt's classes costs ~1.6 us an item


def keep_what_items_draw(scene) -> int:
    """Give the drawing items of `scene` a device-coordinate cache (those that have none yet); returns how many.
    Run at every show of a view (items may have come since): 40-60 us for one of the lab's plots."""
    if QPixmapCache.cacheLimit() < PIXMAP_ROOM_KIB:
        QPixmapCache.setCacheLimit(PIXMAP_ROOM_KIB)
    count = 0
    for item in scene.items():
        # Asked first: setting the mode again would drop the pixmap the item keeps.
        if _draws(type(item)) and item.cacheMode() == NO_CACHE:
            item.setCacheMode(QGraphicsItem.DeviceCoordinateCache)
            count += 1
    return count


class StillScene:
    """Mix into a pyqtgraph view class, before it: class Plot(StillScene, pg.PlotWidget)."""

    def viewportEvent(self, event) -> bool:
        kind = event.type()
        if kind in (QEvent.Show, QEvent.Hide):
            if kind == QEvent.Show and self.scene() is not None:
                keep_what_items_draw(self.scene())     # items added since the last show (an overlaid curve)
            return QAbstractScrollArea.viewportEvent(self, event)     # what QGraphicsView adds is the activation
        return super().viewportEvent(event)


class StillPlotWidget(StillScene, pg.PlotWidget):
    """pg.PlotWidget with a StillScene."""
