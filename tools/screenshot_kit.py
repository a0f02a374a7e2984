"""What tools/screenshots.py and tools/screenshots_pages.py share: the synthetic recording, grabbing the
window at both screen sizes, waiting for a job or a signal without blocking Qt's event loop."""
from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QEventLoop, QTimer
from PySide6.QtWidgets import QApplication

from analysis.drivers import load_driver
from analysis.multitone import design_multitone
from analysis.recording.format import write_recording
from analysis.synthesis import ChannelNoise, synthesize_recording

SIZE = (1400, 900)
SMALL_AND_LARGE = ((1280, 720), (1920, 1080))     # a laptop and a desktop screen
ANALYSIS_TIMEOUT_S = 120


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


def grab_small_and_large(app: QApplication, window, out: Path, stem: str, prepare=None) -> list[Path]:
    """The window (or a dialog) as it is, at 1280x720 and at 1920x1080 (OUT/STEM-WxH.png); then back to its
    usual size. `prepare()`, if given, runs after each resize, before the grab (to scroll something into view)."""
    written = []
    for width, height in SMALL_AND_LARGE:
        window.resize(width, height)
        settle(app, 600)
        if prepare is not None:
            prepare()
            settle(app)
        path = out / f"{stem}-{width}x{height}.png"
        window.grab().save(str(path))
        written.append(path)
    window.resize(*SIZE)
    settle(app)
    return written


def wait_for_click(button, busy_changed, timeout_s: float = ANALYSIS_TIMEOUT_S) -> bool:
    """Click `button` and wait until the job it starts is over (busy_changed(False))."""
    loop = QEventLoop()
    ended = []

    def on_busy(busy: bool) -> None:
        if not busy:
            ended.append(True)
            loop.quit()
    busy_changed.connect(on_busy)
    button.click()
    if not ended:
        QTimer.singleShot(int(timeout_s * 1000), loop.quit)
        loop.exec()
    busy_changed.disconnect(on_busy)
    return bool(ended)


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
