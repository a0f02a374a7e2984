"""The Production page: the statistics of the archive's units in a table, the chosen parameter's control chart
with its alarms flagged and named, the stations, the exports; the Archive page on a PostgreSQL server."""
import json

import numpy as np
import pytest

from analysis.archive import open_archive
from tests.pace import wait_ms
from tests.production_helpers import LIMITS, small_measurement, unit



@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


def fill(spec, measured, n=120, drift_at=80):
    """n units of stations QA1/QA2; fs 2 sigma up from unit `drift_at`; QA2 reads 1.5 sigma high."""
    path, doc = measured
    archive = open_archive(spec)
    rng = np.random.default_rng(2)
    for i in range(n):
        station = f"QA{i % 2 + 1}"
        fs = 70.0 + 0.4 * rng.standard_normal() + (0.8 if i >= drift_at else 0) + (0.6 if station == "QA2" else 0)
        archive.store(path, unit(doc, fs=fs, RE=3.0 + 0.02 * rng.standard_normal()),
                      {"station": station, "serial": f"SN{i:03d}", "driver": "W6",
                       "measured_at": f"2024-05-01T{i // 60:02d}:{i % 60:02d}:00Z"})


def show(qtbot, window):
    window.resize(1280, 720)                 # the smaller of the two screens the page is made for
    page = window.production
    with qtbot.waitSignal(page.computed, timeout=wait_ms(120)) as shown:
        window.pages.setCurrentWidget(page)
    return page, shown.args[0]


def test_statistics_chart_alarms_and_stations_of_the_archive(qtbot, window, measured, archive_root, tmp_path):
    open_archive(str(archive_root)).store_limits(LIMITS)
    fill(str(archive_root), measured)
    page, data = show(qtbot, window)
    assert len(data.population) == 120 and "120 measurement(s)" in page.summary.text()
    names = [page.stats_table.item(r, 0).text() for r in range(page.stats_table.rowCount())]
    assert "fs" in names and "Re" in names          # the customary name, as the Results page writes it
    page.stats_table.selectRow(names.index("fs"))
    fs = data.stats.parameters["fs"]
    assert page.parameter == "fs" and page.stats_table.item(names.index("fs"), 4).text() == "70 ± 6 Hz"
    assert page.chart.alarm_points.size > 0                      # flagged in red on the chart
    assert set(page.chart.alarm_points.tolist()) == set(fs.chart.flagged().tolist())
    assert page.alarms_table.rowCount() == len(fs.chart.alarms)
    first = fs.chart.alarms[0]
    assert page.alarms_table.item(0, 0).text() == first.rule
    assert page.alarms_table.item(0, 3).toolTip().split("\n") == [fs.ids[i] for i in first.points]
    reads = {page.stations_table.item(r, 0).text(): page.stations_table.item(r, 4).text()
             for r in range(page.stations_table.rowCount())}
    assert reads == {"QA1": "low", "QA2": "high"}        # two stations: each differs from the other
    written = page.export_to(tmp_path / "units.dfq")
    assert written and written.read_bytes().startswith(b"K0100 ")
    assert len(json.loads(page.export_to(tmp_path / "units.json").read_text())["measurements"]) == 120
    # One station only: the filter is the statistics' selection.
    with qtbot.waitSignal(page.computed, timeout=wait_ms(120)) as shown:
        page.station_combo.setCurrentIndex(page.station_combo.findData("QA1"))
    assert len(shown.args[0].population) == 60 and set(shown.args[0].population.stations) == {"QA1"}


def test_an_empty_archive_and_a_lost_server_are_said_on_the_page(qtbot, window, monkeypatch):
    page, data = show(qtbot, window)
    assert len(data.population) == 0 and "0 measurement(s)" in page.summary.text()
    assert not page.export_button.isEnabled()
    monkeypatch.setenv("LINPAR_ARCHIVE_URL", "postgresql://nobody@127.0.0.1:1/linpar?connect_timeout=2")
    with qtbot.waitSignal(page.failed, timeout=wait_ms(120)) as failed:
        page.refresh()
    assert "cannot reach the server" in failed.args[0]
    assert "Cannot compute the production statistics" in page.message.text() and page.message.isVisible()


def test_the_archive_page_lists_a_server_named_by_the_environment(qtbot, window, measured, pg_database, monkeypatch):
    fill(pg_database.url("station_a"), measured, n=4)
    monkeypatch.setenv("LINPAR_ARCHIVE_URL", pg_database.url("audrey"))
    archive = window.archive
    with qtbot.waitSignal(archive.listed, timeout=wait_ms(120)) as listed:
        window.pages.setCurrentWidget(archive)
    assert listed.args[0] == 4
    assert archive.root_label.text() == pg_database.url("audrey")
    assert not archive.root_button.isEnabled() and archive.rebuild_button.text() == "Send queue"
    page, data = show(qtbot, window)
    assert len(data.population) == 4 and data.location == pg_database.url("audrey")


def _index_cells(page, name: str):
    names = [page.stats_table.item(r, 0).text() for r in range(page.stats_table.rowCount())]
    row = names.index(name)
    return [page.stats_table.item(row, col) for col in range(5, 9)]         # Cp, Cpk, Pp, Ppk


def test_four_units_grey_the_capability_indices_and_say_why(qtbot, window, measured, archive_root):
    """The issue's case: Cpk 27.6 from 4 units was shown in green. Now greyed, with its interval and the reason."""
    from PySide6.QtCore import Qt
    open_archive(str(archive_root)).store_limits(LIMITS)
    fill(str(archive_root), measured, n=4, drift_at=99)
    page, data = show(qtbot, window)
    assert "capability indices greyed" in page.summary.text() and "at least 25" in page.summary.text()
    for item in _index_cells(page, "fs"):
        if item.text() != "–":
            assert item.foreground().color() == Qt.GlobalColor.gray
            assert "only 4 units" in item.toolTip() and "–" in item.text()      # the interval in the cell


def test_forty_units_show_intervals_and_a_verdict(qtbot, window, measured, archive_root):
    from PySide6.QtCore import Qt
    from analysis.production.capability_interval import centred_interval
    open_archive(str(archive_root)).store_limits(LIMITS)
    fill(str(archive_root), measured, n=40, drift_at=99)
    page, data = show(qtbot, window)
    assert "greyed" not in page.summary.text()
    c = data.stats.parameters["fs"].capability
    lo, hi = centred_interval(c.cpk, c.n)
    cpk = _index_cells(page, "fs")[1]
    assert cpk.text() == f"{c.cpk:.2f}\n{lo:.2f}–{hi:.2f}"                 # the interval on the second line
    colour = cpk.foreground().color()
    assert colour != Qt.GlobalColor.gray
    assert (colour == Qt.GlobalColor.darkGreen) == (lo >= 1.33)       # green only when the interval clears 1.33


def test_without_stored_limits_the_page_says_the_command(qtbot, window, measured, archive_root):
    fill(str(archive_root), measured, n=4, drift_at=99)
    page, _ = show(qtbot, window)
    assert "linpar qa limits --store FILE" in page.summary.text()


def test_the_unit_axis_has_whole_units_only(qtbot):
    from app.production.charts import UnitAxis
    axis = UnitAxis("bottom")
    for low, high in ((0.3, 4.6), (0.5, 40.5), (-2.0, 2000.0)):
        values = [v for _, level in axis.tickValues(low, high, 600) for v in level]
        assert values and all(float(v).is_integer() for v in values), (low, high, values)
