"""The words every page shows a user: no source-code reprs, no internal documents, no statistics jargon.

The test walks the widget tree of the main window after a measurement is shown (the Results page, the
Model lab with a diagnosis ranked, QA, the wizard after its sound-card test) and reads every text a user can
see: labels, buttons, tabs, group titles, text views, table and tree cells and headers, combo entries and
plot titles and axes. Only a "details" section (app.fit_quality.DETAILS) may carry the numbers behind a
sentence.
"""
from __future__ import annotations

import re

import pyqtgraph as pg
import pytest
from PySide6.QtCore import QModelIndex, Qt
from PySide6.QtWidgets import (QAbstractButton, QAbstractItemView, QComboBox, QGroupBox, QLabel, QLineEdit,
                               QTabWidget, QTextEdit, QWidget)

from app.fit_quality import DETAILS

from .conftest import ANALYSIS_TIMEOUT_MS, open_and_wait
from .test_wizard_helpers import choose_simulator, run_job, to_hardware

# A Python repr: Name(...) nested, Name(key=...), or <... object at 0x...>.
FORBIDDEN = {
    "a Python repr": re.compile(r"\b[A-Z]\w*\((?:[A-Z]\w*\(|\w+=)|<\w[\w.]* object at 0x"),
    "physics.md": re.compile(r"physics\.md"),
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


def offending_texts(root: QWidget) -> list[str]:
    found = []
    for widget in [root, *root.findChildren(QWidget)]:
        if in_details(widget):
            continue
        for text in widget_texts(widget):
            for name, pattern in FORBIDDEN.items():
                if text and pattern.search(text):
                    found.append(f"{name} in {type(widget).__name__} {widget.objectName()!r}: {text[:160]!r}")
    return found


@pytest.mark.parametrize("text, bad", [
    ("SimulatedAudio(LinearBlockDriver(lr2,creep-log, 48000 Hz, 65536 taps), 48000 Hz)", True),
    ("Fit(method='leastsq')", True),
    ("<analysis.fit.FitResult object at 0x7f00>", True),
    ("see physics.md section 5", True),
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
    # The Model lab with a ranked diagnosis: its candidates table is where ΔBIC used to be.
    lab = window.model_lab
    with qtbot.waitSignal(lab.diagnosis_shown, timeout=ANALYSIS_TIMEOUT_MS):
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
