"""Archive ▸ Comparison heads each column so that two measurements of one driver are told apart (its number, the
driver and serial, the date to the second; the id in the tooltip), and a driver's name is text wherever it goes:
the legend draws names as HTML."""
from __future__ import annotations

import numpy as np

from analysis.archive.compare import Comparison, ComparisonRow
from analysis.archive.results import Curve
from app.archive.overlay import CompareView
from app.archive.worker import ComparisonData

NAME = "<b>Paper</b> & co"
IDS = ("20261128-135055-bbcf4f", "20261128-135056-adabc3")
DATES = ("2026-11-28T13:50:55Z", "2026-11-28T13:50:56Z")       # one driver measured twice in one minute


def _curve() -> Curve:
    freqs = np.geomspace(10.0, 1e4, 40)
    z = 3.0 + 0.1j * freqs ** 0.5
    return Curve("impedance", "ohm", freqs, z, np.full(40, 1e-3), z)


def test_two_measurements_of_one_driver_are_told_apart_and_the_name_stays_text(qtbot):
    row = ComparisonRow("RE", "ohm", (3.02, 3.03), (0.001, 0.001), 3.025, 0.007, (0.0, 0.3))
    comparison = Comparison(IDS, (NAME, NAME), (row,), DATES)
    view = CompareView()
    qtbot.addWidget(view)
    view.set_data(ComparisonData(comparison, DATES, ({"impedance": _curve()}, {"impedance": _curve()}), ()))
    headers = [view.table.horizontalHeaderItem(i) for i in range(2)]
    texts = [h.text() for h in headers]
    assert texts == [f"1. {NAME}\n2026-11-28 13:50:55", f"2. {NAME}\n2026-11-28 13:50:56"]
    for header, mid in zip(headers, IDS):
        assert mid in header.toolTip()
    legend = [label.text for _, label in view.plot.legend.items]
    assert legend == ["1. &lt;b&gt;Paper&lt;/b&gt; &amp; co", "2. &lt;b&gt;Paper&lt;/b&gt; &amp; co"]
