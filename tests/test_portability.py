"""Issue 22: linpar without the modules only Linux and macOS have (fcntl, termios, pty, resource).

tests/portability_probe.py runs in a process of its own with them blocked (the
module doc says what else it must do to look like Windows); these tests read
its report. What this cannot show: PortAudio's Windows and macOS host APIs,
COM ports, and filelock's Win32 lock (the probe gets filelock's lock-file
fallback); the README's "Windows and macOS" section says what a first user
there should check.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> dict:
    work = tmp_path_factory.mktemp("portability")
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    done = subprocess.run([sys.executable, str(ROOT / "tests" / "portability_probe.py"), str(work)],
                          capture_output=True, text=True, cwd=work, env=env, timeout=240)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def _step(report: dict, name: str) -> dict:
    found = report[name]
    assert "error" not in found, found.get("error")
    return found


def test_every_module_outside_the_rig_and_the_pty_emulator_imports(report):
    found = _step(report, "import_everything")
    assert found["failed"] == {}
    assert found["imported"] > 200          # the walk found the packages (249 modules on 2026-11-25)
    assert report["blocked_still_blocked"]


def test_the_main_window_opens(report):
    found = _step(report, "open_main_window")
    assert found["visible"] and found["title"] == "linpar" and found["has_icon"]


def test_a_measurement_on_the_in_process_simulator_is_analysed_and_stored(report):
    found = _step(report, "measure_and_store")
    assert found["recording"]
    assert found["archive_ids"] == [found["stored_id"]]
    assert found["journal_checks"] > 0 and found["journal_held_at_each"]     # locked while it measured
    assert not found["journal_left"]                                          # and gone once written
    errors = found["relative_errors"]
    assert set(errors) == {"RE", "Bl", "CMES"} and all(abs(e) < 0.01 for e in errors.values()), errors


def test_the_journal_lock_excludes_others_and_dies_with_its_holder_on_the_fallback(report):
    found = _step(report, "journal_lock")
    assert found["held_by_me"] and found["second_refused"] and found["free_after_release"]
    assert found["other_said"] == "held" and found["held_by_other"]
    assert found["free_after_kill"]         # a crashed measurement's journal is offered for recovery


def test_the_native_lock_is_freed_when_its_holder_is_killed(tmp_path):
    """The probe above gets filelock's lock-file fallback (fcntl blocked); here the system's own lock (flock)."""
    import signal
    import time
    from analysis import file_lock
    path = tmp_path / "journal.lock"
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time; from analysis import file_lock; "
                               f"lock = file_lock.take({str(path)!r}); print('held', flush=True); time.sleep(60)"],
                              cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        assert file_lock.held(path)
        holder.send_signal(signal.SIGKILL)
        holder.wait(10)
        deadline = time.monotonic() + 5
        while file_lock.held(path) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not file_lock.held(path)
    finally:
        holder.kill()
        holder.wait()


def test_off_linux_the_rig_commands_say_so_in_one_line(capsys, monkeypatch):
    from app.cli import main
    from instruments.rig import manager
    with pytest.raises(manager.RigError, match="Linux only"):
        manager.require_linux("win32")
    manager.require_linux("linux")
    real = manager.require_linux
    monkeypatch.setattr(manager, "require_linux", lambda platform=None: real("darwin"))
    for argv in (["rig", "status"], ["rig", "start"], ["rig", "stop"]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Linux only" in err and "sound card" in err, err
