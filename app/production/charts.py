"""The Production page's plots: the individuals and moving-range chart with its alarms, and the histogram with
the limits. Values in the parameter's customary unit; the chart's x axis is the unit's number in the selection.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

from app.widgets import style
from app.widgets.grid_axis import OpaqueGridAxis, show_grid
from app.results.parameter_table import display_name

ALARM = "#c62828"
CONTROL = "#8e5bb5"          # control limits (the process)
SPEC = "#2e7d32"             # specification limits (the product)
LEFT_AXIS_WIDTH = 64


class UnitAxis(OpaqueGridAxis):
    """Unit numbers: whole units only (pyqtgraph put ticks at 0.5, 1.5, ... on a chart of 4 units)."""

    def tickValues(self, minVal, maxVal, size):
        levels = [(spacing, [v for v in values if float(v).is_integer()])
                  for spacing, values in super().tickValues(minVal, maxVal, size) if spacing >= 1]
        levels = [(spacing, values) for spacing, values in levels if values]
        if not levels:
            levels = [(1.0, [float(v) for v in range(int(np.ceil(minVal)), int(np.floor(maxVal)) + 1)])]
        return levels


def _axes():
    return {"left": OpaqueGridAxis("left"), "bottom": UnitAxis("bottom")}


RIGHT_MARGIN = 0.14          # room right of the last unit for the lines' labels, clear of the points


def _hline(plot, y, colour, dashed=True, label=""):
    """A horizontal line; its name goes to the plot's MarginLabels (InfiniteLine's own labels overlapped
    where two lines were close, and the top line's was cut at the plot's edge)."""
    pen = pg.mkPen(colour, width=1.5, style=Qt.DashLine if dashed else Qt.SolidLine)
    line = pg.InfiniteLine(pos=y, angle=0, pen=pen)
    plot.addItem(line)
    if label:
        plot.margin_labels.add(label, y, colour)
    return line


class MarginLabels:
    """The horizontal lines' names at the plot's right edge, each beside its line where there is room, pushed
    apart (and inside the plot) where lines lie closer than a line of text; placed again on every resize."""

    def __init__(self, plot):
        self.plot = plot
        self.items: list[tuple[pg.TextItem, float]] = []
        plot.getViewBox().sigResized.connect(self.place)
        plot.getViewBox().sigRangeChanged.connect(self.place)

    def clear(self) -> None:
        self.items = []             # plot.clear() removed the text items themselves

    def add(self, text: str, y: float, colour: str) -> None:
        item = pg.TextItem(text, color=colour, anchor=(1, 0.5), fill=pg.mkBrush(255, 255, 255, 210))
        item.setZValue(10)
        self.plot.addItem(item)
        self.items.append((item, float(y)))
        self.place()

    def place(self, *_) -> None:
        if not self.items:
            return
        box = self.plot.getViewBox()
        (x0, x1), (y0, y1) = box.viewRange()
        pixels = box.height()
        if pixels <= 0 or y1 <= y0:
            return
        per_pixel = (y1 - y0) / pixels
        order = sorted(self.items, key=lambda pair: -pair[1])            # top first, in pixels from the top
        heights = [item.boundingRect().height() for item, _ in order]
        at = [(y1 - y) / per_pixel - h / 2 for (_, y), h in zip(order, heights)]     # just above its line
        for i in range(len(at)):                                         # down from the top, no overlap
            low = heights[i] / 2 if i == 0 else at[i - 1] + (heights[i - 1] + heights[i]) / 2
            at[i] = max(at[i], low)
        for i in reversed(range(len(at))):                               # up from the bottom edge
            high = pixels - heights[i] / 2 if i == len(at) - 1 else at[i + 1] - (heights[i + 1] + heights[i]) / 2
            at[i] = min(at[i], high)
        for (item, _), pixel in zip(order, at):
            item.setPos(x1, y1 - pixel * per_pixel)


def display_unit(unit: str) -> str:
    from analysis.report.numbers import pretty_unit
    return "" if unit in ("", "-", "1") else pretty_unit(unit)


class ControlChartView(pg.GraphicsLayoutWidget):
    """Individuals (top) and moving ranges (below) of one parameter, alarm points in red."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setBackground("w")
        self.individuals = self.addPlot(row=0, col=0, axisItems=_axes())
        self.ranges = self.addPlot(row=1, col=0, axisItems=_axes())
        self.ci.layout.setRowStretchFactor(0, 3)
        self.ci.layout.setRowStretchFactor(1, 1)
        for plot in (self.individuals, self.ranges):
            show_grid(plot)
            plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
            plot.margin_labels = MarginLabels(plot)
        self.ranges.setXLink(self.individuals)
        self.ranges.setLabel("bottom", "unit (in the order measured)")
        self.ranges.setLabel("left", "moving range")
        self.alarm_points = np.array([], dtype=int)

    def clear_chart(self, why: str = "") -> None:
        for plot in (self.individuals, self.ranges):
            plot.clear()
            plot.margin_labels.clear()
        self.individuals.setTitle(why)
        self.alarm_points = np.array([], dtype=int)

    def show_parameter(self, p) -> None:
        """p: analysis.production.summary.ParameterStats."""
        self.clear_chart()
        chart, scale, unit = p.chart, p.display_scale, p.display_unit
        if chart is None:
            self.individuals.setTitle("No control chart: fewer than two units, or no spread between them")
            return
        x = np.arange(1, chart.values.size + 1)
        y = chart.values * scale
        unit = display_unit(unit)
        name = display_name(p.name)
        self.individuals.setLabel("left", f"{name} ({unit})" if unit else name)
        self.individuals.plot(x, y, pen=pg.mkPen("#9bb7e0", width=1), symbol="o", symbolSize=4,
                              symbolBrush=style.MEASURED, symbolPen=None)
        _hline(self.individuals, chart.centre * scale, style.GUIDE, dashed=False, label="centre")
        _hline(self.individuals, chart.ucl * scale, CONTROL, label="UCL +3σ")
        _hline(self.individuals, chart.lcl * scale, CONTROL, label="LCL −3σ")
        lines = [chart.centre, chart.ucl, chart.lcl]
        for value, name in ((p.capability.low, "LSL"), (p.capability.high, "USL")):
            if value is not None:
                _hline(self.individuals, value * scale, SPEC, label=name)
                lines.append(value)
        self.individuals.setXRange(0, x[-1] * (1 + RIGHT_MARGIN), padding=0)
        # Every line and point in view, the outermost line's label inside the plot.
        shown = np.concatenate([y, np.array(lines) * scale])
        self.individuals.setYRange(float(shown.min()), float(shown.max()), padding=0.06)
        if chart.baseline < x[-1]:
            # Where the baseline ends (every unit is in it: no line, the title says so), labelled at the top
            # left of its line, away from the limits' labels at the right edge.
            self.individuals.addItem(pg.InfiniteLine(
                pos=chart.baseline + 0.5, angle=90, pen=pg.mkPen(style.GUIDE, width=1, style=Qt.DotLine),
                label="baseline", labelOpts={"position": 0.97, "color": style.GUIDE, "anchors": [(1, 0), (1, 0)]}))
        flagged = chart.flagged()
        self.alarm_points = flagged
        if flagged.size:
            self.individuals.plot(x[flagged], y[flagged], pen=None, symbol="o", symbolSize=8,
                                  symbolBrush=ALARM, symbolPen=pg.mkPen("#7f0000"))
            # Where the run of alarms the eye looks for begins: the first alarm after the baseline
            # (or the first one), marked on the axis of units with its rule.
            later = [a for a in chart.alarms if a.triggers[0] >= chart.baseline] or list(chart.alarms)
            first = later[0]
            self.individuals.addItem(pg.InfiniteLine(
                pos=first.triggers[0] + 1, angle=90, pen=pg.mkPen(ALARM, width=1, style=Qt.DashLine),
                label=f"first alarm: {first.rule}, unit {first.triggers[0] + 1}",
                labelOpts={"position": 0.97, "color": ALARM, "anchors": [(0, 0), (0, 0)]}))
        mr_x = x[1:]
        self.ranges.plot(mr_x, chart.moving_ranges * abs(scale), pen=pg.mkPen("#9bb7e0", width=1), symbol="o",
                         symbolSize=3, symbolBrush=style.MEASURED, symbolPen=None)
        _hline(self.ranges, chart.mr_centre * abs(scale), style.GUIDE, dashed=False)
        _hline(self.ranges, chart.mr_ucl * abs(scale), CONTROL, label="UCL")
        self.ranges.setYRange(0, max(float(chart.moving_ranges.max()), chart.mr_ucl) * abs(scale) * 1.25, padding=0)
        jumps = sorted({k for a in chart.alarms if a.rule == "MR" for k in a.points if k >= 1})
        if jumps:
            k = np.array(jumps)
            self.ranges.plot(x[k], chart.moving_ranges[k - 1] * abs(scale), pen=None, symbol="o", symbolSize=7,
                             symbolBrush=ALARM, symbolPen=None)
        # A short title: pyqtgraph makes a title's width the chart's minimum width, and at 1280 px a long one ran
        # the chart, with its limits' labels, past the window's edge.
        said = f"{len(chart.alarms)} alarm(s)" if chart.judges else "no alarms below 10 units"
        self.individuals.setTitle(f"{display_name(p.name)}: {said}; centre, σ of units 1–{chart.baseline}")


