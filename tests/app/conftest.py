"""Fixtures for the GUI tests: synthetic recordings, private settings, a main window.

Dialogs are replaced by recorders for every test: a modal box would block an
offscreen test run forever, and the tests want to read what it would say.
"""
from __future__ import annotations

import os
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QMessageBox

from analysis.drivers import load_driver
from analysis.multitone import design_multitone
from analysis.recording.format import write_recording
from analysis.synthesis import ChannelNoise, synthesize_recording
from tests.pace import wait_ms

PAPER = load_driver("paper")
ANALYSIS_WAIT_S = 60           # an analysis takes a few seconds on an idle machine


def analysis_wait_ms(times: float = 1) -> int:
    """The timeout of a wait for `times` analyses, at the machine's pace when the wait begins (tests/pace.py)."""
    return wait_ms(times * ANALYSIS_WAIT_S)


def make_recording(folder: Path, name: str = "paper", *, laser: bool = True, sd_m2: float | None = 0.0133,
                   n_periods: int = 8) -> Path:
    """The paper's driver (lr2, creep-log) on the project multitone 5 Hz..10 kHz, realistic noise; the .wav path."""
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    driver = {"name": "paper (synthetic)"}
    if sd_m2:
        driver["sd_m2"] = sd_m2
    recording = synthesize_recording(PAPER.model(with_displacement=laser), PAPER.parameters, mt.waveform,
                                     mt.excited_bins, mt.sample_rate, n_periods, 1,
                                     ChannelNoise(1e-4, 1e-4, 1e-8), seed=3, driver=driver)
    wav, _ = write_recording(folder / name, recording)
    return wav


@pytest.fixture(scope="session")
def recordings(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("recordings")
    bad_wav = folder / "broken.wav"
    bad_wav.write_bytes(b"RIFF this is not a wave file")
    (folder / "broken.json").write_text('{"format": "linpar-recording/1"}', encoding="utf-8")
    return {
        "paper": make_recording(folder, "paper"),
        "no_sd": make_recording(folder, "no-sd", sd_m2=None),
        "no_laser": make_recording(folder, "no-laser", laser=False, sd_m2=None),
        "broken": bad_wav,
    }


@pytest.fixture
def settings(tmp_path):
    from app.window.settings import Settings
    return Settings(QSettings(str(tmp_path / "linpar.ini"), QSettings.IniFormat))


@pytest.fixture(autouse=True)
def archive_root(monkeypatch, tmp_path) -> Path:
    """The measurement archive of a test: never the user's. A window whose settings name no archive folder
    uses analysis.archive.default_root(), which $LINPAR_ARCHIVE points here."""
    root = tmp_path / "archive"
    monkeypatch.setenv("LINPAR_ARCHIVE", str(root))
    return root


@pytest.fixture(autouse=True)
def dialogs(monkeypatch) -> list[tuple[str, str, str]]:
    """(kind, title, text) of every message box the code under test opens."""
    shown: list[tuple[str, str, str]] = []

    def recorder(kind):
        def show(parent, title, text, *args, **kwargs):
            shown.append((kind, title, text))
            return QMessageBox.Ok
        return show
    for kind in ("warning", "critical", "information", "question"):
        monkeypatch.setattr(QMessageBox, kind, staticmethod(recorder(kind)))
    return shown


@pytest.fixture
def window(qtbot, settings):
    from app.window.main_window import MainWindow
    w = MainWindow(settings)
    qtbot.addWidget(w)
    w.resize(1400, 900)
    w.show()
    return w


def open_and_wait(qtbot, window, path, signal: str = "analysis_shown"):
    """Open `path` and wait for `signal`; the signal's arguments."""
    with qtbot.waitSignal(getattr(window, signal), timeout=analysis_wait_ms()) as blocker:
        window.open_path(path)
    return blocker.args
