"""The model lab's "New effect…" dialog: write an effect of one's own, checked as one types, and save it.

The form holds exactly what an effect file holds (analysis.effects.user): id, title, site, formula,
physics and the parameters with their unit, start and bounds. Every change is turned into the file's
text and read back by the same checks the command line uses, so the dialog says the same one line a
bad file would get. While the effect is valid, its signature on the current data is drawn beside the
misfit the current version leaves (analysis.effect_preview), in size and in phase: the user sees whether
the formula bends the model where the data need it. The site starts at the one the diagnosis named.
Saving writes ID.toml to the user folder and registers the effect.
"""
from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt, QTimer, Signal, Slot
from PySide6.QtGui import QFont
from PySide6.QtWidgets import (QComboBox, QDialog, QDialogButtonBox, QFormLayout, QHBoxLayout, QHeaderView, QLabel,
                               QLineEdit, QPlainTextEdit, QPushButton, QTableWidget, QTableWidgetItem, QVBoxLayout,
                               QWidget)

from analysis.effect_preview import channel_misfit, signature
from analysis.effects import registry
from analysis.effects.base import SITE_KEYS, Site
from analysis.effects.file_error import EffectFileError
from analysis.effects.formula import FUNCTIONS
from analysis.effects.user import (UNITS_AT_SITE, ParameterEntry, UserEffect, effect_file_text, effect_from_text,
                                   load_effect_file)
from analysis.fit.least_squares import FitResult
from analysis.model.composed import ModelError
from app.widgets import style
from app.widgets.plots import LogFrequencyAxis, style_plot

CHECK_DELAY_MS = 200            # a pause in typing, then the check
SOURCE = "the new effect"       # how the checks name the form (their lines start with it)
COLUMNS = ("name", "unit", "start", "min", "max")
CHANGE_COLOUR = "#1f6fb4"
MISFIT_COLOUR = "#9a9a9a"
OK_COLOUR, BAD_COLOUR = "#1b6e20", "#8e1b1b"
CHANNEL_TITLES = {"impedance": "Z", "displacement": "Hx"}
NAMES_HINT = ("Names: s (= jω), w (ω), f (Hz), ws (2π·fs of the fit), j, pi and the parameters below. Functions: "
              + " ".join(FUNCTIONS) + ".")


