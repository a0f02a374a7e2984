"""Colours, pens and pyqtgraph options shared by every page.

White plots with black text: screenshots go into reports and documents, and a
dark theme would make them unreadable when printed.
"""
from __future__ import annotations

from importlib.resources import files

import pyqtgraph as pg
from PySide6.QtGui import QIcon

MEASURED = "#1f5fbf"        # measured lines: blue points
MODEL = "#d1495b"           # the fitted model: red line
REFERENCE = "#2e8b57"       # imported curves: the exporting tool's own fitted curve, a green dashed line
RESIDUAL_REAL = "#1f5fbf"
RESIDUAL_IMAG = "#e08a00"
RESIDUAL_BEYOND = "#8e1b1b"  # residuals beyond the strip's range, pinned at its edge
GUIDE = "#8c8c8c"
MISSING_TEXT = "#8c8c8c"

# Validity lights (result.validity.overall, analysis/validity/assessment.py) -> (background, text) colours.
VALIDITY_COLOURS = {
    "green": ("#d8f0d8", "#1b5e20"),
    "yellow": ("#fff1c9", "#7a5300"),
    "red": ("#f8d4d4", "#8e1b1b"),
    "unknown": ("#e6e6e6", "#404040"),
}
VALIDITY_TEXT = {
    "green": "every channel passed the signal, noise and distortion checks",
    "yellow": "some checks are doubtful: read the channel findings before trusting the parameters",
    "red": "the measurement failed a validity check: its parameters are not to be trusted",
    "unknown": "not checked yet: the signal, noise and distortion checks have not run on this measurement",
}

MEASURED_SYMBOL_SIZE = 5
MODEL_WIDTH = 2


def configure_pyqtgraph() -> None:
    """Must run before the first plot widget is built (pyqtgraph reads these at construction)."""
    pg.setConfigOptions(antialias=True, background="w", foreground="k")


def validity_colours(state: str) -> tuple[str, str]:
    return VALIDITY_COLOURS.get(state, VALIDITY_COLOURS["unknown"])


def model_pen():
    return pg.mkPen(MODEL, width=MODEL_WIDTH)


def reference_pen():
    from PySide6.QtCore import Qt
    return pg.mkPen(REFERENCE, width=MODEL_WIDTH, style=Qt.DashLine)


def measured_brush():
    return pg.mkBrush(MEASURED)


def app_icon():
    """linpar's icon (resources/icons/linpar.png, shipped in the wheel) for the window and the task bar."""
    return QIcon(str(files("resources") / "icons" / "linpar.png"))
