"""`linpar gui` end to end, in a fresh interpreter: start, open, quit, exit code."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from PySide6.QtCore import QObject, Signal

from tests.pace import paced


ROOT = Path(__file__).resolve().parents[2]
RUN = "import sys; from app.main import run_gui; sys.exit(run_gui(sys.argv[1] if len(sys.argv) > 1 else None))"


def _env(tmp_path, **extra) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM",
                                                            "LINPAR_EXIT_AFTER_S")}
    # QSettings on Linux writes under XDG_CONFIG_HOME: keep the user's settings out of it.
    env.update(HOME=str(tmp_path), XDG_CONFIG_HOME=str(tmp_path / "config"), PYTHONPATH=str(ROOT), **extra)
    return env


def _run(tmp_path, *args, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", RUN, *map(str, args)], cwd=ROOT, env=_env(tmp_path, **env),
                          capture_output=True, text=True, timeout=paced(120))


def test_offscreen_run_opens_a_recording_and_exits_cleanly(tmp_path, recordings):
    done = _run(tmp_path, recordings["paper"], QT_QPA_PLATFORM="offscreen", LINPAR_EXIT_AFTER_S="2")
    assert done.returncode == 0, done.stderr
    assert "Fatal Python error" not in done.stderr and "Traceback" not in done.stderr
    assert (tmp_path / "config" / "linpar" / "linpar.conf").is_file()     # geometry saved on the way out


def test_without_a_display_it_says_so_instead_of_aborting(tmp_path):
    done = _run(tmp_path)
    assert done.returncode == 2
    assert "no display" in done.stderr and "QT_QPA_PLATFORM=offscreen" in done.stderr


class _Emitter(QObject):
    pinged = Signal(int)


def test_many_signals_and_calls_do_not_exhaust_none_or_true(qapp):
    """PySide6 6.12.0 on Python 3.11 lost a reference to None on every void call and to True on every
    emit, until Python aborted (none_dealloc): the pinned version must not."""
    emitter = _Emitter()
    before = sys.getrefcount(None), sys.getrefcount(True)
    for i in range(20_000):
        emitter.pinged.emit(i)
        emitter.setObjectName("x")
    after = sys.getrefcount(None), sys.getrefcount(True)
    assert after[0] >= before[0] - 10 and after[1] >= before[1] - 10