class HistogramView(pg.PlotWidget):
    """The distribution of one parameter with its specification limits."""

    def __init__(self, parent=None):
        # Counts of units up the side: whole numbers; the parameter's values along the bottom.
        super().__init__(parent, axisItems={"left": UnitAxis("left"), "bottom": OpaqueGridAxis("bottom")},
                         background="w")
        show_grid(self.getPlotItem())
        self.getPlotItem().getAxis("left").setWidth(LEFT_AXIS_WIDTH)
        self.setLabel("left", "units")

    def show_parameter(self, p) -> None:
        plot = self.getPlotItem()
        plot.clear()
        edges, counts = p.histogram
        if len(counts) == 0:
            plot.setTitle("No unit in this selection")
            return
        scale = p.display_scale
        e = np.sort(edges * scale)
        plot.addItem(pg.BarGraphItem(x0=e[:-1], x1=e[1:], height=counts[::-1] if scale < 0 else counts,
                                     brush="#9bb7e0", pen=pg.mkPen("#1f5fbf")))
        for value, name in ((p.capability.low, "LSL"), (p.capability.high, "USL")):
            if value is not None:
                plot.addItem(pg.InfiniteLine(pos=value * scale, angle=90, pen=pg.mkPen(SPEC, width=2,
                                                                                        style=Qt.DashLine),
                                             label=name, labelOpts={"position": 0.9, "color": SPEC}))
        unit = display_unit(p.display_unit)
        name = display_name(p.name)
        plot.setLabel("bottom", f"{name} ({unit})" if unit else name)
        c = p.capability
        plot.setTitle(f"{name}: n = {c.n}" + (f", yield {100 * c.yield_fraction:.1f} %"
                                                if c.yield_fraction is not None else ", no limits"))
