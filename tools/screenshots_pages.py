"""Every page at 1280x720 and at 1920x1080, after a measurement is shown (tools/screenshots.py --only pages).

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only pages

Writes page-<page>-<W>x<H>.png for the Results page (each plot tab), the Model lab with a ranked
diagnosis, Series, Large signal, QA and Archive, and page-measure-<step>-<W>x<H>.png for each step of the
wizard run on the in-process simulator; page-measure-level-empty-*.png is the Level step before its
check, with the plots' placeholders.
"""
from __future__ import annotations

import sys
from pathlib import Path

from PySide6.QtWidgets import QApplication

from tools.screenshot_kit import (ANALYSIS_TIMEOUT_S, grab_small_and_large, settle, synthetic_recording, wait_for,
                                  wait_for_click)


def every_page_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    written: list[Path] = []

    def shoot(stem: str) -> None:
        written.extend(grab_small_and_large(app, window, out, f"page-{stem}"))

    wizard = window.wizard
    wizard.state.settings.setValue("measure/out_dir", str(folder / "measurements"))
    window.pages.setCurrentWidget(wizard)
    shoot("measure-driver")
    page = wizard.driver_page
    page.name_edit.setText("W18-PAPER")
    page.sd_value.setValue(133.0)
    wizard.next_button.click()
    hardware = wizard.hardware_page
    hardware.simulator_radio.setChecked(True)
    hardware.realtime_check.setChecked(False)
    wait_for_click(hardware.test_audio_button, hardware.audio_jobs.busy_changed)
    shoot("measure-hardware")
    wizard.next_button.click()
    calibration = wizard.calibration_page
    wait_for_click(calibration.measure_button, calibration.jobs.busy_changed)
    shoot("measure-calibration")
    wizard.next_button.click()
    level = wizard.level_page
    shoot("measure-level-empty")
    wait_for_click(level.run_button, level.jobs.busy_changed)
    shoot("measure-level")
    wizard.next_button.click()
    measure = wizard.measure_page
    shoot("measure-measure-empty")
    wait_for_click(measure.start_button, measure.jobs.busy_changed)
    shoot("measure-measure")
    wizard.next_button.click()
    shoot("measure-results")

    window.open_path(synthetic_recording(folder))
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        print("screenshots: the recording was not analysed in time", file=sys.stderr)
        return written
    window.pages.setCurrentWidget(window.results)
    tabs = window.results.plot_tabs
    for index, name in enumerate(("results", "results-displacement", "results-spl")):
        tabs.setCurrentIndex(index)
        shoot(name)
    tabs.setCurrentIndex(0)
    window.pages.setCurrentWidget(window.model_lab)
    settle(app)
    lab = window.model_lab
    lab.candidates.diagnose_button.click()
    wait_for(lab.diagnosis_shown, ANALYSIS_TIMEOUT_S)
    shoot("model-lab")
    for widget, name in ((window.series, "series"), (window.large_signal, "large-signal"), (window.qa, "qa"),
                         (window.archive, "archive")):
        window.pages.setCurrentWidget(widget)
        shoot(name)
    return written
