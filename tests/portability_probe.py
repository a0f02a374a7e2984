"""What a Windows PC would meet, tried on Linux: run by tests/test_portability.py in a process of its own.

    python tests/portability_probe.py WORK_DIR     (from the checkout; prints one JSON object)

The modules Windows lacks (fcntl, termios, pty, resource) are blocked in
sys.modules before anything of linpar is imported. pyserial is imported
first, because it picks its back end by the system (serialposix, which
needs fcntl, here; serialwin32, which needs the Win32 API, on Windows):
neither can be loaded on the other's system, and which one is used is
pyserial's business, not linpar's. filelock is not: it is loaded blocked,
and takes its lock-file fallback (on Windows it takes the Win32 lock).
"""
from __future__ import annotations

import importlib
import json
import os
import pkgutil
import subprocess
import sys
import time
import traceback
from pathlib import Path

import serial                    # noqa: F401 - see the module doc
import serial.tools.list_ports   # noqa: F401

BLOCKED = ("fcntl", "termios", "pty", "resource")
for _name in BLOCKED:
    sys.modules[_name] = None    # type: ignore[assignment]   # "import fcntl" now raises ImportError

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
# Linux-only by design: the virtual rig (JACK, pseudo-terminals) and the laser's pty emulator.
LINUX_ONLY = ("instruments.rig", "instruments.laser.emulator", "instruments.laser.ild1420.emulator")


def linux_only(name: str) -> bool:
    return any(name == prefix or name.startswith(prefix + ".") for prefix in LINUX_ONLY)


def import_everything() -> dict:
    failed, imported = {}, 0
    for package in ("analysis", "instruments", "app"):
        for info in pkgutil.walk_packages([str(ROOT / package)], prefix=package + "."):
            if linux_only(info.name):
                continue
            try:
                importlib.import_module(info.name)
                imported += 1
            except Exception as exc:  # noqa: BLE001 - every failure is the finding
                failed[info.name] = f"{type(exc).__name__}: {exc}"
    return {"imported": imported, "failed": failed}


def open_main_window(work: Path) -> dict:
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from app.window.main_window import MainWindow
    from app.window.settings import Settings

    app = QApplication.instance() or QApplication([])
    window = MainWindow(Settings(QSettings(str(work / "linpar.ini"), QSettings.IniFormat)))
    window.resize(1280, 720)
    window.show()
    app.processEvents()
    hardware = window.wizard.hardware_page
    found = {"title": window.windowTitle(), "visible": window.isVisible(),
             "has_icon": not window.windowIcon().isNull(),
             "rig_offered": hardware.rig_radio.isEnabled(), "rig_status": hardware.rig_status.text()}
    window.close()
    app.processEvents()
    return found


def measure_and_store(work: Path) -> dict:
    """The in-process simulator as the wizard builds it, the journaled runner, then the archive."""
    from analysis.archive.archive import Archive
    from analysis.drivers import load_driver
    from app.wizard.hardware import SIMULATOR, HardwareConfig, open_audio
    from instruments.measurement.plan import MeasurementPlan
    from instruments.measurement.recovery import run_journaled
    from instruments.measurement.recovery_journal import in_use, journal_path

    out = work / "measurements"
    journal = journal_path(out, "portable")
    held_while_measuring = []

    def progress(p) -> None:
        if journal.is_dir():
            held_while_measuring.append(in_use(journal))

    plan = MeasurementPlan.from_template("woofer", n_periods=4, period_samples=8192)
    audio = open_audio(HardwareConfig(kind=SIMULATOR, realtime=False))
    outcome = run_journaled(plan, audio, None, out, name="portable", progress=progress)
    archive = Archive(work / "archive")
    mid = archive.store(outcome.recording_path, outcome.result, {"serial": "portability"})
    stored = [str(e.id) for e in archive.list()]
    fit = outcome.result.fit
    truth = load_driver("paper").parameters      # the simulator's driver
    errors = {name: fit.values[name] / truth[name] - 1.0 for name in ("RE", "Bl", "CMES")} if fit else {}
    return {"recording": outcome.recording_path.is_file(), "stored_id": str(mid), "archive_ids": stored,
            "journal_checks": len(held_while_measuring), "journal_held_at_each": all(held_while_measuring),
            "journal_left": journal.exists(),
            "relative_errors": errors}


def journal_lock(work: Path) -> dict:
    """The lock the recovery journal uses: held by this process, by another, and free once that one is killed."""
    from analysis import file_lock

    path = work / "lock-probe" / "lock"
    path.parent.mkdir()
    mine = file_lock.take(path, wait_s=0)
    held_by_me = file_lock.held(path)
    second = file_lock.take(path, wait_s=0)
    mine.release()
    free_after_release = not file_lock.held(path)

    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys\n"
         f"for m in {BLOCKED!r}: sys.modules[m] = None\n"
         f"sys.path.insert(0, {str(ROOT)!r})\n"
         "from analysis import file_lock\n"
         f"lock = file_lock.take({str(path)!r}, wait_s=0)\n"
         "print('held' if lock else 'refused', flush=True)\n"
         "sys.stdin.read()\n"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    said = holder.stdout.readline().strip()
    held_by_other = file_lock.held(path)
    holder.kill()                # a crash: the holder never releases
    holder.wait()
    deadline = time.monotonic() + 10.0
    while file_lock.held(path) and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"held_by_me": held_by_me, "second_refused": second is None, "free_after_release": free_after_release,
            "other_said": said, "held_by_other": held_by_other, "free_after_kill": not file_lock.held(path)}


def main() -> None:
    work = Path(sys.argv[1])
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    os.environ["LINPAR_ARCHIVE"] = str(work / "default-archive")
    os.environ["LINPAR_CACHE"] = str(work / "cache")
    report = {}
    for step in (import_everything, open_main_window, measure_and_store, journal_lock):
        try:
            report[step.__name__] = step(work) if step is not import_everything else step()
        except Exception:  # noqa: BLE001 - the test shows the traceback
            report[step.__name__] = {"error": traceback.format_exc()}
    report["blocked_still_blocked"] = all(sys.modules.get(name) is None for name in BLOCKED)
    print(json.dumps(report))


if __name__ == "__main__":
    main()
