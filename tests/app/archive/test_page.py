"""The Archive page: list, filter, open, compare, errors as messages; a wizard measurement lands in the archive."""
from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest
from PySide6.QtCore import QDate, QItemSelection, QItemSelectionModel, Qt

from analysis.archive import Archive
from analysis.archive.index import INDEX_FILE
from analysis.archive.results import results_document
from analysis.pipeline import analyze_recording
from analysis.recording.format import read_recording, write_recording
from analysis.report import report_for_measurement, report_for_recording, write_report
from analysis.session import software
from app.archive.page import ROOT_KEY
from app.archive.table import FIRST_PARAMETER, HEADERS
from tests.builders import DRIVERS, TYPICAL_NOISE, needs_pdftotext, pdf_text, recording

from tests.app.conftest import analysis_wait_ms
from tests.app.wizard.test_wizard_helpers import job_wait_ms, skip_to_measure
from tests.pace import wait_ms

# key: (builders driver, driver name, serial, operator, measured_at)
STORED = {
    "paper": ("paper", "W18-PAPER", "0042", "ana", "2024-05-01T10:00:00Z"),
    "mid": ("midwoofer-6in", "M6-MID", "0007", "ben", "2024-05-02T10:00:00Z"),
    "big": ("woofer-12in", "W30-BIG", "0100", "ana", "2024-05-03T10:00:00Z"),
    "red": ("paper", "W18-PAPER", "0043", "carl", "2024-06-01T09:30:00Z"),
}


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """Per builders driver: (recording path, results document) of a short synthetic measurement."""
    folder = tmp_path_factory.mktemp("archived-recordings")
    out = {}
    for seed, name in enumerate(("paper", "midwoofer-6in", "woofer-12in")):
        rec = recording(DRIVERS[name], noise=TYPICAL_NOISE, n_periods=3, seed=seed)
        write_recording(folder / name, rec)
        out[name] = (folder / name, results_document(analyze_recording(rec), rec))
    return out


@pytest.fixture
def archive(archive_root, measured):
    """The test's archive (where $LINPAR_ARCHIVE points) with STORED in it: (Archive, key -> id, key -> document)."""
    archive = Archive(archive_root)
    ids, docs = {}, {}
    for key, (driver, name, serial, operator, when) in STORED.items():
        path, doc = measured[driver]
        if key == "red":
            doc = {**doc, "validity": {**doc["validity"], "overall": "red"}}
        ids[key] = archive.store(path, doc, {"driver": name, "serial": serial, "operator": operator,
                                             "station": "QA1", "measured_at": when})
        docs[key] = doc
    return archive, ids, docs


def show_page(window):
    window.pages.setCurrentWidget(window.archive)
    return window.archive


def shown_ids(page) -> list[str]:
    return [page.table.entry_at(row).id for row in range(page.table.proxy.rowCount())]


def cell(page, row: int, header: str) -> str:
    return page.table.proxy.index(row, HEADERS.index(header)).data()


def select(page, ids) -> None:
    selection = QItemSelection()
    for row, mid in enumerate(shown_ids(page)):
        if mid in ids:
            selection.select(page.table.proxy.index(row, 0), page.table.proxy.index(row, len(HEADERS) - 1))
    page.table.selectionModel().select(selection, QItemSelectionModel.ClearAndSelect | QItemSelectionModel.Rows)


