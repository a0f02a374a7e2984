"""The Results page on a Klippel LPM export (File > Open curves…) with the export's own fit overlaid
(screenshots.py --only curves).

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only curves

Writes results-lpm-overlay-z-<W>x<H>.png and results-lpm-overlay-hx-<W>x<H>.png: the 6.5" mid-woofer's |Z| and
|Hx| of tests/lpm_exports.py (a realistic driver, magnitude only, noisy), linpar's fit and the export's "Fitted"
curve as a dashed third line, the comparison of the two fits above, once the model part is estimated;
qa-imported-curves-<W>x<H>.png, the QA page on them (no signal, noise or distortion checks: judged by their fit);
and open-curves-dialog.png, the dialog with the two files chosen.
"""
from __future__ import annotations

import sys
from pathlib import Path

from PySide6.QtWidgets import QApplication

from tools.screenshot_kit import ANALYSIS_TIMEOUT_S, grab_small_and_large, settle, wait_for


def curves_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from app.window.open_curves import OpenCurvesDialog
    from tests.lpm_exports import write_exports
    z, hx = write_exports(folder / "lpm", "midwoofer")
    dialog = OpenCurvesDialog(str(folder), window)
    dialog.impedance.setText(str(z))
    dialog.hx.setText(str(hx))
    dialog.show()
    settle(app)
    path = out / "open-curves-dialog.png"
    dialog.grab().save(str(path))
    written = [path]
    request = dialog.request()
    dialog.close()
    window.open_curves(request)
    if not wait_for(window.model_part_shown, 4 * ANALYSIS_TIMEOUT_S):
        print("screenshots: the LPM export's analysis did not finish in time", file=sys.stderr)
        return written
    window.pages.setCurrentWidget(window.results)
    tabs = window.results.plot_tabs
    for index, stem in ((0, "results-lpm-overlay-z"), (1, "results-lpm-overlay-hx")):
        tabs.setCurrentIndex(index)
        written += grab_small_and_large(app, window, out, stem)
    tabs.setCurrentIndex(0)
    window.pages.setCurrentWidget(window.qa)
    written += grab_small_and_large(app, window, out, "qa-imported-curves")
    window.pages.setCurrentWidget(window.results)
    return written
