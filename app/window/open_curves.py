"""File > Open curves…: the files of curves another tool exported, as `linpar analyze` takes them: an impedance
curve and an Hx curve (a Klippel dB-Lab/LPM export, a .zma, a REW or text table; `--impedance Z --hx HX
[--mm-per-volt]`), or one CSV of complex voltage, current and laser spectra (`--uiv FILE`). The dialog only gathers
the paths; reading them is the analysis job's (app.jobs.curves), which says in one line what is wrong with a file,
and what it is when it was given as the other kind."""
from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (QButtonGroup, QCheckBox, QDialog, QDialogButtonBox, QFileDialog, QFormLayout,
                               QHBoxLayout, QLabel, QLineEdit, QPushButton, QRadioButton, QVBoxLayout, QWidget)

from app.jobs.curve_kinds import CURVES_CHOICE, UIV_CHOICE, UIV_COLUMNS
from app.jobs.curves import CurvesRequest

CURVE_FILTER = "Curves (*.txt *.zma *.frd *.csv *.dat);;All files (*)"
UIV_FILTER = "Spectra (*.csv *.txt *.dat);;All files (*)"
INTRO = ("Curves exported by another tool: an impedance curve, and the displacement transfer function Hx = X/U "
         "for Bl and the mechanical parameters (a Klippel LPM export's own fitted curve is drawn beside linpar's); "
         "or one file of complex voltage, current and laser spectra, from which linpar takes Z = U/I and Hx.")


class OpenCurvesDialog(QDialog):
    def __init__(self, start_dir: str = "", parent=None):
        super().__init__(parent)
        self.setWindowTitle("Open curves")
        self.start_dir = start_dir
        self.curves_choice = QRadioButton(CURVES_CHOICE)
        self.uiv_choice = QRadioButton(UIV_CHOICE)
        self.curves_choice.setChecked(True)
        kinds = QButtonGroup(self)
        kinds.addButton(self.curves_choice)
        kinds.addButton(self.uiv_choice)
        self.impedance = QLineEdit()
        self.impedance.setPlaceholderText("required: |Z| (and phase), ohm")
        self.hx = QLineEdit()
        self.hx.setPlaceholderText("optional: |Hx| (and phase), m/V")
        self.mm_per_volt = QCheckBox("Hx in mm/V (a plain table's; a Klippel export's header says its unit)")
        self.uiv = QLineEdit()
        self.uiv.setPlaceholderText(f"CSV with columns {UIV_COLUMNS} (or X_re, X_im: displacement)")
        intro = QLabel(INTRO)
        intro.setWordWrap(True)
        choice_row = QHBoxLayout()
        choice_row.addWidget(self.curves_choice)
        choice_row.addWidget(self.uiv_choice)
        choice_row.addStretch(1)
        form = QFormLayout()
        self._curve_rows = (self._with_browse(self.impedance, "Impedance curve", CURVE_FILTER),
                            self._with_browse(self.hx, "Hx curve", CURVE_FILTER), self.mm_per_volt)
        form.addRow("Impedance Z:", self._curve_rows[0])
        form.addRow("Displacement Hx:", self._curve_rows[1])
        form.addRow("", self.mm_per_volt)
        self._uiv_row = self._with_browse(self.uiv, "U, I and laser spectra", UIV_FILTER)
        form.addRow("U, I, V spectra:", self._uiv_row)
        self.buttons = QDialogButtonBox(QDialogButtonBox.Open | QDialogButtonBox.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        for edit in (self.impedance, self.uiv):
            edit.textChanged.connect(self._update)
        self.uiv_choice.toggled.connect(self._update)
        layout = QVBoxLayout(self)
        layout.addWidget(intro)
        layout.addLayout(choice_row)
        layout.addLayout(form)
        layout.addWidget(self.buttons)
        self._update()
        self.resize(680, self.sizeHint().height())

    def _with_browse(self, edit: QLineEdit, title: str, file_filter: str) -> QWidget:
        row = QWidget()
        layout = QHBoxLayout(row)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(edit, 1)
        browse = QPushButton("Browse…")
        browse.clicked.connect(lambda: self._browse(edit, title, file_filter))
        layout.addWidget(browse)
        return row

    def _browse(self, edit: QLineEdit, title: str, file_filter: str) -> None:
        given = next((e.text().strip() for e in (edit, self.impedance, self.uiv) if e.text().strip()), "")
        start = str(Path(given).parent) if given else self.start_dir
        path, _ = QFileDialog.getOpenFileName(self, title, start, file_filter)
        if path:
            edit.setText(path)

    def _update(self) -> None:
        uiv = self.uiv_choice.isChecked()
        # The other kind's rows stay in place, greyed: the dialog does not change its shape under the pointer.
        for row in self._curve_rows:
            row.setEnabled(not uiv)
        self._uiv_row.setEnabled(uiv)
        needed = self.uiv if uiv else self.impedance
        self.buttons.button(QDialogButtonBox.Open).setEnabled(bool(needed.text().strip()))

    def request(self) -> CurvesRequest:
        if self.uiv_choice.isChecked():
            return CurvesRequest(uiv=Path(self.uiv.text().strip()))
        hx = self.hx.text().strip()
        return CurvesRequest(Path(self.impedance.text().strip()), Path(hx) if hx else None,
                             self.mm_per_volt.isChecked())
