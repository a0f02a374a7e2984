"""Grid lines that are cheap to draw: opaque colours, behind the data.

pyqtgraph draws its grid lines translucent (an alpha per tick level). On
Qt's raster engine a translucent line costs ten to twenty times an opaque
one, and the grid was most of every plot's repaint: showing the Results page
or the Model lab took 100-150 ms, the live panels a third of theirs. Over the
plain background a translucent line looks exactly like an opaque one of the
blended colour, so OpaqueGridAxis draws that; show_grid puts the axes behind
the data, so a grid line never crosses a point or the model's line.
"""
from __future__ import annotations

import pyqtgraph as pg
from PySide6.QtGui import QColor, QPen

GRID_ALPHA = 0.25           # pyqtgraph's grid strength (0..1), as the plots had it
BEHIND_THE_DATA = -1.0      # z value of the axes: the view box (and so the data) sits at 0


class OpaqueGridAxis(pg.AxisItem):
    """pyqtgraph's axis with its tick and grid lines in opaque colours, pre-blended with the background."""

    def generateDrawSpecs(self, p):
        specs = super().generateDrawSpecs(p)
        background = _background()
        if specs is None or background is None:
            return specs
        axis_spec, tick_specs, text_specs = specs
        return axis_spec, [(opaque_pen(pen, background), a, b) for pen, a, b in tick_specs], text_specs


def opaque_pen(pen: QPen, background: QColor) -> QPen:
    """`pen` with its colour laid over `background`: the colour a translucent line shows there."""
    colour = pen.color()
    alpha = colour.alphaF()
    if alpha >= 1.0:
        return pen

    def blend(fore: float, back: float) -> float:
        return alpha * fore + (1.0 - alpha) * back

    out = QPen(pen)
    out.setColor(QColor.fromRgbF(blend(colour.redF(), background.redF()),
                                 blend(colour.greenF(), background.greenF()),
                                 blend(colour.blueF(), background.blueF())))
    return out


def _background() -> QColor | None:
    """The plots' background colour, or None when it is not one opaque colour (then nothing is blended)."""
    option = pg.getConfigOption("background")
    if option is None:
        return None
    colour = pg.mkColor(option)
    return colour if colour.alphaF() >= 1.0 else None


def show_grid(plot: pg.PlotItem, x: bool = True, y: bool = True) -> None:
    """A grid on `plot` drawn by OpaqueGridAxis axes (default axes are replaced), behind the data."""
    for name in ("left", "bottom"):
        old = plot.getAxis(name)
        if not isinstance(old, OpaqueGridAxis):
            axis = OpaqueGridAxis(name)
            plot.setAxisItems({name: axis})
            axis.setLogMode(old.logMode)        # a plot already in log mode keeps it on the new axis
    plot.showGrid(x=x, y=y, alpha=GRID_ALPHA)
    for name in ("left", "bottom"):
        plot.getAxis(name).setZValue(BEHIND_THE_DATA)
