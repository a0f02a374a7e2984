"""The main window's menus: File, View and Help, their shortcuts, and the dialogs Help opens.

File: Open recording, Open curves (another tool's exported curves), Open recent, Export report…, Export data…, Load limits…, Quit. View: each page (Ctrl+1..).
Help: the user guide (resources/guide.md, shown in the window), the keyboard shortcuts, About (the
version and the licences of the libraries linpar is built on).
"""
from __future__ import annotations

import html
from importlib import metadata
from importlib.resources import files
from pathlib import Path

from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QFileDialog, QTextBrowser, QVBoxLayout

from analysis.errors import LinparError
from analysis.session import software

GUIDE = "guide.md"
# The libraries linpar is built on (pyproject.toml's dependencies), for About.
DEPENDENCIES = ("PySide6-Essentials", "pyqtgraph", "numpy", "scipy", "uncertainties", "matplotlib",
                "sounddevice", "pyserial", "JACK-Client")


def data_filters() -> dict[str, str]:
    """Export data…: file-dialog filter -> export kind, the registry's formats offered in the menu."""
    from analysis.export import exporters
    return {f"{e.title} (*{e.suffix})": e.kind for e in exporters().values() if e.in_menu}


def suffix_kind() -> dict[str, str]:
    """A file's suffix -> the export it gets (the first format of that suffix offered in the menu)."""
    from analysis.export import exporters
    kinds: dict[str, str] = {}
    for e in exporters().values():
        if e.in_menu:
            kinds.setdefault(e.suffix, e.kind)
    return kinds


def licence_of(name: str) -> str:
    """A dependency's licence as its package metadata states it (SPDX expression, classifier or text)."""
    try:
        meta = metadata.metadata(name)
    except metadata.PackageNotFoundError:
        return "not installed"
    if meta.get("License-Expression"):
        return meta["License-Expression"]
    classifiers = [c.split("::")[-1].strip() for c in meta.get_all("Classifier") or () if c.startswith("License ::")]
    if classifiers:
        return ", ".join(classifiers)
    text = (meta.get("License") or "").strip()
    return text if text and len(text) <= 60 and "\n" not in text else "see the package's licence file"


def about_html() -> str:
    rows = "".join(f"<tr><td>{html.escape(name)}</td><td>{html.escape(_version(name))}</td>"
                   f"<td>{html.escape(licence_of(name))}</td></tr>" for name in DEPENDENCIES)
    return (f"<h2>{html.escape(software())}</h2><p>Loudspeaker linear parameters from one multitone "
            "measurement of voltage, current and cone displacement.</p>"
            f"<h3>Built on</h3><table cellpadding='3'><tr><th align='left'>library</th><th align='left'>version"
            f"</th><th align='left'>licence</th></tr>{rows}</table>")


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "–"


def guide_markdown() -> str:
    return files("resources").joinpath(GUIDE).read_text(encoding="utf-8")


class TextDialog(QDialog):
    """A non-modal window with one text (Help's three dialogs)."""

    def __init__(self, title: str, parent=None):
        super().__init__(parent)
        self.setWindowTitle(title)
        self.browser = QTextBrowser()
        self.browser.setOpenExternalLinks(True)
        buttons = QDialogButtonBox(QDialogButtonBox.Close)
        buttons.rejected.connect(self.close)
        layout = QVBoxLayout(self)
        layout.addWidget(self.browser)
        layout.addWidget(buttons)
        self.resize(640, 560)


