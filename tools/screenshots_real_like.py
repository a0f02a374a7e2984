"""The Model lab on a real-like woofer, and the New effect… dialog it leads to (screenshots.py --only real-like).

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only real-like

Writes model-lab-real-like-<W>x<H>.png: the recording of tests/real_like.py (six physics at once, none in
the catalogue's exact form, 65,536-sample periods) after the greedy path, with the site the misfit left
belongs to; and model-lab-new-effect-phase-<W>x<H>.png: the New effect… dialog opened from there, at the
site the diagnosis named, with a formula typed and its change drawn in size and in phase.
"""
from __future__ import annotations

import sys
from pathlib import Path

from PySide6.QtWidgets import QApplication

from analysis.recording import write_recording
from tools.screenshot_kit import ANALYSIS_TIMEOUT_S, grab_small_and_large, settle, wait_for

DIAGNOSIS_TIMEOUT_S = 10 * ANALYSIS_TIMEOUT_S     # a path of steps on a busy machine


def real_like_screenshots(app: QApplication, window, folder: Path, out: Path, open_in_lab) -> list[Path]:
    from tests.real_like import real_like_recording
    wav, _ = write_recording(folder / "woofer-real-like", real_like_recording())
    if not open_in_lab(app, window, wav, "real-like"):
        return []
    lab = window.model_lab
    lab.candidates.follow_button.click()
    if not wait_for(lab.diagnosis_shown, DIAGNOSIS_TIMEOUT_S):
        print("screenshots: the diagnosis of the real-like recording did not finish in time", file=sys.stderr)
        return []
    written = grab_small_and_large(app, window, out, "model-lab-real-like")
    lab.catalogue.new_effect_button.click()
    dialog = lab.new_effect_dialog
    # The diagnosis names the displacement site (the laser's spot on the outer cone): the spot's transmissibility
    # with structural damping, started near the mode, drawn over the misfit in size and in phase.
    dialog.id_edit.setText("cone-spot-structural")
    dialog.title_edit.setText("The laser spot riding a cone mode with structural damping")
    dialog.physics_edit.setPlainText("The spot on the outer cone is carried by the cone's own stiffness k(1 + j eta): "
                                     "it moves more than the coil near the mode and less above it.")
    dialog.set_parameter(0, "f0", "Hz", "1800", "200", "10000")
    dialog.set_parameter(1, "eta", "1", "0.2", "0.01", "1")
    dialog.formula_edit.setText("(2*pi*f0)**2 * (1 + j*eta) / ((2*pi*f0)**2 * (1 + j*eta) + s**2)")
    dialog.timer.stop()
    dialog.check()
    settle(app)
    written += grab_small_and_large(app, dialog, out, "model-lab-new-effect-phase")
    dialog.reject()
    return written
