"""The words every page shows a user: no source-code reprs, no internal documents, no statistics jargon.

The test walks the widget tree of the main window after a measurement is shown (the Results page, the
Model lab with a diagnosis ranked, QA, the wizard after its sound-card test) and reads every text a user can
see: labels, buttons, tabs, group titles, text views, table and tree cells and headers, combo entries and
plot titles and axes. Only a "details" section (app.results.fit_quality.DETAILS) may carry the numbers behind a
sentence.
"""
from __future__ import annotations

import re

import pyqtgraph as pg
import pytest
from PySide6.QtCore import QModelIndex, Qt
from PySide6.QtWidgets import (QAbstractButton, QAbstractItemView, QComboBox, QGroupBox, QLabel, QLineEdit,
                               QTabWidget, QTextEdit, QWidget)

from app.results.fit_quality import DETAILS

from .conftest import analysis_wait_ms, open_and_wait
from tests.app.wizard.test_wizard_helpers import choose_simulator, run_job, to_hardware

# A Python repr: Name(...) nested, Name(key=...), or <... object at 0x...>.
FORBIDDEN = {
    "a Python repr": re.compile(r"\b[A-Z]\w*\((?:[A-Z]\w*\(|\w+=)|<\w[\w.]* object at 0x"),
    "docs/physics.md": re.compile(r"physics\.md"),
    "Table I": re.compile(r"\bTable I\b"),
    "ΔBIC": re.compile(r"ΔBIC"),
}


def in_details(widget: QWidget) -> bool:
    while widget is not None:
        if widget.objectName() == DETAILS:
            return True
        widget = widget.parentWidget()
    return False


def _columns(model, parent) -> int:
    try:
        return model.columnCount(parent)
    except TypeError:          # a list model keeps columnCount private
        return 1


def _has_children(model, index) -> bool:
    try:
        return model.hasChildren(index)
    except TypeError:          # a table or list model keeps it private: they have no children
        return False


def _model_texts(model, parent=QModelIndex()) -> list[str]:
    texts = []
    for row in range(model.rowCount(parent)):
        for column in range(_columns(model, parent)):
            index = model.index(row, column, parent)
            value = model.data(index, Qt.DisplayRole)
            if value is not None:
                texts.append(str(value))
            if column == 0 and _has_children(model, index):
                texts += _model_texts(model, index)
    for orientation in (Qt.Horizontal, Qt.Vertical):
        count = _columns(model, parent) if orientation == Qt.Horizontal else model.rowCount(parent)
        for section in range(count):
            value = model.headerData(section, orientation, Qt.DisplayRole)
            if isinstance(value, str):
                texts.append(value)
    return texts


def widget_texts(widget: QWidget) -> list[str]:
    """What `widget` itself shows (not its children)."""
    if isinstance(widget, QLabel):
        return [widget.text()]
    if isinstance(widget, QAbstractButton):
        return [widget.text()]
    if isinstance(widget, QLineEdit):
        return [widget.text(), widget.placeholderText()]
    if isinstance(widget, QTextEdit):
        return [widget.toPlainText()]
    if isinstance(widget, QGroupBox):
        return [widget.title()]
    if isinstance(widget, QComboBox):
        return [widget.itemText(i) for i in range(widget.count())]
    if isinstance(widget, QTabWidget):
        return [widget.tabText(i) for i in range(widget.count())]
    if isinstance(widget, QAbstractItemView) and widget.model() is not None:
        return _model_texts(widget.model())
    if isinstance(widget, pg.PlotWidget):
        item = widget.getPlotItem()
        texts = [item.titleLabel.text]
        texts += [item.getAxis(name).labelText for name in ("left", "bottom", "right") if item.getAxis(name)]
        return texts
    return []


def offending_texts(root: QWidget, patterns: dict[str, re.Pattern] = FORBIDDEN) -> list[str]:
    """What `patterns` find in the texts `root` and its children show (rich text read with and without its tags:
    a repr's "<... object at 0x...>" looks like a tag)."""
    found = []
    for widget in [root, *root.findChildren(QWidget)]:
        if in_details(widget):
            continue
        for text in widget_texts(widget):
            plain_text = re.sub(r"<[^>]+>", "", text or "")
            for name, pattern in patterns.items():
                if text and (pattern.search(text) or pattern.search(plain_text)):
                    found.append(f"{name} in {type(widget).__name__} {widget.objectName()!r}: {text[:160]!r}")
    return found


@pytest.mark.parametrize("text, bad", [
    ("SimulatedAudio(LinearBlockDriver(lr2,creep-log, 48000 Hz, 65536 taps), 48000 Hz)", True),
    ("Fit(method='leastsq')", True),
    ("<analysis.fit.least_squares.FitResult object at 0x7f00>", True),
    ("see docs/physics.md section 5", True),
    ("as the paper's Table I.", True),
    ("ΔBIC -9.2e9", True),
    ("LR-2 (L2 shunted by R2)", False),
    ("Level series (Table II)", False),
    ("in-process simulator (as fast as read), laser", False),
])
def test_the_patterns_catch_what_they_should(text, bad):
    assert any(p.search(text) for p in FORBIDDEN.values()) == bad


