"""The control chart's line labels: each beside its line, none over another, none cut at the plot's edge (UCL and
USL overlapped on a chart of 4 units; the top line's label was cut by the plot's top)."""
import itertools

import pyqtgraph as pg


def _labels_shown(qtbot, values, size):
    from app.production.charts import MarginLabels, _hline
    widget = pg.PlotWidget()
    qtbot.addWidget(widget)
    plot = widget.getPlotItem()
    plot.margin_labels = MarginLabels(plot)
    for i, y in enumerate(values):
        _hline(plot, y, "#8e5bb5", label=f"line {i} +3σ")
    plot.setXRange(0, 10, padding=0)
    plot.setYRange(min(values), max(values), padding=0.02)
    widget.resize(*size)
    widget.show()
    qtbot.waitExposed(widget)
    widget.grab()               # one paint: a TextItem places itself on the scene when it is drawn
    box = plot.getViewBox()
    return [item.sceneBoundingRect() for item, _ in plot.margin_labels.items], box.sceneBoundingRect()


def test_close_lines_get_labels_apart_and_inside_the_plot(qtbot):
    # USL and UCL 1 % of the range apart, the centre and LCL near the bottom edge: all at one place once.
    values = [0.0, 0.01, 0.5, 0.99, 1.0]
    for size in ((420, 180), (800, 400)):
        rects, plot_rect = _labels_shown(qtbot, values, size)
        for a, b in itertools.combinations(rects, 2):
            assert not a.intersects(b), (a, b)
        for r in rects:
            assert plot_rect.adjusted(-1, -1, 1, 1).contains(r), (r, plot_rect)


def test_a_label_with_room_sits_just_above_its_line(qtbot):
    rects, plot_rect = _labels_shown(qtbot, [0.0, 0.5, 1.0], (600, 400))
    middle = rects[1]
    line_y = plot_rect.top() + plot_rect.height() * (1.0 - 0.5 / 1.0) * 1.0
    # Within a label's height of the line (the range's 2 % padding moves the line by a few pixels).
    assert middle.bottom() <= line_y + 6 and middle.bottom() >= line_y - middle.height()
