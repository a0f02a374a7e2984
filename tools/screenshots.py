"""Screenshots of the main window on a synthetic recording, for docs and for looking at.

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] [--only archive|model-lab|large-signal|production|qa]

Writes results.png (and one PNG per Results plot tab and per other page) to
docs/screenshots/ unless OUTDIR is given, then model-lab-before.png and
model-lab-after.png: a recording whose laser lags by 100 us, diagnosed in the
Model lab, before and after applying the top candidate;
model-lab-unexplained-1280x720.png and -1920x1080.png: a recording with
damping the catalogue lacks, the greedy path ending "unexplained" with the
mechanical site's correction plotted (--only model-lab: just the Model lab's
screenshots); then wizard-1-driver.png
.. wizard-6-results.png: the measurement wizard run on the in-process
simulator, live-panels.png: the live panels in the middle of a real-time
measurement, and qa-measured.png, qa-limits.png, qa-invalid.png: the QA page on
the measured driver, with limits, and on a recording whose current input was
disconnected; then archive-list.png and archive-compare.png: the Archive page
with a batch of drivers stored (and the wizard's measurement), four of them
compared (--only archive: just these two, without the wizard's measurement);
model-lab-new-effect-1280x720.png and -1920x1080.png: the "New effect…" dialog
with the effect a recording lacks written in it (damping rising as sqrt(f)),
and model-lab-own-effect-*.png: the lab once it is saved and checked, reduced
chi^2 down to 1 (--only new-effect: just these).
--only real-like: the Model lab on a real-like woofer and the New effect… dialog with its phase panel
(tools/screenshots_real_like.py).
large-signal-1280x720.png and -1920x1080.png: the Large-signal page on the
known-polynomial driver at three levels (--only large-signal: just these).
production-1280x720.png and production-1920x1080.png: the Production page
over 240 units from three stations, fs drifting 2 sigma up from unit 150 and
station QA3 reading high, its control chart with the alarms flagged
(--only production: just these two).
--only model-part: the Results page of a realistic woofer while its model part is estimated and after, and
its report's first page, at both sizes (tools/screenshots_model_part.py).
--only curves: the Results page on a Klippel LPM export with the export's own fit overlaid, and the QA page on it, at both sizes
(tools/screenshots_curves.py).
--only verdicts: the Results page and QA's PASS, UNCERTAIN, FAIL and INVALID at both sizes
(tools/screenshots_verdicts.py).
--only pages: every page and every wizard step at both sizes (tools/screenshots_pages.py).
--only production-counts: production-4-units-*.png and production-40-units-*.png, the capability
indices greyed below 25 units, with their 95 % intervals.
--only first-window: a fresh user's first window on a 1280x720 and a 1920x1080 screen, and the Results page
with residuals beyond the strip's range (tools/screenshots_window.py).
--only hardware: the Hardware page's sound-card and serial-port lists at both sizes, this machine's and a
Windows PC's as an example (tools/screenshots_hardware.py).
qa-current-zeroed-1280x720.png and -1920x1080.png: the QA page judging a recording
whose current lead is broken against limits, results-current-zeroed-*.png: the Results page of it (what the
valid channels measured); help-guide.png and help-about.png:
Help's user guide and About (--only qa: just these).
Nothing of the user's settings or archive is touched: the window gets
a QSettings file and an archive in the temporary folder.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QItemSelection, QItemSelectionModel, QSettings  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from analysis.drivers import load_driver  # noqa: E402
from analysis.effects import get_effect  # noqa: E402
from analysis.multitone import design_multitone  # noqa: E402
from analysis.recording.format import write_recording  # noqa: E402
from analysis.synthesis import ChannelNoise, synthesize_recording  # noqa: E402
from tools.screenshot_kit import (ANALYSIS_TIMEOUT_S, SIZE, SMALL_AND_LARGE, grab_small_and_large,  # noqa: E402
                                  settle, synthetic_recording, wait_for, wait_for_click)

HIDDEN_DELAY_S = 100e-6     # the laser's latency the default model does not know about


def hidden_delay_recording(folder: Path) -> Path:
    """The paper's driver seen through a laser that lags by HIDDEN_DELAY_S: the default model misses it."""
    driver = load_driver("paper")
    model = driver.model()
    model = model.with_effects(model.effects + (get_effect("delay-x"),))
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    recording = synthesize_recording(model, {**driver.parameters, "tau_x": HIDDEN_DELAY_S}, mt.waveform,
                                     mt.excited_bins, mt.sample_rate, 8, 1, ChannelNoise(1e-4, 1e-4, 1e-8),
                                     seed=3, driver={"name": "paper (synthetic, laser 100 us late)",
                                                     "sd_m2": driver.sd_m2})
    wav, _ = write_recording(folder / "paper-laser-late", recording)
    return wav


