"""The Production page on the smaller screen it is made for: its statistics table fits 1280 px without sideways
scrolling (the capability indices' intervals had widened it), with 4 units (greyed, wide intervals) and with 40;
and limits stored from the page itself (a server refuses a login whose role may not store them)."""
import json

import pytest
from PySide6.QtCore import Qt

from analysis.archive import open_archive
from tests.app.production.test_page import fill, show
from tests.pace import wait_ms
from tests.production_helpers import LIMITS, small_measurement


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


@pytest.mark.parametrize("units", [4, 40])
@pytest.mark.parametrize("size", [(1280, 720), (1920, 1080)])
def test_the_statistics_table_fits_without_sideways_scrolling(qtbot, window, measured, archive_root, units, size):
    open_archive(str(archive_root)).store_limits(LIMITS)
    fill(str(archive_root), measured, n=units, drift_at=99)
    page, data = show(qtbot, window)
    window.resize(*size)
    qtbot.waitUntil(lambda: window.width() == size[0], timeout=wait_ms(120))
    table = page.stats_table
    # The layout settles on the event loop: wait for it, then ask whether any column lies past the edge.
    header = table.horizontalHeader()

    def fits():
        widths = [header.sectionSize(i) for i in range(header.count())]
        assert header.length() <= table.viewport().width(), f"columns {widths} in {table.viewport().width()} px"
        assert table.horizontalScrollBar().maximum() == 0
        # The control chart inside its pane: a long title had made the chart's layout wider than the window.
        chart_min = page.chart.ci.effectiveSizeHint(Qt.SizeHint.MinimumSize).width()
        assert chart_min <= page.chart.viewport().width(), (chart_min, page.chart.viewport().width())
    qtbot.waitUntil(fits, timeout=wait_ms(10))
    fs = [r for r in range(table.rowCount()) if table.item(r, 0).text() == "fs"][0]
    cpk = table.item(fs, 6).text()
    assert "\n" in cpk and "–" in cpk.split("\n")[1]                                         # the interval on the cell's second line
    assert table.rowHeight(fs) >= 2 * table.fontMetrics().height()   # and the row tall enough to show it
    assert page.width() <= size[0]


def test_limits_stored_from_the_page_reach_the_statistics(qtbot, window, measured, archive_root, tmp_path):
    fill(str(archive_root), measured, n=4, drift_at=99)
    page, data = show(qtbot, window)
    assert data.stats.limits is None and "Store limits…" in page.summary.text()
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps(LIMITS))
    with qtbot.waitSignal(page.computed, timeout=wait_ms(120)) as computed:
        with qtbot.waitSignal(page.limits_stored, timeout=wait_ms(120)) as stored:
            page.store_limits(limits)
    assert "limits version 1 (6-inch woofer)" in stored.args[0]
    assert computed.args[0].stats.limits.version == 1
    assert "limits version 1 (6-inch woofer)" in page.summary.text()
    assert "Stored" in page.message.text() and page.message.isVisible()
    assert open_archive(str(archive_root)).limits().name == "6-inch woofer"


def test_a_bad_limits_file_is_said_and_nothing_is_stored(qtbot, window, measured, archive_root, tmp_path):
    fill(str(archive_root), measured, n=4, drift_at=99)
    page, _ = show(qtbot, window)
    bad = tmp_path / "limits.json"
    bad.write_text('{"format": "linpar-limits/1", "name": "x", "parameters": {"fs": {"min": 80, "max": 60}}}')
    with qtbot.waitSignal(page.failed, timeout=wait_ms(120)) as failed:
        page.store_limits(bad)
    assert "The limits were not stored" in page.message.text() and failed.args[0]
    assert open_archive(str(archive_root)).limits() is None


def test_a_server_refuses_limits_from_an_operator_and_takes_them_from_an_engineer(qtbot, window, measured,
                                                                                 pg_database, monkeypatch, tmp_path):
    fill(pg_database.url("station_a"), measured, n=4)
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps(LIMITS))
    monkeypatch.setenv("LINPAR_ARCHIVE_URL", pg_database.url("station_a"))
    page, _ = show(qtbot, window)
    with qtbot.waitSignal(page.failed, timeout=wait_ms(120)) as failed:
        page.store_limits(limits)
    assert "engineer" in failed.args[0], failed.args[0]
    monkeypatch.setenv("LINPAR_ARCHIVE_URL", pg_database.url("eva"))
    with qtbot.waitSignal(page.computed, timeout=wait_ms(120)) as computed:
        page.store_limits(limits)
    assert computed.args[0].stats.limits.version == 1