def test_the_page_lists_the_stored_measurements_newest_first(window, archive):
    _, ids, docs = archive
    page = show_page(window)
    assert window.pages.tabText(window.pages.indexOf(page)) == "Archive"
    assert shown_ids(page) == [ids["red"], ids["big"], ids["mid"], ids["paper"]]
    assert [cell(page, r, "Driver") for r in range(4)] == ["W18-PAPER", "W30-BIG", "M6-MID", "W18-PAPER"]
    assert [cell(page, r, "Serial") for r in range(4)] == ["0043", "0100", "0007", "0042"]
    assert [cell(page, r, "Validity") for r in range(4)] == ["red", "green", "green", "green"]
    assert cell(page, 1, "Measured (UTC)") == "2024-05-03 10:00:00"
    assert cell(page, 1, "Operator") == "ana" and cell(page, 1, "Station") == "QA1"
    big = docs["big"]["parameters"]
    assert cell(page, 1, "RE (Ω)") == f"{big['RE']['value']:.4g}"
    assert cell(page, 1, "Mms (g)") == f"{big['Mms']['value'] * 1e3:.4g}"
    assert float(cell(page, 1, "fs (Hz)")) == pytest.approx(35.6, rel=0.01)     # woofer-12in's fs
    assert not page.table.proxy.index(0, 0).data(Qt.DecorationRole).isNull()    # the lamp
    assert page.count_label.text() == "4 measurements."


def test_the_filter_narrows_the_list_once_the_typing_stops(qtbot, window, archive):
    _, ids, _ = archive
    page = show_page(window)
    qtbot.keyClicks(page.filters.driver_edit, "w18")
    assert len(shown_ids(page)) == 4                      # not yet: the list waits for the typing to stop
    with qtbot.waitSignal(page.listed, timeout=wait_ms(30)):
        pass
    assert set(shown_ids(page)) == {ids["paper"], ids["red"]}
    page.filters.validity_combo.setCurrentIndex(page.filters.validity_combo.findData("red"))
    page.refresh_now()
    assert shown_ids(page) == [ids["red"]]
    page.filters.driver_edit.clear()
    page.filters.validity_combo.setCurrentIndex(0)
    page.filters.operator_edit.setText("ANA")
    page.refresh_now()
    assert set(shown_ids(page)) == {ids["paper"], ids["big"]}
    page.filters.operator_edit.clear()
    page.filters.since_edit.setDate(QDate(2024, 5, 2))
    page.filters.until_edit.setDate(QDate(2024, 5, 3))
    page.refresh_now()
    assert shown_ids(page) == [ids["big"], ids["mid"]]
    assert page.count_label.text() == "2 measurements match the filter."
    page.filters.serial_edit.setText("no such serial")
    page.refresh_now()
    assert shown_ids(page) == [] and page.count_label.text() == "No measurement matches the filter."


def test_open_shows_the_stored_measurement_on_the_results_page(qtbot, window, archive):
    store, ids, docs = archive
    page = show_page(window)
    row = shown_ids(page).index(ids["mid"])
    rect = page.table.visualRect(page.table.proxy.index(row, HEADERS.index("Driver")))
    with qtbot.waitSignal(window.analysis_shown, timeout=analysis_wait_ms()):
        qtbot.mouseClick(page.table.viewport(), Qt.LeftButton, pos=rect.center())
        qtbot.mouseDClick(page.table.viewport(), Qt.LeftButton, pos=rect.center())
    result = window.results.result
    assert result.source == store.get(ids["mid"]).recording_path()
    assert window.pages.currentWidget() is window.results
    assert "M6-MID 0007" in window.windowTitle()
    for name in ("RE", "fs", "Bl", "Mms"):       # the analysis again, of the same recording
        stored = docs["mid"]["parameters"][name]
        assert result.parameters[name].value == pytest.approx(stored["value"], abs=5 * stored["std"] + 1e-9)
    assert window.model_lab.base is result and window.qa.result is result