def model_lab_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Model lab diagnosing a missing effect: before and after applying the top candidate."""
    if not open_in_lab(app, window, hidden_delay_recording(folder), "laser-late"):
        return []
    lab = window.model_lab
    lab.candidates.diagnose_button.click()
    if not wait_for(lab.diagnosis_shown, ANALYSIS_TIMEOUT_S):
        print("screenshots: the diagnosis did not finish in time", file=sys.stderr)
        return []
    settle(app)
    written = [out / "model-lab-before.png", out / "model-lab-after.png"]
    window.grab().save(str(written[0]))
    lab.candidates.select(0)
    lab.candidates.apply_button.click()
    settle(app)
    window.grab().save(str(written[1]))
    return written


def odd_mechanical_recording(folder: Path) -> Path:
    """The paper's driver with a hump of damping at 250 Hz that no catalogue holds (tests/odd_physics.py)."""
    from tests.odd_physics import odd_recording
    wav, _ = write_recording(folder / "paper-odd-damping", odd_recording("mechanical"))
    return wav


def model_lab_unexplained_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Model lab following the greedy path on physics the catalogue lacks: it ends "unexplained", pointing
    at the mechanical site, with that site's correction plotted; at 1280x720 and at 1920x1080."""
    if not open_in_lab(app, window, odd_mechanical_recording(folder), "odd-damping"):
        return []
    lab = window.model_lab
    lab.candidates.follow_button.click()
    if not wait_for(lab.diagnosis_shown, ANALYSIS_TIMEOUT_S):
        print("screenshots: the diagnosis of the odd-damping recording did not finish in time", file=sys.stderr)
        return []
    return grab_small_and_large(app, window, out, "model-lab-unexplained")