class Menus:
    """Builds the menus on `window` (app.window.main_window.MainWindow) and answers their actions."""

    def __init__(self, window):
        self.window = window
        self.dialogs: dict[str, TextDialog] = {}
        bar = window.menuBar()
        file_menu = bar.addMenu("&File")
        self.open_action = self._action(file_menu, "&Open recording…", QKeySequence.Open, window.on_open)
        self.open_curves_action = self._action(file_menu, "Open &curves…", "Ctrl+Shift+O", window.on_open_curves)
        window.recent_menu = file_menu.addMenu("Open &recent")
        file_menu.addSeparator()
        self.export_report_action = self._action(file_menu, "Export &report…", "Ctrl+E", self.on_export_report)
        self.export_data_action = self._action(file_menu, "Export &data…", "Ctrl+Shift+E", self.on_export_data)
        self.load_limits_action = self._action(file_menu, "Load &limits…", "Ctrl+L", self.on_load_limits)
        file_menu.addSeparator()
        self.quit_action = self._action(file_menu, "&Quit", "Ctrl+Q", window.close)

        view_menu = bar.addMenu("&View")
        self.page_actions = {}
        for number in range(window.pages.count()):
            name = window.pages.tabText(number)
            self.page_actions[name] = self._action(view_menu, f"&{number + 1} {name}", f"Ctrl+{number + 1}",
                                                   lambda _=False, n=number: window.pages.setCurrentIndex(n))

        help_menu = bar.addMenu("&Help")
        self.guide_action = self._action(help_menu, "User &guide", QKeySequence.HelpContents, self.show_guide)
        self.shortcuts_action = self._action(help_menu, "&Keyboard shortcuts", None, self.show_shortcuts)
        self.about_action = self._action(help_menu, "&About linpar", None, self.show_about)
        self.update()

    def _action(self, menu, text: str, shortcut, slot) -> QAction:
        action = QAction(text, self.window)
        if shortcut is not None:
            action.setShortcut(QKeySequence(shortcut))
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def update(self) -> None:
        """Exports need a result: disabled (and saying why) until one is shown."""
        has_result = self.window.results.result is not None
        for action in (self.export_report_action, self.export_data_action):
            action.setEnabled(has_result)
            action.setStatusTip("" if has_result else "Open or measure a recording first")

    # -- File ------------------------------------------------------------------
    def on_export_report(self) -> None:
        """The QA page writes reports (with its verdict against the loaded limits); the page shown stays: the
        status bar says when it is written, a message why it could not be."""
        self.window.qa.on_export()

    def on_load_limits(self) -> None:
        self.window.pages.setCurrentWidget(self.window.qa)
        self.window.qa.on_load_limits()

    def on_export_data(self) -> None:
        result = self.window.results.result
        if result is None:
            return
        stem = result.source.with_suffix("").name if result.source else "parameters"
        start = str(result.source.with_name(stem + ".csv")) if result.source else "parameters.csv"
        filters = data_filters()
        path, chosen = QFileDialog.getSaveFileName(self.window, "Export data", start, ";;".join(filters))
        if path:
            self.export_data_to(Path(path), filters.get(chosen))

    def export_data_to(self, path: Path, kind: str | None = None) -> bool:
        """Write the shown result as `kind` (from the suffix when None); False, and why, when it cannot be."""
        from analysis.archive.results import StoredResult, header_of_recording, results_document
        from analysis.export import write_exports
        from analysis.recording.format import read_recording
        result = self.window.results.result
        suffixes = suffix_kind()
        kind = kind or suffixes.get(path.suffix.lower())
        if result is None or kind is None:
            self.window.show_error("Cannot export", f"{path.name}: choose one of "
                                   f"{', '.join(suffixes)} (the file type says what is written)")
            return False
        try:
            if not hasattr(result, "spectra"):      # imported curves (File > Open curves…): no recording to read
                from analysis.curves.stored import curve_header, curve_results_document
                stored = StoredResult.from_json(curve_results_document(result))
                header = curve_header(result)
            else:
                recording = read_recording(result.source) if result.source and Path(result.source).exists() else None
                stored = StoredResult.from_json(results_document(result, recording))
                header = header_of_recording(recording) if recording is not None else {}
            written = write_exports(stored, {kind: path}, header)
        except (LinparError, OSError) as exc:
            self.window.show_error(f"Cannot export {path.name}", str(exc))
            return False
        self.window.status_label.setText(f"Written: {', '.join(str(p) for p in written)}")
        return True

    # -- Help ------------------------------------------------------------------
    def _dialog(self, key: str, title: str) -> TextDialog:
        dialog = self.dialogs.get(key)
        if dialog is None:
            dialog = self.dialogs[key] = TextDialog(title, self.window)
        dialog.show()
        dialog.raise_()
        return dialog

    def show_guide(self) -> TextDialog:
        dialog = self._dialog("guide", "linpar user guide")
        dialog.browser.setMarkdown(guide_markdown())
        return dialog

    def show_shortcuts(self) -> TextDialog:
        dialog = self._dialog("shortcuts", "Keyboard shortcuts")
        rows = "".join(f"<tr><td><b>{html.escape(a.shortcut().toString(QKeySequence.NativeText))}</b></td>"
                       f"<td>{html.escape(a.text().replace('&', '').lstrip('0123456789 '))}</td></tr>"
                       for a in self.actions() if not a.shortcut().isEmpty())
        dialog.browser.setHtml(f"<h3>Keyboard shortcuts</h3><table cellpadding='4'>{rows}</table>")
        return dialog

    def show_about(self) -> TextDialog:
        dialog = self._dialog("about", "About linpar")
        dialog.browser.setHtml(about_html())
        return dialog

    def actions(self) -> list[QAction]:
        return [self.open_action, self.open_curves_action, self.export_report_action, self.export_data_action, self.load_limits_action,
                self.quit_action, *self.page_actions.values(), self.guide_action, self.shortcuts_action,
                self.about_action]