class SignaturePlot(pg.PlotWidget):
    """One channel, one part: the misfit left (grey points) and what the new effect changes (blue line), as a
    change of size in % or of phase in degrees. A misfit far from 1 may be almost all phase: both are drawn."""

    def __init__(self, channel: str, part: str = "size", parent=None):
        super().__init__(parent=parent, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.part = part
        plot = self.getPlotItem()
        style_plot(plot, "change of size (%)" if part == "size" else "change of phase (°)", bottom="frequency (Hz)")
        plot.setMenuEnabled(False)
        plot.getAxis("left").enableAutoSIPrefix(False)
        # Short: two plots share the width, and a title wider than its plot pushes the plot out of view.
        plot.setTitle(f"{CHANNEL_TITLES.get(channel, channel)}, {part}: "
                      f"<span style='color:{MISFIT_COLOUR}'>● misfit</span>"
                      f" <span style='color:{CHANGE_COLOUR}'>━ new effect</span>", size="9pt")
        plot.addItem(pg.InfiniteLine(pos=0.0, angle=0, movable=False, pen=pg.mkPen(style.GUIDE, width=1)))
        self.misfit = pg.PlotDataItem(pen=None, symbol="o", symbolSize=3, symbolPen=None,
                                      symbolBrush=pg.mkBrush(MISFIT_COLOUR))
        self.change = pg.PlotDataItem(pen=pg.mkPen(CHANGE_COLOUR, width=2))
        plot.addItem(self.misfit)
        plot.addItem(self.change)

    def _shown(self, x: np.ndarray) -> np.ndarray:
        """x (a ratio less 1) as this plot shows it; the phase of a magnitude-only misfit is unknown (NaN)."""
        if self.part == "size":
            return 100.0 * (np.abs(1.0 + x) - 1.0)
        if not np.iscomplexobj(x):
            return np.full(len(x), np.nan)
        return np.degrees(np.angle(1.0 + x))

    def draw(self, freqs: np.ndarray, misfit: np.ndarray, change: np.ndarray | None) -> None:
        """The misfit left and the effect's change (None: not drawn)."""
        self.misfit.setData(freqs, self._shown(misfit), connect="finite")
        self.change.setData(freqs, self._shown(change) if change is not None else np.full(len(freqs), np.nan),
                            connect="finite")


class NewEffectDialog(QDialog):
    saved = Signal(object)          # the UserEffect, once written to the user folder and registered

    def __init__(self, fit: FitResult | None = None, folder: Path | None = None, parent=None,
                 site: Site | None = None):
        super().__init__(parent)
        self.setWindowTitle("New effect")
        self.fit = fit
        self.folder = folder
        self.effect: UserEffect | None = None
        self.text = ""
        self.timer = QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(CHECK_DELAY_MS)
        self.timer.timeout.connect(self.check)

        self.id_edit = QLineEdit()
        self.id_edit.setPlaceholderText("e.g. rms-sqrt-f (letters, digits, -)")
        self.title_edit = QLineEdit()
        self.title_edit.setPlaceholderText("what it is, in a few words")
        self.site_combo = QComboBox()
        for each, key in SITE_KEYS.items():
            self.site_combo.addItem(f"{key}: {UNITS_AT_SITE[each]}", key)
        # The site the diagnosis named, when there is one: that is where the user is writing an effect for.
        self.site_combo.setCurrentIndex(list(SITE_KEYS).index(site or Site.MECHANICAL))
        self.formula_edit = QLineEdit()
        mono = QFont("monospace")
        mono.setStyleHint(QFont.TypeWriter)
        self.formula_edit.setFont(mono)
        self.formula_edit.setPlaceholderText("e.g. r * (sqrt(w / ws) - 1)")
        hint = QLabel(html.escape(NAMES_HINT))
        hint.setWordWrap(True)
        hint.setStyleSheet(f"color: {style.MISSING_TEXT}")
        self.physics_edit = QPlainTextEdit()
        self.physics_edit.setPlaceholderText("the physics in a sentence or two, for whoever reads the report")
        self.physics_edit.setFixedHeight(60)

        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels([c.capitalize() for c in COLUMNS])
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.Stretch)
        self.table.verticalHeader().setVisible(False)
        self.table.setMinimumHeight(110)
        self.add_button = QPushButton("Add parameter")
        self.remove_button = QPushButton("Remove parameter")
        buttons_row = QHBoxLayout()
        buttons_row.addWidget(self.add_button)
        buttons_row.addWidget(self.remove_button)
        buttons_row.addStretch(1)

        self.status = QLabel()
        self.status.setWordWrap(True)
        self.status.setTextFormat(Qt.RichText)
        self.status.setTextInteractionFlags(Qt.TextSelectableByMouse)

        form = QFormLayout()
        form.addRow("Id", self.id_edit)
        form.addRow("Title", self.title_edit)
        form.addRow("Site", self.site_combo)
        form.addRow("Formula", self.formula_edit)
        form.addRow("", hint)
        form.addRow("Physics", self.physics_edit)
        left = QVBoxLayout()
        left.addLayout(form)
        left.addWidget(QLabel("<b>Parameters</b> (each needs a unit, a start value and both bounds)"))
        left.addWidget(self.table, 1)
        left.addLayout(buttons_row)
        left.addWidget(self.status)

        channels = tuple(fit.channels) if fit is not None else ()
        self.plots = {name: SignaturePlot(name) for name in channels}
        self.phase_plots = {name: SignaturePlot(name, "phase") for name in channels}
        right = QVBoxLayout()
        self.preview_note = QLabel()
        self.preview_note.setWordWrap(True)
        right.addWidget(self.preview_note)
        for name in channels:           # size and phase side by side, a row per channel
            row = QHBoxLayout()
            row.addWidget(self.plots[name], 1)
            row.addWidget(self.phase_plots[name], 1)
            right.addLayout(row, 1)
        if fit is None:
            self.preview_note.setText("Open a recording to see the new effect's signature on its data.")

        self.buttons = QDialogButtonBox(QDialogButtonBox.Save | QDialogButtonBox.Cancel)
        self.save_button = self.buttons.button(QDialogButtonBox.Save)
        self.save_button.setText("Save to the user folder")
        self.save_button.setToolTip(str(self.folder or registry.user_folder()))
        columns = QHBoxLayout()
        left_box, right_box = QWidget(), QWidget()
        left_box.setLayout(left)
        right_box.setLayout(right)
        columns.addWidget(left_box, 5)
        columns.addWidget(right_box, 6)
        layout = QVBoxLayout(self)
        layout.addLayout(columns, 1)
        layout.addWidget(self.buttons)

        for edit in (self.id_edit, self.title_edit, self.formula_edit):
            edit.textChanged.connect(self.on_changed)
        self.physics_edit.textChanged.connect(self.on_changed)
        self.site_combo.currentIndexChanged.connect(self.on_changed)
        self.table.itemChanged.connect(self.on_changed)
        self.add_button.clicked.connect(self.on_add_parameter)
        self.remove_button.clicked.connect(self.on_remove_parameter)
        self.buttons.accepted.connect(self.on_save)
        self.buttons.rejected.connect(self.reject)
        self.resize(1100, 640)
        self.check()

    # -- the form ------------------------------------------------------------
    def set_parameter(self, row: int, name: str, unit: str, start: str, low: str, high: str) -> None:
        if row >= self.table.rowCount():
            self.table.setRowCount(row + 1)
        for column, text in enumerate((name, unit, start, low, high)):
            self.table.setItem(row, column, QTableWidgetItem(text))

    def parameters(self) -> list[ParameterEntry]:
        rows = []
        for row in range(self.table.rowCount()):
            cells = [(self.table.item(row, c).text().strip() if self.table.item(row, c) else "") for c in range(5)]
            if any(cells):
                rows.append(ParameterEntry(*cells))
        return rows

    def file_text(self) -> str:
        return effect_file_text(self.id_edit.text().strip(), self.title_edit.text().strip(),
                                self.site_combo.currentData(), self.formula_edit.text(),
                                self.physics_edit.toPlainText().strip(), self.parameters())

    # -- checking --------------------------------------------------------------
    @Slot()
    def on_changed(self, *_args) -> None:
        self.timer.start()

    @Slot()
    def check(self) -> None:
        """Read the form back as a file would be read; show the one line of the first problem, or the preview."""
        self.text = self.file_text()
        taken, ids = registry.taken_names()
        try:
            self.effect = effect_from_text(self.text, SOURCE, taken, ids)
        except EffectFileError as exc:
            self.effect = None
            message = str(exc).removeprefix(f"{SOURCE}: ")
            self._say(BAD_COLOUR, f"✗ {message}")
            self._preview(None)
            return
        self._say(OK_COLOUR, f"✓ {self.effect.id}: {self.effect.formula.text} ({UNITS_AT_SITE[self.effect.site]}) "
                             "reads like a valid effect file.")
        self._preview(self.effect)

    def _say(self, colour: str, text: str) -> None:
        self.status.setText(f"<span style='color:{colour}'>{html.escape(text)}</span>")
        self.save_button.setEnabled(self.effect is not None)

    def _preview(self, effect: UserEffect | None) -> None:
        if self.fit is None:
            return
        try:
            channels = signature(self.fit, effect) if effect is not None else None
        except (ModelError, ValueError) as exc:
            self.preview_note.setText(f"No preview on this recording: {exc}")
            channels = None
        if channels is None:
            for name, ch in self.fit.channels.items():
                for plots in (self.plots, self.phase_plots):
                    plots[name].draw(ch.freqs, channel_misfit(ch), None)
            if effect is None:
                self.preview_note.setText("The misfit of the current version; the new effect's change is drawn "
                                          "over it once the form reads as a valid effect.")
            return
        self.preview_note.setText(f"What {effect.id} changes at its start values (the rest at the current version's "
                                  f"fit, {self.fit.model.describe()}), over the misfit that version leaves.")
        for ch in channels:
            for plots in (self.plots, self.phase_plots):
                plots[ch.channel].draw(ch.freqs, ch.misfit, ch.change)

    # -- buttons -------------------------------------------------------------
    @Slot()
    def on_add_parameter(self) -> None:
        self.set_parameter(self.table.rowCount(), "", "1", "0", "-1", "1")
        self.table.editItem(self.table.item(self.table.rowCount() - 1, 0))

    @Slot()
    def on_remove_parameter(self) -> None:
        row = self.table.currentRow()
        if row >= 0:
            self.table.removeRow(row)
            self.on_changed()

    @Slot()
    def on_save(self) -> None:
        self.timer.stop()
        self.check()
        if self.effect is None:
            return
        taken, ids = registry.taken_names()
        try:
            path = registry.save_effect_file(self.text, self.effect.id, self.folder)
            saved = load_effect_file(path, taken, ids)      # as the next start will read it
        except (EffectFileError, OSError) as exc:
            self._say(BAD_COLOUR, f"✗ not saved: {exc}")
            return
        registry.register([saved])
        self.saved.emit(saved)
        self.accept()