def measure_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """Every step of the measurement wizard on the in-process simulator, the live panels mid-measurement, QA."""
    wizard = window.wizard
    wizard.state.settings.setValue("measure/out_dir", str(folder / "measurements"))
    window.pages.setCurrentWidget(wizard)
    written = []

    def shot(name: str) -> None:
        settle(app)
        path = out / f"{name}.png"
        window.grab().save(str(path))
        written.append(path)

    def run(button, jobs, name: str) -> bool:
        with_result = wait_for_click(button, jobs.busy_changed)
        if not with_result:
            print(f"screenshots: {name} did not finish in time", file=sys.stderr)
        return with_result

    page = wizard.driver_page
    page.name_edit.setText("W18-PAPER")
    page.serial_edit.setText("0042")
    page.sd_value.setValue(133.0)
    page.impedance.setValue(4.0)
    page.operator_edit.setText("ana")
    page.station_edit.setText("QA1")
    shot("wizard-1-driver")
    wizard.next_button.click()
    hardware = wizard.hardware_page
    hardware.simulator_radio.setChecked(True)
    hardware.realtime_check.setChecked(False)
    run(hardware.test_audio_button, hardware.audio_jobs, "the sound-card test")
    shot("wizard-2-hardware")
    wizard.next_button.click()
    calibration = wizard.calibration_page
    run(calibration.measure_button, calibration.jobs, "the calibration")
    shot("wizard-3-calibration")
    wizard.next_button.click()
    level = wizard.level_page
    run(level.run_button, level.jobs, "the level check")
    shot("wizard-4-level")
    wizard.next_button.click()
    measure = wizard.measure_page
    run(measure.start_button, measure.jobs, "the measurement")
    shot("wizard-5-measure")
    wizard.next_button.click()
    shot("wizard-6-results")

    # The live panels in the middle of a measurement in real time.
    for _ in range(4):
        wizard.back_button.click()
    hardware.realtime_check.setChecked(True)
    for _ in range(3):
        wizard.next_button.click()
    measure.start_button.click()
    deadline = time.monotonic() + ANALYSIS_TIMEOUT_S
    halfway = max(2, measure.request().template.n_periods // 2)
    while (measure.panels.frame is None or measure.panels.frame.n_periods < halfway) and time.monotonic() < deadline:
        wait_for(measure.panels.repainted, 5)
    shot("live-panels")
    wait_for_click(measure.jobs.cancel_button, measure.jobs.busy_changed)

    window.pages.setCurrentWidget(window.qa)
    shot("qa-measured")
    limits = folder / "w18-limits.json"
    limits.write_text(json.dumps({"format": "linpar-limits/1", "name": "W18 production QA", "parameters": {
        "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
        "fs": {"nominal": 70, "tolerance": 7, "unit": "Hz"},
        "Qts": {"min": 0.3, "max": 0.5, "unit": "1"},
        "Mms": {"nominal": 12, "tolerance": "10%", "unit": "g"},
        "Bl": {"min": 5.5, "unit": "T*m"}}}, indent=1))
    if window.qa.load_button.isEnabled():
        window.qa.load_limits(limits)
        shot("qa-limits")
    from instruments.simulation import faults
    bad, _ = write_recording(folder / "current-disconnected", faults.current_disconnected())
    window.open_path(bad)
    if wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        window.pages.setCurrentWidget(window.qa)
        shot("qa-invalid")
    return written


def series_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Series page with a level series of the simulated nonlinear driver analysed."""
    from instruments.simulation.level_series import write_level_series

    paths = write_level_series(folder / "levels", levels_v=(0.3, 3.0, 6.0, 10.0, 14.0))
    window.pages.setCurrentWidget(window.series)
    window.series.setCurrentIndex(1)
    window.series.analyse("levels", paths)
    if not wait_for(window.series.worker.finished, 4 * ANALYSIS_TIMEOUT_S):
        print("screenshots: the level series did not finish", file=sys.stderr)
        return []
    settle(app)
    path = out / "series-levels.png"
    window.grab().save(str(path))
    return [path]


def large_signal_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Large-signal page: the issue's known-polynomial driver at three levels up to +-4 mm, identified;
    at 1280x720 and at 1920x1080."""
    from tests.large_signal_truth import clean_periods, known_driver, noisy_recording

    driver = known_driver(16384)
    paths = []
    for level in (3.0, 6.0, 10.5):
        block, mt = clean_periods(driver, level, 4)
        paths.append(write_recording(folder / f"large-signal-{level:g}V",
                                     noisy_recording(block, mt, driver_name="demo driver (known curves)"))[0])
    page = window.large_signal
    window.pages.setCurrentWidget(page)
    page.analyse(paths)
    if not wait_for(page.result_shown, 4 * ANALYSIS_TIMEOUT_S):
        print("screenshots: the large-signal identification did not finish", file=sys.stderr)
        return []
    return grab_small_and_large(app, window, out, "large-signal")


# A production batch of the paper's driver measured in the days before: (serial, operator, station, days and
# hours before now, relative change of Bl, Mms, Cms, RE). Electrical analogues: CMES = Mms/Bl^2, LCES = Cms*Bl^2,
# RES = Bl^2/Rms.
ARCHIVE_BATCH = (
    ("0031", "ana", "QA1", 3, 6.0, 0.00, 0.00, 0.00, 0.000),
    ("0032", "ana", "QA1", 3, 5.9, 0.02, -0.03, 0.06, 0.010),
    ("0033", "ana", "QA1", 3, 5.8, -0.03, 0.04, -0.08, -0.012),
    ("0034", "ben", "QA2", 2, 2.0, 0.05, 0.01, 0.12, 0.020),
    ("0035", "ben", "QA2", 2, 1.9, -0.01, -0.02, 0.03, 0.004),
)


def archive_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Archive page: a batch of one driver stored over a few days (one measured with the laser unplugged),
    the list, then four of them compared."""
    from analysis.archive import Archive
    from analysis.pipeline import analyze_recording
    from analysis.recording.format import read_recording
    from instruments.simulation import faults

    from datetime import datetime, timedelta, timezone

    def before(days: float, hours: float) -> str:
        return (datetime.now(timezone.utc) - timedelta(days=days, hours=hours)).isoformat(timespec="seconds")

    driver = load_driver("paper")
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    archive = Archive(Path(window.archive.source))
    for number, (serial, operator, station, days, hours, bl, mms, cms, re) in enumerate(ARCHIVE_BATCH):
        p = dict(driver.parameters)
        b, m, c = p["Bl"] * (1 + bl), p["CMES"] * p["Bl"] ** 2 * (1 + mms), p["LCES"] / p["Bl"] ** 2 * (1 + cms)
        p.update(Bl=b, CMES=m / b**2, LCES=c * b**2, RES=p["RES"] / p["Bl"] ** 2 * b**2, RE=p["RE"] * (1 + re))
        recording = synthesize_recording(driver.model(), p, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1,
                                         ChannelNoise(1e-4, 1e-4, 1e-8), seed=10 + number,
                                         driver={"name": "W18-PAPER", "sd_m2": driver.sd_m2})
        wav, _ = write_recording(folder / f"batch-{serial}", recording)
        archive.store(wav, analyze_recording(read_recording(wav)),
                      {"driver": "W18-PAPER", "serial": serial, "operator": operator, "station": station,
                       "measured_at": before(days, hours)})
    wav, _ = write_recording(folder / "batch-0036", faults.laser_disconnected())
    archive.store(wav, analyze_recording(read_recording(wav)),
                  {"driver": "W18-PAPER", "serial": "0036", "operator": "ben", "station": "QA2",
                   "measured_at": before(2, 1.8)})
    page = window.archive
    window.pages.setCurrentWidget(page)
    page.tabs.setCurrentWidget(page.list_tab)
    page.refresh_now()
    selection = QItemSelection()
    for row in range(page.table.proxy.rowCount()):
        if page.table.entry_at(row).serial in ("0031", "0032", "0033", "0034"):
            selection.select(page.table.proxy.index(row, 0), page.table.proxy.index(row, 0))
    page.table.selectionModel().select(selection, QItemSelectionModel.ClearAndSelect | QItemSelectionModel.Rows)
    settle(app)
    written = [out / "archive-list.png", out / "archive-compare.png"]
    window.grab().save(str(written[0]))
    page.compare_button.click()
    if not wait_for(page.comparison_shown, ANALYSIS_TIMEOUT_S):
        print("screenshots: the comparison of the stored measurements did not come", file=sys.stderr)
        return written[:1]
    settle(app)
    window.grab().save(str(written[1]))
    return written


def rms_sqrt_f_recording(folder: Path) -> Path:
    """The paper's driver whose damping rises as sqrt(f) (resources/effects/rms-sqrt-f.toml with r = Rms)."""
    from analysis.effects.user import load_effect_file
    driver = load_driver("paper")
    model = driver.model()
    model = model.with_effects(model.effects + (load_effect_file(ROOT / "resources" / "effects" / "rms-sqrt-f.toml"),))
    values = {**driver.parameters, "r": driver.parameters["Bl"] ** 2 / driver.parameters["RES"]}
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    recording = synthesize_recording(model, values, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1,
                                     ChannelNoise(1e-4, 1e-4, 1e-8), seed=3,
                                     driver={"name": "paper (synthetic, damping rising as sqrt(f))",
                                             "sd_m2": driver.sd_m2})
    wav, _ = write_recording(folder / "paper-rms-sqrt-f", recording)
    return wav


def new_effect_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The user writes the missing effect in the "New effect…" dialog (its signature drawn over the misfit), saves
    it, checks it: reduced chi^2 falls to 1. At 1280x720 and 1920x1080 each."""
    from PySide6.QtCore import Qt
    os.environ["LINPAR_EFFECTS"] = str(folder / "effects")      # the dialog saves there, not in the user's folder
    if not open_in_lab(app, window, rms_sqrt_f_recording(folder), "sqrt(f) damping"):
        return []
    lab = window.model_lab
    lab.catalogue.new_effect_button.click()
    dialog = lab.new_effect_dialog
    dialog.id_edit.setText("rms-sqrt-f")
    dialog.title_edit.setText("Viscous damping rising with the square root of frequency")
    dialog.site_combo.setCurrentIndex(dialog.site_combo.findData("mechanical"))
    dialog.physics_edit.setPlainText("Air pumped through the spider and the surround adds damping that grows "
                                     "with frequency.")
    dialog.set_parameter(0, "r", "kg/s", "0.5", "-10", "10")
    dialog.formula_edit.setText("r * (sqrt(w / ws) - 1)")
    dialog.formula_edit.setFocus()
    dialog.formula_edit.setCursorPosition(len(dialog.formula_edit.text()))
    written = grab_small_and_large(app, dialog, out, "model-lab-new-effect")
    dialog.save_button.click()
    settle(app)
    item = lab.catalogue.item("rms-sqrt-f")
    lab.catalogue.tree.setCurrentItem(item)
    lab.catalogue.tree.scrollToItem(item)
    item.setCheckState(0, Qt.Checked)
    if not wait_for(lab.version_added, ANALYSIS_TIMEOUT_S):
        print("screenshots: the refit with the new effect did not finish in time", file=sys.stderr)
        return written
    # the User effects branch in view, with the effect checked
    return written + grab_small_and_large(app, window, out, "model-lab-own-effect",
                                          prepare=lambda: lab.catalogue.tree.scrollToItem(item))


def _store_units(window, folder: Path, counts: tuple[int, ...]):
    """Yield after storing each count of units (cumulative) of one driver from three stations, fs 2 sigma up
    from unit 150, QA3 reading 0.6 Hz high; limits version 1 stored first."""
    import copy

    import numpy as np

    from analysis.archive import open_archive
    from analysis.archive.results import results_document
    from analysis.pipeline import analyze_recording

    driver = load_driver("paper")
    mt = design_multitone(8000, 1024, 8.0, 3000.0, rms=1.0)      # a small recording: the units differ below
    recording = synthesize_recording(driver.model(), driver.parameters, mt.waveform, mt.excited_bins, 8000, 3, 0,
                                     ChannelNoise(1e-4, 1e-4, 1e-8), seed=1,
                                     driver={"name": "W18-PAPER", "sd_m2": driver.sd_m2})
    wav, _ = write_recording(folder / "unit", recording)
    doc = results_document(analyze_recording(recording), recording)
    archive = open_archive(window.production.request().source)
    archive.store_limits({"format": "linpar-limits/1", "name": "W18-PAPER production",
                          "parameters": {"fs": {"nominal": 70.5, "tolerance": 5.0, "unit": "Hz"},
                                         "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
                                         "Qts": {"min": 0.40, "max": 0.52, "unit": "-"}}}, note="first article")
    rng = np.random.default_rng(4)
    i = 0
    for count in counts:
        while i < count:
            station = ("QA1", "QA2", "QA3")[i % 3]
            unit_doc = copy.deepcopy(doc)
            params = unit_doc["parameters"]
            fs = 70.5 + 0.8 * rng.standard_normal() + (1.6 if i >= 150 else 0.0) + (0.6 if station == "QA3" else 0.0)
            for name, p in params.items():          # unit-to-unit spread of a few percent, as a batch has
                if p.get("value") is not None:
                    p["value"] = p["value"] * (1 + 0.015 * rng.standard_normal())
            params["fs"]["value"] = fs
            archive.store(wav, unit_doc, {"driver": "W18-PAPER", "serial": f"{7000 + i}", "station": station,
                                          "operator": ("ana", "ben")[i % 2],
                                          "measured_at": f"2024-05-{1 + i // 80:02d}T{6 + i % 80 // 8:02d}:"
                                                         f"{i % 8 * 7:02d}:00Z"})
            i += 1
        yield count


def _grab_production(app: QApplication, window, out: Path, stem: str) -> list[Path]:
    page = window.production
    window.pages.setCurrentWidget(page)
    written = []
    for width, height in SMALL_AND_LARGE:
        window.resize(width, height)
        page.parameter = "fs"
        page.refresh()
        if not wait_for(page.computed, ANALYSIS_TIMEOUT_S) and page.data is None:
            print("screenshots: the production statistics did not come", file=sys.stderr)
            return written
        page.details.setCurrentIndex(0)
        settle(app)
        path = out / f"{stem}-{width}x{height}.png"
        window.grab().save(str(path))
        written.append(path)
    window.resize(*SIZE)
    return written


def production_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Production page over 240 units (see _store_units), at 1280x720 and 1920x1080."""
    written = []
    for _ in _store_units(window, folder, (240,)):
        written += _grab_production(app, window, out, "production")
    return written


def production_counts_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """The Production page with 4 units (capability greyed, its intervals wide) and with 40."""
    written = []
    for count in _store_units(window, folder, (4, 40)):
        written += _grab_production(app, window, out, f"production-{count}-units")
    return written


def model_lab_only(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """--only model-lab: the lab's page as the Results page hands it over, then its two diagnosis sessions."""
    if not open_in_lab(app, window, synthetic_recording(folder), "synthetic"):
        return []
    written = [out / "model-lab.png"]
    window.grab().save(str(written[0]))
    written += model_lab_screenshots(app, window, folder, out)
    written += model_lab_unexplained_screenshots(app, window, folder, out)
    return written


def open_in_lab(app: QApplication, window, wav: Path, what: str) -> bool:
    """Open a recording and show the Model lab once it is analysed; False (said on stderr) if it was not in time."""
    window.open_path(wav)
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        print(f"screenshots: the {what} recording was not analysed in time", file=sys.stderr)
        return False
    window.pages.setCurrentWidget(window.model_lab)
    settle(app)
    return True


def hardware_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_hardware import hardware_screenshots as shots
    return shots(app, window, folder, out)


def real_like_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_real_like import real_like_screenshots as shots
    return shots(app, window, folder, out, open_in_lab)


def first_window_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_window import first_window_screenshots as shots
    return shots(app, window, folder, out, hidden_delay_recording(folder))


def pages_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_pages import every_page_screenshots
    return every_page_screenshots(app, window, folder, out)


def qa_broken_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    """--only qa: the QA page judging a recording whose current lead is broken (zeroed) against limits, at
    both screen sizes; then Help's guide and About."""
    import numpy as np

    from analysis.recording.format import make_recording, read_recording
    good = read_recording(synthetic_recording(folder))
    signals = {c.signal: good.signal(c.signal) for c in good.channels}
    signals["current"] = np.zeros_like(signals["current"])
    broken, _ = write_recording(folder / "current-zeroed", make_recording(
        good.sample_rate, signals, good.period_samples, good.settle_periods, good.excited_bins, dict(good.driver)))
    limits = folder / "w18-limits.json"
    limits.write_text(json.dumps({"format": "linpar-limits/1", "name": "W18 production QA", "parameters": {
        "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"}, "fs": {"nominal": 70, "tolerance": 7, "unit": "Hz"},
        "Bl": {"min": 5.0, "unit": "T*m"}}}, indent=1))
    window.qa.load_limits(limits)
    window.open_path(broken)
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        return []
    written = []
    for page, stem in ((window.qa, "qa-current-zeroed"), (window.results, "results-current-zeroed")):
        window.pages.setCurrentWidget(page)
        for size in SMALL_AND_LARGE:
            window.resize(*size)
            settle(app)
            path = out / f"{stem}-{size[0]}x{size[1]}.png"
            window.grab().save(str(path))
            written.append(path)
    for name, show in (("help-guide", window.menus.show_guide), ("help-about", window.menus.show_about)):
        dialog = show()
        settle(app)
        path = out / f"{name}.png"
        dialog.grab().save(str(path))
        dialog.close()
        written.append(path)
    window.resize(*SIZE)
    return written


def model_part_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_model_part import model_part_screenshots as shots
    return shots(app, window, folder, out)


def curves_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_curves import curves_screenshots as shots
    return shots(app, window, folder, out)


def verdicts_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshots_verdicts import verdict_screenshots
    return verdict_screenshots(app, window, folder, out)


ONLY = {"archive": archive_screenshots, "model-lab": model_lab_only, "new-effect": new_effect_screenshots,
        "large-signal": large_signal_screenshots, "production": production_screenshots,
        "pages": pages_screenshots, "qa": qa_broken_screenshots, "hardware": hardware_screenshots,
        "verdicts": verdicts_screenshots, "real-like": real_like_screenshots,
        "first-window": first_window_screenshots, "production-counts": production_counts_screenshots,
        "model-part": model_part_screenshots, "curves": curves_screenshots}


def main(argv: list[str]) -> int:
    if any(a in ("-h", "--help") for a in argv[1:]):      # not an output folder named "--help"
        print(__doc__)
        return 0
    only = None
    if "--only" in argv:
        at = argv.index("--only")
        only = argv[at + 1] if at + 1 < len(argv) else ""
        argv = argv[:at] + argv[at + 2:]
        if only not in ONLY:
            print(f"screenshots: --only takes {', '.join(repr(k) for k in ONLY)}", file=sys.stderr)
            return 2
    out = Path(argv[1]) if len(argv) > 1 else ROOT / "docs" / "screenshots"
    out.mkdir(parents=True, exist_ok=True)
    app = QApplication.instance() or QApplication(argv[:1])
    from app.jobs.gui_gc import collect_in_gui_thread
    collect_in_gui_thread()               # a worker thread must never free a Qt object (app/jobs/gui_gc.py)
    from app.window.main_window import MainWindow
    from app.window.settings import Settings

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        wav = synthetic_recording(folder)
        window = MainWindow(Settings(QSettings(str(folder / "settings.ini"), QSettings.IniFormat)))
        window.archive.set_root(folder / "archive")      # the wizard's measurement is stored there too
        window.resize(*SIZE)
        window.show()
        if only is not None:
            written = ONLY[only](app, window, folder, out)
            window.close()
            for path in written:
                print(path)
            return 0
        window.open_path(wav)
        if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
            print(f"screenshots: the analysis did not finish in {ANALYSIS_TIMEOUT_S} s", file=sys.stderr)
            return 1
        settle(app)
        written = []
        tabs = window.results.plot_tabs
        for index, name in enumerate(("results", "results-displacement", "results-spl")):
            tabs.setCurrentIndex(index)
            settle(app)
            path = out / f"{name}.png"
            window.grab().save(str(path))
            written.append(path)
        tabs.setCurrentIndex(0)
        for index in range(window.pages.count()):
            page = window.pages.tabText(index)
            if page in ("Results", "Archive", "Production"):    # these once they have measurements, below
                continue
            window.pages.setCurrentIndex(index)
            settle(app)
            path = out / f"{page.lower().replace(' ', '-')}.png"
            window.grab().save(str(path))
            written.append(path)
        # The same driver measured without the laser: greyed parameters, no Hx, "enter Sd".
        window.open_path(synthetic_recording(folder, "paper-no-laser", laser=False))
        if wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
            window.pages.setCurrentWidget(window.results)
            tabs.setCurrentIndex(2)
            settle(app)
            path = out / "results-no-laser.png"
            window.grab().save(str(path))
            written.append(path)
        written += model_lab_screenshots(app, window, folder, out)
        written += model_lab_unexplained_screenshots(app, window, folder, out)
        written += new_effect_screenshots(app, window, folder, out)
        written += measure_screenshots(app, window, folder, out)
        written += series_screenshots(app, window, folder, out)
        written += large_signal_screenshots(app, window, folder, out)
        written += archive_screenshots(app, window, folder, out)
        written += qa_broken_screenshots(app, window, folder, out)
        window.archive.set_root(folder / "production-archive")      # a line's worth of units of its own
        written += production_screenshots(app, window, folder, out)
        window.close()
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
