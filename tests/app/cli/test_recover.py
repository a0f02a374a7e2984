"""`linpar recover` and Ctrl-C during `linpar measure` (the issue's finding 12).

Ctrl-C used to leave the captured periods only as NAME.unfinished/, which only the GUI could recover. Now
the first Ctrl-C ends the measurement as a failing device does (the whole periods so far are written,
marked partial); and `linpar recover DIR` lists, keeps, analyses or discards what a crash left.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import pytest

import app.cli.devices as cli_devices

from analysis.recording.format import read_recording
from app.cli import main
from instruments.audio.simulated import SimulatedAudio
from tests.pace import paced

SHORT = ["--period", "16384", "--periods", "6", "--no-archive"]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


@pytest.fixture
def simulated_card(monkeypatch):
    monkeypatch.setattr(cli_devices, "open_devices", lambda args, stack: (
        SimulatedAudio(realtime=False, seed=1), None, {"name": "paper (simulated)", "sd_m2": 0.0133}))


def test_ctrl_c_during_measure_writes_the_periods_so_far(simulated_card, monkeypatch, tmp_path, capsys):
    class CtrlCAfterThreePeriods(cli_devices.Progress):
        pressed = False

        def __call__(self, p):
            super().__call__(p)
            if p.stage == "averaging" and p.periods_kept == 3 and not self.pressed:
                self.pressed = True
                os.kill(os.getpid(), signal.SIGINT)       # as the terminal does
    monkeypatch.setattr(cli_devices, "Progress", CtrlCAfterThreePeriods)
    before = signal.getsignal(signal.SIGINT)      # SIG_IGN, not Python's handler, under a shell's `cmd &`
    code, out, err = run(capsys, "measure", "--out", tmp_path, "--name", "m", *SHORT)
    assert code == 130 and out == ""
    assert "Ctrl-C: stopping" in err and "linpar: interrupted: the measurement was cancelled" in err
    assert "marked partial" in err and str(tmp_path / "m.wav") in err
    rec = read_recording(tmp_path / "m")
    assert rec.extra["measurement"]["partial"] and 3 <= rec.n_periods < 6
    assert not list(tmp_path.glob("*.unfinished"))           # nothing left for `recover`
    assert signal.getsignal(signal.SIGINT) is before          # the handler it found is back


def test_a_second_ctrl_c_stops_at_once_and_recover_makes_the_journal_a_recording(simulated_card, monkeypatch,
                                                                                 tmp_path, capsys):
    class CtrlCTwice(cli_devices.Progress):
        presses = 0

        def __call__(self, p):
            super().__call__(p)
            if p.stage == "averaging" and p.periods_kept >= 3 and self.presses < 2:
                self.presses += 1
                os.kill(os.getpid(), signal.SIGINT)
    monkeypatch.setattr(cli_devices, "Progress", CtrlCTwice)
    code, _, err = run(capsys, "measure", "--out", tmp_path, "--name", "m", *SHORT)
    assert code == 130 and f"'linpar recover {tmp_path}' makes it a recording" in err
    assert not (tmp_path / "m.wav").exists() and (tmp_path / "m.unfinished").is_dir()
    code, out, err = run(capsys, "recover", tmp_path, "--keep", "m")
    assert code == 0 and read_recording(tmp_path / "m").n_periods >= 2


@pytest.fixture(scope="module")
def crashed(tmp_path_factory):
    """A folder with a journal whose measuring process was killed (tests/reliability/children.py)."""
    from tests.reliability.test_crash_safety import kill_when_periods_on_disk
    folder = tmp_path_factory.mktemp("crashed")
    kill_when_periods_on_disk(folder, "cut", "analog", 3)
    return folder


def copy_of(folder, tmp_path):
    import shutil
    target = tmp_path / "out"
    shutil.copytree(folder, target)
    return target


def test_recover_lists_keeps_and_analyses(crashed, tmp_path, capsys):
    folder = copy_of(crashed, tmp_path)
    code, out, _ = run(capsys, "recover", folder, "--json")
    (found,) = json.loads(out)["unfinished"]
    assert code == 0 and found["name"] == "cut" and found["recoverable"] and found["periods"] >= 2
    code, out, _ = run(capsys, "recover", folder)
    assert code == 0 and "cut (" in out and "--keep" in out
    code, out, err = run(capsys, "recover", folder, "--analyse", "--json")
    doc = json.loads(out)
    assert code == 0 and doc["failed"] == [] and doc["done"][0]["analysis"]["validity"]["overall"]
    wav = doc["done"][0]["recording"]
    assert read_recording(wav).extra["measurement"]["ended_by"] == "crash"
    assert not list(folder.glob("*.unfinished")) and "kept cut as" in err
    code, out, _ = run(capsys, "recover", folder)
    assert code == 0 and "no unfinished measurement" in out


def test_recover_discards_only_what_is_named(crashed, tmp_path, capsys):
    folder = copy_of(crashed, tmp_path)
    code, _, err = run(capsys, "recover", folder, "--discard", "other")
    assert code == 2 and "other: no unfinished measurement of that name" in err and len(err.splitlines()) == 1
    assert list(folder.glob("*.unfinished"))
    code, _, err = run(capsys, "recover", folder, "--discard", "cut")
    assert code == 0 and not list(folder.glob("*.unfinished")) and not list(folder.glob("*.wav"))


def test_recover_of_a_folder_that_is_not_one(capsys, tmp_path):
    code, _, err = run(capsys, "recover", tmp_path / "nowhere")
    assert code == 2 and "not a folder" in err


def test_recover_is_a_command_of_the_installed_program(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "app.cli", "recover", str(tmp_path)], capture_output=True,
                          text=True, timeout=paced(120))
    assert proc.returncode == 0 and "no unfinished measurement" in proc.stdout
