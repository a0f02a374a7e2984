"""The Model lab's catalogue and reduced-chi^2 chart at the sizes they have on a 1280x720 screen: the effects'
titles take the room left without a horizontal scroll bar (cut with "…", whole in the tooltip), and the channels'
names never lie over the noise floor's label."""
from __future__ import annotations

import pytest
from PySide6.QtWidgets import QApplication

from app.model_lab.catalogue import EffectCatalogue
from app.model_lab.plots import CHANNEL_SHORT, ChartPoint, ChiSquareChart

# What the lab gives them in a 1280x720 window (docs/screenshots/model-lab-*-1280x720.png).
CATALOGUE_SIZE, CHART_SIZE = (270, 560), (365, 230)


def test_the_catalogues_titles_fit_beside_the_ids_without_a_scroll_bar(qtbot):
    catalogue = EffectCatalogue()
    qtbot.addWidget(catalogue)
    catalogue.resize(*CATALOGUE_SIZE)
    catalogue.show()
    QApplication.processEvents()
    tree = catalogue.tree
    assert not tree.horizontalScrollBar().isVisible()
    assert tree.columnWidth(0) + tree.columnWidth(1) <= tree.viewport().width()
    item = catalogue.item("lr2")
    title = item.text(1)
    # Too long for its column, so cut on screen; whole where the user points.
    assert tree.fontMetrics().horizontalAdvance(title) > tree.columnWidth(1)
    assert title in item.toolTip(1)


@pytest.mark.parametrize("last", [1.0, 3.0, 0.8, 40.0])
def test_the_chi2_charts_channel_names_never_cover_the_noise_floors_label(qtbot, last):
    chart = ChiSquareChart()
    qtbot.addWidget(chart)
    chart.resize(*CHART_SIZE)
    chart.show()
    chart.set_points([ChartPoint(1, "lr2, creep-log", "as fitted", {"impedance": 200.0, "displacement": 900.0}),
                      ChartPoint(2, "lr2, creep-log, rms", "added", {"impedance": last, "displacement": last})])
    QApplication.processEvents()
    floor = chart.floor.label.sceneBoundingRect()
    legend = chart.plot.legend
    assert legend is None or not legend.sceneBoundingRect().intersects(floor)
    title = chart.plot.titleLabel.text
    assert all(name in title for name in CHANNEL_SHORT.values())       # the colours are said in the title
