"""The first window as a newcomer sees it on a 1280x720 and a 1920x1080 screen, and the Results page of a
recording whose model misses hidden physics, its residuals beyond the strip's ±30σ pinned at the edge.

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only first-window

Writes first-window-<W>x<H>.png (a fresh user's window, sized by app/window/window_fit.py for that screen) and
results-beyond-range-<W>x<H>.png (the Results page, displacement tab: a laser 100 µs late the default model
does not know about).
"""
from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QRect, QSettings
from PySide6.QtWidgets import QApplication

from tools.screenshot_kit import ANALYSIS_TIMEOUT_S, SMALL_AND_LARGE, grab_small_and_large, settle, wait_for


def first_window_screenshots(app: QApplication, window, folder: Path, out: Path, misfit_wav: Path) -> list[Path]:
    """misfit_wav: a recording the default model does not describe (tools/screenshots.hidden_delay_recording)."""
    import app.window.window_fit as window_fit
    from app.window.main_window import MainWindow
    from app.window.settings import Settings
    written = []
    real_room = window_fit._room
    try:
        for width, height in SMALL_AND_LARGE:
            # What the screen would offer: the offscreen platform's own screen is neither size.
            window_fit._room = lambda widget, w=width, h=height: QRect(0, 0, w, h)
            fresh = MainWindow(Settings(QSettings(str(folder / f"fresh-{width}.ini"), QSettings.IniFormat)))
            # Shown at the geometry fit_window chose: maximizing would fill the offscreen platform's own screen.
            geometry = fresh.geometry()
            fresh.show()
            fresh.setGeometry(geometry)
            settle(app, 600)
            path = out / f"first-window-{width}x{height}.png"
            fresh.grab().save(str(path))
            print(f"{path.name}: window {fresh.width()}x{fresh.height()} on a {width}x{height} screen")
            written.append(path)
            fresh.close()
    finally:
        window_fit._room = real_room
    window.open_path(misfit_wav)
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        raise RuntimeError(f"the analysis did not finish in {ANALYSIS_TIMEOUT_S} s")
    window.pages.setCurrentWidget(window.results)
    window.results.plot_tabs.setCurrentIndex(1)
    settle(app)
    print("displacement strip:", window.results.displacement_plot.beyond_text or "nothing beyond the range")
    print("impedance strip:", window.results.impedance_plot.beyond_text or "nothing beyond the range")
    written += grab_small_and_large(app, window, out, "results-beyond-range")
    return written
