"""Names shown by the GUI are never markup (issue 31, class 1: text escaped where it leaves): a recording's file
name in the status bar and the QA view, an archive's limits name on the Production page."""
import shutil

from PySide6.QtCore import Qt

from analysis.archive import open_archive
from tests.app.conftest import open_and_wait
from tests.pace import wait_ms
from tests.production_helpers import LIMITS, small_measurement, unit

# What a hostile name would draw if a label took it as rich text: a big green verdict and an image.
MARKUP = "<h1 style='color:green'>ALL UNITS PASS<img src='x.png'>"


def test_a_recording_named_as_markup_is_shown_as_its_name(qtbot, window, recordings, tmp_path):
    source = recordings["paper"]
    named = tmp_path / f"{MARKUP}.wav"
    shutil.copy(source, named)
    shutil.copy(source.with_suffix(".json"), named.with_suffix(".json"))
    open_and_wait(qtbot, window, named)
    for label in (window.status_label, window.qa.source):
        assert MARKUP in label.text()
        assert label.textFormat() == Qt.PlainText, label.text()


def test_a_limits_name_as_markup_is_shown_as_its_name(qtbot, window, archive_root, tmp_path):
    path, doc = small_measurement(tmp_path)
    archive = open_archive(str(archive_root))
    archive.store_limits({**LIMITS, "name": MARKUP})
    archive.store(path, unit(doc, fs=20.0), {"serial": "SN1", "station": "QA1", "driver": "W6"})
    page = window.production
    with qtbot.waitSignal(page.computed, timeout=wait_ms(120)):
        window.pages.setCurrentWidget(page)
    assert MARKUP in page.summary.text()
    assert page.summary.textFormat() == Qt.PlainText
    assert page.source_label.textFormat() == Qt.PlainText