def test_no_page_shows_a_repr_an_internal_document_or_delta_bic(qtbot, window, recordings, tmp_path, settings):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    open_and_wait(qtbot, window, recordings["paper"])
    # The Model lab with a ranked diagnosis: its candidates table is where ΔBIC used to be. Without its creep law
    # the model misses the recording (at the noise floor the diagnosis ranks nothing: the table would be empty).
    lab = window.model_lab
    with qtbot.waitSignal(lab.version_added, timeout=analysis_wait_ms()):
        lab.catalogue.item("creep-log").setCheckState(0, Qt.Unchecked)
    with qtbot.waitSignal(lab.diagnosis_shown, timeout=analysis_wait_ms()):
        lab.candidates.diagnose_button.click()
    assert lab.candidates.table.rowCount() > 0
    # The wizard's hardware test, whose answer used to be the simulator's repr.
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    to_hardware(wizard)
    choose_simulator(wizard, realtime=False)
    hardware = wizard.hardware_page
    run_job(qtbot, hardware.test_audio_button, hardware.audio_jobs)
    assert "Found:" in hardware.audio_result.text()

    found = []
    for index in range(window.pages.count()):
        window.pages.setCurrentIndex(index)
        qtbot.wait(10)
        found += offending_texts(window.pages.widget(index))
    assert found == []


def test_a_details_section_may_hold_the_numbers(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["paper"])
    details = window.results.fit_quality.details
    assert details.objectName() == DETAILS and "BIC" in details.text()
    assert offending_texts(window.results) == []
    details.setText("ΔBIC -12")                     # inside details: allowed
    assert offending_texts(window.results) == []
    window.results.fit_quality.headline.setText("ΔBIC -12")      # outside: caught
    assert len(offending_texts(window.results)) == 1


# --- the QA and Production pages: plain names and proper units in their cells ---------------------------------

def code_words() -> dict[str, re.Pattern]:
    """What a developer writes and a user should not read: effect ids, the code's parameter names where the
    customary name differs (RE for Re), and units as the code spells them (ohm, T*m, uF)."""
    from analysis.effects import CATALOGUE
    from app.results.parameter_table import DISPLAY_NAMES
    ids = "|".join(re.escape(i) for i in sorted(CATALOGUE, key=len, reverse=True))
    return {
        "an effect id": re.compile(rf"(?<![\w-])(?:{ids})(?![\w-])"),
        "a code parameter name": re.compile(rf"^(?:{'|'.join(re.escape(n) for n in DISPLAY_NAMES)})$"),
        "a code unit": re.compile(r"\bohms?\b|T\*m|\buF\b|\bus\b|\^"),
    }


@pytest.mark.parametrize("text, bad", [
    ("Result of paper.wav — model lr2,creep-log", True),
    ("RE", True),
    ("3 ohm ± 5 %", True),
    ("≥ 5 T*m", True),
    ("Result of paper.wav — fitted with the lumped model with LR-2, creep", False),
    ("Re", False),
    ("3 Ω ± 5 %", False),
    ("≥ 5 T·m", False),
    ("Cms", False),
])
def test_the_code_word_patterns_catch_what_they_should(text, bad):
    assert any(p.search(text) for p in code_words().values()) == bad


QA_LIMITS = {"format": "linpar-limits/1", "name": "words", "parameters": {
    "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
    "LE": {"max": 2.0, "unit": "mH"},
    "Bl": {"min": 5.0, "unit": "T*m"},
    "fs": {"nominal": 70, "tolerance": 7, "unit": "Hz"}}}


def test_the_qa_and_production_pages_speak_in_names_and_units(qtbot, window, recordings, tmp_path, archive_root):
    import json

    from analysis.archive import open_archive
    from tests.production_helpers import small_measurement, unit
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps(QA_LIMITS), encoding="utf-8")
    open_and_wait(qtbot, window, recordings["paper"])
    qa = window.qa
    assert qa.load_limits(limits) and qa.table.rowCount() == 4
    qa_texts = [qa.source.text()] + [qa.table.item(r, c).text() for r in range(4) for c in range(4)]
    assert "lr2" not in qa.source.text() and "fitted with" in qa.source.text()
    assert {qa.table.item(r, 0).text() for r in range(4)} == {"Re", "Le", "Bl", "fs"}
    assert {qa.table.item(r, 2).text() for r in range(4)} == {"3 Ω ± 5 %", "≤ 2 mH", "≥ 5 T·m", "70 ± 7 Hz"}
    assert any(text.endswith(" Ω") for text in qa_texts) and any(text.endswith(" T·m") for text in qa_texts)
    assert offending_texts(qa, code_words()) == []
    # The Production page over units stored with the same limits: the statistics table, its tabs and plots.
    (tmp_path / "unit").mkdir()
    path, doc = small_measurement(tmp_path / "unit")
    archive = open_archive(str(archive_root))          # the window's archive (conftest)
    archive.store_limits(QA_LIMITS)
    for i in range(6):
        archive.store(path, unit(doc, RE=3.0 + 0.01 * i), {"station": "QA1", "serial": f"SN{i}", "driver": "W6",
                                                           "measured_at": f"2024-05-01T10:0{i}:00Z"})
    page = window.production
    with qtbot.waitSignal(page.computed, timeout=analysis_wait_ms()):
        window.pages.setCurrentWidget(page)
    names = [page.stats_table.item(r, 0).text() for r in range(page.stats_table.rowCount())]
    assert "Re" in names and "Le" in names and "RE" not in names
    row = names.index("Re")
    page.stats_table.selectRow(row)
    assert page.parameter == "RE"                       # the statistics' key is kept behind the name
    assert page.stats_table.item(row, 4).text() == "3 Ω ± 5 %" and page.stats_table.item(row, 2).text().endswith("Ω")
    assert offending_texts(page, code_words()) == []
