"""The Results page and the report of a realistic woofer, with each uncertainty's noise and model parts
(screenshots.py --only model-part).

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only model-part

Writes results-model-part-estimating-<W>x<H>.png (the statistical result, shown at once, while the model
part's refits run), results-model-part-<W>x<H>.png (the parts arrived: the fit error of each curve, what the
model part came to, "Mms ±… g noise, ±… g model" under the table) and report-model-part-<W>x<H>.png (the
report's first page, its parameter notes naming both parts, rendered from its PDF by pdftoppm when
installed) for tests/realistic_drivers.py's woofer.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QApplication

from analysis.recording import write_recording
from tools.screenshot_kit import ANALYSIS_TIMEOUT_S, SMALL_AND_LARGE, grab_small_and_large, wait_for

MODEL_PART_TIMEOUT_S = 4 * ANALYSIS_TIMEOUT_S       # a few seconds of refits, on a busy machine


def model_part_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tests.realistic_drivers import realistic_recording
    wav, _ = write_recording(folder / "woofer-realistic", realistic_recording("woofer", 0))
    written: list[Path] = []
    window.analysis_shown.connect(lambda _outcome: written.extend(
        grab_small_and_large(app, window, out, "results-model-part-estimating")))
    window.open_path(wav)
    if not wait_for(window.model_part_shown, MODEL_PART_TIMEOUT_S):
        print("screenshots: the model part of the realistic woofer did not arrive in time", file=sys.stderr)
        return written
    window.pages.setCurrentWidget(window.results)
    written += grab_small_and_large(app, window, out, "results-model-part")
    written += report_pages(window.results.result, folder, out, "report-model-part")
    return written


def report_pages(result, folder: Path, out: Path, stem: str) -> list[Path]:
    """The report's first page as PNGs at both sizes' heights (white margins), from its PDF by pdftoppm."""
    from analysis.archive.results import StoredResult, calibration_of, header_of_recording, results_document
    from analysis.recording.format import read_recording
    from analysis.report import build_report, write_report
    if shutil.which("pdftoppm") is None:
        print("screenshots: no pdftoppm (poppler-utils): the report's page is not drawn", file=sys.stderr)
        return []
    recording = read_recording(result.source)
    stored = StoredResult.from_json(results_document(result, recording))
    content = build_report(stored, header_of_recording(recording, result.source), None, calibration_of(recording))
    pdf = folder / f"{stem}.pdf"
    write_report(content, pdf=pdf)
    written = []
    for width, height in SMALL_AND_LARGE:
        prefix = folder / f"{stem}-{height}"
        subprocess.run(["pdftoppm", "-png", "-f", "1", "-l", "1", "-scale-to-y", str(height), "-scale-to-x", "-1",
                        str(pdf), str(prefix)], check=True, capture_output=True)
        page = QImage(str(next(folder.glob(f"{stem}-{height}*.png"))))
        canvas = QImage(width, height, QImage.Format_RGB32)
        canvas.fill(0xFFFFFF)
        painter = QPainter(canvas)
        painter.drawImage((width - page.width()) // 2, 0, page)
        painter.end()
        path = out / f"{stem}-{width}x{height}.png"
        canvas.save(str(path))
        written.append(path)
    return written
