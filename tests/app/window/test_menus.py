"""The menus: File (open, recent, export report and data, load limits, quit), View (each page), Help (the
guide, the shortcuts, About), and the page a first start opens on."""
from __future__ import annotations

import csv
import json

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QFileDialog

from app.window.main_window import MainWindow, PAGE_ORDER
from app.window.menus import DEPENDENCIES, guide_markdown
from app.window.settings import Settings

from tests.pace import wait_ms

from tests.app.conftest import open_and_wait
from tests.app.qa.test_view import LIMITS


def titles(menu) -> list[str]:
    return [a.text().replace("&", "") for a in menu.actions() if not a.isSeparator()]


def test_the_menus_hold_every_command_with_its_shortcut(window):
    menus = {a.text().replace("&", ""): a.menu() for a in window.menuBar().actions()}
    assert list(menus) == ["File", "View", "Help"]
    assert titles(menus["File"]) == ["Open recording…", "Open curves…", "Open recent", "Export report…",
                                     "Export data…", "Load limits…", "Quit"]
    assert titles(menus["View"]) == [f"{i} {name}" for i, name in enumerate(PAGE_ORDER, start=1)]
    assert titles(menus["Help"]) == ["User guide", "Keyboard shortcuts", "About linpar"]
    shortcuts = {a.text().replace("&", ""): a.shortcut().toString() for a in window.menus.actions()}
    assert shortcuts["Open recording…"] == "Ctrl+O" and shortcuts["Quit"] == "Ctrl+Q"
    assert shortcuts["Export report…"] == "Ctrl+E" and shortcuts["Load limits…"] == "Ctrl+L"
    assert shortcuts["Open curves…"] == "Ctrl+Shift+O"
    assert shortcuts["1 Measure"] == "Ctrl+1" and shortcuts["User guide"] == "F1"
    assert len({s for s in shortcuts.values() if s}) == len([s for s in shortcuts.values() if s])    # no clash


def test_view_goes_to_each_page(window):
    for number, name in enumerate(PAGE_ORDER):
        window.menus.page_actions[name].trigger()
        assert window.pages.currentIndex() == number and window.pages.tabText(number) == name


def test_help_shows_the_guide_the_shortcuts_and_about(window):
    guide = window.menus.show_guide()
    assert guide.isVisible() and "Open recording" not in guide.windowTitle()
    shown = guide.browser.toPlainText()
    assert "short user guide" in shown and "NOT JUDGED" in shown and "no-signal" in shown
    assert guide_markdown().startswith("# linpar")
    shortcuts = window.menus.show_shortcuts().browser.toPlainText()
    assert "Ctrl+O" in shortcuts and "Open recording…" in shortcuts and "Ctrl+3" in shortcuts
    about = window.menus.show_about().browser.toPlainText()
    from importlib.metadata import version
    assert f"linpar {version('linpar')}" in about
    for name in DEPENDENCIES:
        assert name in about and version(name) in about
    assert "LGPL" in about and "BSD" in about and "MIT" in about       # Qt's licence, numpy's, pyqtgraph's


def test_exports_wait_for_a_result_then_write_report_and_data(qtbot, window, recordings, tmp_path, monkeypatch):
    assert not window.menus.export_report_action.isEnabled() and not window.menus.export_data_action.isEnabled()
    open_and_wait(qtbot, window, recordings["paper"])
    assert window.menus.export_report_action.isEnabled() and window.menus.export_data_action.isEnabled()
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps(LIMITS), encoding="utf-8")
    monkeypatch.setattr(QFileDialog, "getOpenFileName", lambda *a, **k: (str(limits), ""))
    window.menus.load_limits_action.trigger()
    assert window.pages.currentWidget() is window.qa and window.qa.limits is not None
    report = tmp_path / "report.html"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(report), "HTML (*.html)"))
    window.pages.setCurrentWidget(window.results)           # exported from the Results page, which stays shown
    with qtbot.waitSignal(window.qa.report_written, timeout=wait_ms(60)):
        window.menus.export_report_action.trigger()
    assert window.pages.currentWidget() is window.results
    assert "QA: FAIL" in report.read_text(encoding="utf-8")           # the paper's Bl is below LIMITS' 5.5
    assert str(report) in window.status_label.text()
    data = tmp_path / "parameters.csv"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(data), "Parameters, CSV (*.csv)"))
    window.menus.export_data_action.trigger()
    lines = data.read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("# linpar parameters")
    rows = {row["parameter"]: row for row in csv.DictReader(line for line in lines if not line.startswith("#"))}
    assert float(rows["RE"]["value"]) == window.results.result.parameters["RE"].value
    assert str(data) in window.status_label.text()


def test_export_data_says_why_a_file_type_cannot_be_written(qtbot, window, recordings, tmp_path, dialogs):
    open_and_wait(qtbot, window, recordings["paper"])
    assert not window.menus.export_data_to(tmp_path / "parameters.xlsx")
    assert dialogs and ".csv" in dialogs[-1][2] and not (tmp_path / "parameters.xlsx").exists()


def test_a_first_start_opens_on_the_wizards_first_step_and_later_starts_on_results(qtbot, tmp_path):
    settings = Settings(QSettings(str(tmp_path / "fresh.ini"), QSettings.IniFormat))
    first = MainWindow(settings)
    qtbot.addWidget(first)
    assert first.pages.currentWidget() is first.wizard
    assert first.wizard.current is first.wizard.driver_page
    first.close()                                    # saves the window: the next start is not the first
    again = MainWindow(settings)
    qtbot.addWidget(again)
    assert again.pages.currentWidget() is again.results