def test_compare_three_overlays_their_curves_and_tabulates_their_parameters(qtbot, window, archive):
    _, ids, docs = archive
    page = show_page(window)
    select(page, {ids["paper"], ids["mid"], ids["big"]})
    assert page.selection_label.text() == "3 selected"
    with qtbot.waitSignal(page.comparison_shown, timeout=analysis_wait_ms()) as shown:
        page.compare_button.click()
    order = ["big", "mid", "paper"]                        # as the list shows them: newest first
    assert list(shown.args[0].comparison.ids) == [ids[k] for k in order]
    view = page.compare_view
    assert page.tabs.currentWidget() is view
    for channel in ("impedance", "displacement"):
        items = view.plot.items[channel]
        assert len(items) == 3
        for item, key in zip(items, order):
            curve = docs[key]["curves"][channel]
            expected = np.abs(np.array(curve["measured_re"]) + 1j * np.array(curve["measured_im"]))
            expected *= 1e3 if channel == "displacement" else 1.0
            x, y = item.getOriginalDataset()
            assert len(x) == len(curve["freqs_hz"]) > 50
            assert np.allclose(y, expected, rtol=1e-12)
    assert len(view.plot.legend.items) == 3
    table = view.table
    assert table.n_measurements == 3 and table.columnCount() == 3 + 1     # and the spread
    for number, key in enumerate(order):
        shown_values = table.values(number)
        params = docs[key]["parameters"]
        for name in ("RE", "fs", "Qts", "Bl", "Mms", "Cms"):
            assert shown_values[name] == pytest.approx(params[name]["value"] * params[name]["display_scale"])
        assert STORED[key][1] in table.horizontalHeaderItem(number).text()
    re_row = table.names.index("RE")
    assert table.verticalHeaderItem(re_row).text() == "RE (Ω)"
    assert "±" in table.item(re_row, 0).text()            # with its stored uncertainty
    cells = [table.item(r, c).text() for r in range(table.rowCount()) for c in range(table.columnCount())
             if table.item(r, c) is not None]
    assert not [t for t in cells if re.search(r"\de[-+]\d", t)]       # written out, never "1.6e-05"


def test_more_than_eight_selected_is_a_message_not_a_crash(qtbot, window, archive, measured):
    store, _, _ = archive
    path, doc = measured["paper"]
    for i in range(5):
        store.store(path, doc, {"driver": "batch", "serial": f"B{i}"})
    page = show_page(window)
    page.table.selectAll()
    assert "9 selected: at most 8" in page.selection_label.text()
    page.compare_button.click()
    assert "9 measurements are selected, but at most 8" in page.message.text() and page.message.isVisible()
    assert not page.jobs.busy and page.compare_view.table.rowCount() == 0
    assert page.tabs.currentWidget() is page.list_tab


def test_a_corrupted_index_is_rebuilt_and_the_page_still_lists(qtbot, window, archive, archive_root):
    _, ids, _ = archive
    (archive_root / INDEX_FILE).write_bytes(b"this is not an SQLite database" * 10)
    page = show_page(window)
    assert set(shown_ids(page)) == set(ids.values())
    assert "repaired" in page.message.text()
    broken = archive_root / "measurements" / "not-a-measurement"
    broken.mkdir()
    (broken / "measurement.json").write_text("{", encoding="utf-8")
    with qtbot.waitSignal(page.rebuilt, timeout=analysis_wait_ms()):
        page.rebuild_button.click()
    assert set(shown_ids(page)) == set(ids.values())
    assert "4 measurement(s); 1 folder(s) skipped" in page.message.text()
    assert page.rebuild_button.isEnabled()


def test_archive_errors_are_messages_on_the_page(qtbot, window, archive, archive_root):
    _, ids, _ = archive
    page = show_page(window)
    (Archive(archive_root).get(ids["mid"]).folder / "results.json").write_text("[1, 2", encoding="utf-8")
    select(page, {ids["mid"], ids["big"]})
    with qtbot.waitSignal(page.worker.failed, timeout=analysis_wait_ms()):
        page.compare_button.click()
    assert "Cannot compare" in page.message.text() and "results.json" in page.message.text()
    (Archive(archive_root).get(ids["big"]).folder / "recording.wav").unlink()
    select(page, {ids["big"]})
    assert page.on_open() is None
    assert "the recording is missing" in page.message.text()
    shutil.rmtree(archive_root)
    archive_root.write_text("a file where the archive's folder should be", encoding="utf-8")
    assert page.refresh_now() == 0
    assert "No archive in this folder yet" in page.count_label.text()


