"""Screenshots of the main window on a synthetic recording, for docs and for looking at.

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR]

Writes results.png (and one PNG per Results plot tab and per other page) to
docs/screenshots/ unless OUTDIR is given, then model-lab-before.png and
model-lab-after.png: a recording whose laser lags by 100 us, diagnosed in the
Model lab, before and after applying the top candidate. Nothing of the user's
settings is touched: the window gets a QSettings file in the temporary folder.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEventLoop, QSettings, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from analysis.drivers import load_driver  # noqa: E402
from analysis.effects import get_effect  # noqa: E402
from analysis.multitone import design_multitone  # noqa: E402
from analysis.recording import write_recording  # noqa: E402
from analysis.synthesis import ChannelNoise, synthesize_recording  # noqa: E402

SIZE = (1400, 900)
ANALYSIS_TIMEOUT_S = 120
HIDDEN_DELAY_S = 100e-6     # the laser's latency the default model does not know about


def synthetic_recording(folder: Path, name: str = "paper-synthetic", laser: bool = True) -> Path:
    """The paper's driver, 48 kHz, the project multitone 5 Hz..10 kHz, realistic noise.

    Without the laser the recording has no displacement channel and no Sd.
    """
    driver = load_driver("paper")
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    info = {"name": "paper (synthetic)", "sd_m2": driver.sd_m2} if laser else {"name": "paper (synthetic)"}
    recording = synthesize_recording(driver.model(with_displacement=laser), driver.parameters, mt.waveform,
                                     mt.excited_bins, mt.sample_rate, 8, 1, ChannelNoise(1e-4, 1e-4, 1e-8),
                                     seed=3, driver=info)
    wav, _ = write_recording(folder / name, recording)
    return wav


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
    window.open_path(hidden_delay_recording(folder))
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        print("screenshots: the laser-late recording was not analysed in time", file=sys.stderr)
        return []
    lab = window.model_lab
    window.pages.setCurrentWidget(lab)
    settle(app)
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


def wait_for(signal, timeout_s: float) -> bool:
    loop = QEventLoop()
    fired = []
    signal.connect(lambda *a: (fired.append(a), loop.quit()))
    QTimer.singleShot(int(timeout_s * 1000), loop.quit)
    loop.exec()
    return bool(fired)


def settle(app: QApplication, ms: int = 300) -> None:
    loop = QEventLoop()
    QTimer.singleShot(ms, loop.quit)
    loop.exec()
    app.processEvents()


def main(argv: list[str]) -> int:
    out = Path(argv[1]) if len(argv) > 1 else ROOT / "docs" / "screenshots"
    out.mkdir(parents=True, exist_ok=True)
    app = QApplication.instance() or QApplication(argv[:1])
    from app.main_window import MainWindow
    from app.settings import Settings

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        wav = synthetic_recording(folder)
        window = MainWindow(Settings(QSettings(str(folder / "settings.ini"), QSettings.IniFormat)))
        window.resize(*SIZE)
        window.show()
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
            if page == "Results":
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
        window.close()
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
