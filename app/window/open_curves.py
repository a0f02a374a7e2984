"""File > Open curves…: the files of curves another tool exported (a Klippel dB-Lab/LPM export, a .zma, a REW or
text table), as `linpar analyze --impedance Z --hx HX [--mm-per-volt]` takes them. The dialog only gathers the
paths; reading them is the analysis job's (app.jobs.curves), which says in one line what is wrong with a file."""
from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (QCheckBox, QDialog, QDialogButtonBox, QFileDialog, QFormLayout, QHBoxLayout, QLabel,
                               QLineEdit, QPushButton, QVBoxLayout, QWidget)

from app.jobs.curves import CurvesRequest

CURVE_FILTER = "Curves (*.txt *.zma *.frd *.csv *.dat);;All files (*)"
INTRO = ("Curves exported by another tool: an impedance curve, and the displacement transfer function Hx = X/U "
         "for Bl and the mechanical parameters. A Klippel LPM export's own fitted curve is drawn beside linpar's.")


class OpenCurvesDialog(QDialog):
    def __init__(self, start_dir: str = "", parent=None):
        super().__init__(parent)
        self.setWindowTitle("Open curves")
        self.start_dir = start_dir
        self.impedance = QLineEdit()
        self.impedance.setPlaceholderText("required: |Z| (and phase), ohm")
        self.hx = QLineEdit()
        self.hx.setPlaceholderText("optional: |Hx| (and phase), m/V")
        self.mm_per_volt = QCheckBox("Hx in mm/V (a plain table's; a Klippel export's header says its unit)")
        intro = QLabel(INTRO)
        intro.setWordWrap(True)
        form = QFormLayout()
        form.addRow("Impedance Z:", self._with_browse(self.impedance, "Impedance curve"))
        form.addRow("Displacement Hx:", self._with_browse(self.hx, "Hx curve"))
        form.addRow("", self.mm_per_volt)
        self.buttons = QDialogButtonBox(QDialogButtonBox.Open | QDialogButtonBox.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        self.impedance.textChanged.connect(self._update)
        layout = QVBoxLayout(self)
        layout.addWidget(intro)
        layout.addLayout(form)
        layout.addWidget(self.buttons)
        self._update()
        self.resize(640, self.sizeHint().height())

    def _with_browse(self, edit: QLineEdit, title: str) -> QWidget:
        row = QWidget()
        layout = QHBoxLayout(row)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(edit, 1)
        browse = QPushButton("Browse…")
        browse.clicked.connect(lambda: self._browse(edit, title))
        layout.addWidget(browse)
        return row

    def _browse(self, edit: QLineEdit, title: str) -> None:
        start = str(Path(self.impedance.text()).parent) if self.impedance.text().strip() else self.start_dir
        path, _ = QFileDialog.getOpenFileName(self, title, start, CURVE_FILTER)
        if path:
            edit.setText(path)

    def _update(self) -> None:
        self.buttons.button(QDialogButtonBox.Open).setEnabled(bool(self.impedance.text().strip()))

    def request(self) -> CurvesRequest:
        hx = self.hx.text().strip()
        return CurvesRequest(Path(self.impedance.text().strip()), Path(hx) if hx else None,
                             self.mm_per_volt.isChecked())