def test_the_archive_folder_is_chosen_and_remembered(qtbot, window, archive, settings, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QFileDialog
    other = tmp_path / "other-archive"
    other.mkdir()
    monkeypatch.setattr(QFileDialog, "getExistingDirectory", staticmethod(lambda *a, **k: str(other)))
    page = show_page(window)
    assert len(shown_ids(page)) == 4
    page.root_button.click()
    assert settings.qsettings.value(ROOT_KEY) == str(other)
    assert str(other) in page.root_label.text()
    assert shown_ids(page) == [] and page.count_label.text().startswith("The archive is empty")


def test_a_store_that_fails_keeps_the_recording_and_says_so(qtbot, window, measured, archive_root):
    path, _ = measured["paper"]
    archive_root.write_text("not a folder", encoding="utf-8")
    result = analyze_recording(read_recording(path))
    with qtbot.waitSignal(window.archive.store_failed, timeout=analysis_wait_ms()):
        window.archive.store_measurement(path.with_suffix(".wav"), result, {"driver": "x"})
    assert "NOT stored in the archive" in window.status_label.text()
    assert path.with_suffix(".wav").is_file()
    assert "was not stored in the archive" in window.archive.message.text()


@needs_pdftotext
def test_a_wizard_measurement_ends_up_in_the_archive(qtbot, window, settings, tmp_path, archive_root):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    wizard.driver_page.operator_edit.setText("ana")
    wizard.driver_page.station_edit.setText("bench 3")
    skip_to_measure(qtbot, wizard, realtime=False, template="midrange")
    with qtbot.waitSignal(window.archive.stored, timeout=job_wait_ms()) as stored:
        wizard.measure_page.start_button.click()
    outcome = wizard.state.outcome
    mid, recording_path = stored.args
    assert recording_path == str(outcome.path)
    (entry,) = Archive(archive_root).list()
    assert (entry.id, entry.driver, entry.serial, entry.operator, entry.station) == \
           (mid, "W18-PAPER", "0042", "ana", "bench 3")
    assert entry.parameters["RE"]["value"] == pytest.approx(outcome.analysis.result.parameters["RE"].value)
    m = Archive(archive_root).get(mid)
    assert m.recording_path().read_bytes() == outcome.path.read_bytes()
    assert outcome.path.is_file()                          # the recording stays where it was written
    assert f"stored in the archive as {mid}" in window.status_label.text()
    assert shown_ids(window.archive) == [mid]              # the page listed it again after storing
    assert settings.qsettings.value("measure/operator") == "ana"
    # Traceable: the sidecar says who, where, with what; the archive and every report say the same.
    session = json.loads(outcome.path.with_suffix(".json").read_text(encoding="utf-8"))["session"]
    assert (session["operator"], session["station"], session["template"]) == ("ana", "bench 3", "midrange")
    assert session["software"] == software() and session["measured_at"] == m.record["measured_at"]
    archived, fresh = report_for_measurement(m), report_for_recording(outcome.path)
    traced = {"Driver", "Serial number", "Date", "Operator", "Station", "Template", "Measured with"}
    assert {k: v for k, v in archived.header if k in traced} == {k: v for k, v in fresh.header if k in traced}
    assert dict(archived.header)["Operator"] == "ana" and dict(archived.header)["Template"] == "midrange"
    write_report(archived, pdf=tmp_path / "archived.pdf")
    text = pdf_text(tmp_path / "archived.pdf")
    assert re.search(r"Operator\s+ana", text) and re.search(r"Station\s+bench 3", text)
    assert re.search(r"Serial number\s+0042", text) and software() in text


def test_a_narrow_window_puts_the_filters_on_two_rows(qtbot, window, archive):
    page = show_page(window)
    assert page.filters.rows == 1
    window.resize(700, 500)               # the page must not set the window's minimum width
    qtbot.waitUntil(lambda: window.width() == 700, timeout=wait_ms(5))
    qtbot.waitUntil(lambda: page.filters.rows == 2, timeout=wait_ms(5))
    assert page.filters.driver_edit.isVisible() and page.filters.until_edit.isVisible()
    assert page.filters.until_edit.geometry().right() <= page.filters.width()
