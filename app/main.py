"""`linpar gui`: the application object, the main window and the event loop."""
from __future__ import annotations

import logging
import os
import sys

EXIT_OK, EXIT_NO_DISPLAY = 0, 2
EXIT_AFTER_ENV = "LINPAR_EXIT_AFTER_S"
# Said by the offscreen platform on every window; noise for whoever runs `make run` without a display.
_IGNORED_QT_MESSAGES = ("This plugin does not support propagateSizeHints()",)


def _qt_message(mode, context, message: str) -> None:
    if message not in _IGNORED_QT_MESSAGES:
        print(message, file=sys.stderr)


def _no_display() -> bool:
    """On Linux without X11/Wayland, Qt would abort inside QApplication with a cryptic message."""
    if not sys.platform.startswith("linux") or os.environ.get("QT_QPA_PLATFORM"):
        return False
    return not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _exit_after_s() -> float | None:
    text = os.environ.get(EXIT_AFTER_ENV)
    if not text:
        return None
    try:
        seconds = float(text)
    except ValueError:
        print(f"linpar: ignoring {EXIT_AFTER_ENV}={text!r}: expected a number of seconds", file=sys.stderr)
        return None
    return max(seconds, 0.0)


def _report_uncaught(window):
    """sys.excepthook for the GUI: a bug in a slot is one message with its crash report, not a traceback on a
    terminal the user may not see (the jobs' own errors go through app.jobs.book.failure_text)."""
    def hook(kind, exc, tb):
        if issubclass(kind, KeyboardInterrupt):
            sys.__excepthook__(kind, exc, tb)
            return
        from app.jobs.book import failure_text
        window.show_error("Internal error", failure_text(exc.with_traceback(tb), "working in the window"))
    return hook


def _load_user_effects() -> list[str]:
    """Register the effects of the user folder and of packages; the files that could not be read, one line each
    (the window says them in the Model lab's User effects branch, and starts without them)."""
    from analysis.effects import registry
    problems: list[str] = []
    registry.register(registry.load_user_effects(problems=problems))
    for line in problems:
        logging.getLogger(__name__).warning("effect file not read: %s", line)
    return problems


def run_gui(path: str | None = None) -> int:
    if _no_display():
        print("linpar: error: no display (DISPLAY and WAYLAND_DISPLAY are unset); set DISPLAY, or "
              "QT_QPA_PLATFORM=offscreen to run without a window (tools/run-gui.sh does)", file=sys.stderr)
        return EXIT_NO_DISPLAY
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")

    # Qt is imported here so that the rest of the CLI never loads it.
    from PySide6.QtCore import QTimer, qInstallMessageHandler
    from PySide6.QtWidgets import QApplication

    from app.window.main_window import MainWindow
    from app.window.settings import APPLICATION, ORGANIZATION

    qInstallMessageHandler(_qt_message)

    QApplication.setOrganizationName(ORGANIZATION)
    QApplication.setApplicationName(APPLICATION)
    app = QApplication.instance() or QApplication(sys.argv[:1])
    from app.jobs.gui_gc import collect_in_gui_thread
    collect_in_gui_thread()               # a worker thread must never free a Qt object (app/jobs/gui_gc.py)
    from app.widgets.style import app_icon
    app.setWindowIcon(app_icon())         # dialogs and the task bar too (on Linux the desktop entry names it)
    problems = _load_user_effects()
    window = MainWindow()
    sys.excepthook = _report_uncaught(window)
    window.model_lab.catalogue.set_problems(problems)
    from app.window.window_fit import show_fitted
    show_fitted(window)                   # maximized when the screen is smaller than the window's preferred size
    QTimer.singleShot(0, window.offer_unfinished)     # measurements a crash cut short: keep, analyse, discard
    if path:
        window.open_path(path)
    exit_after = _exit_after_s()
    if exit_after is not None:
        # `make run` without a display: prove the window starts, then leave cleanly.
        QTimer.singleShot(int(exit_after * 1000), window.close)
        QTimer.singleShot(int(exit_after * 1000), lambda: app.exit(EXIT_OK))
    code = app.exec()
    return EXIT_OK if exit_after is not None else int(code)
