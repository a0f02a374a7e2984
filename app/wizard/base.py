"""What every wizard page shares: the state handed from page to page, the page base."""
from __future__ import annotations

import html
from dataclasses import dataclass, field

from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtWidgets import QLabel, QWidget

from app.wizard.measure_session import MeasureSession
from app.wizard.calibration import Corrections
from app.wizard.hardware import HardwareConfig
from app.wizard.plans import DriverInfo

ERROR_COLOUR = "#8e1b1b"
OK_COLOUR = "#1b5e20"


@dataclass
class WizardState:
    """What the pages have settled so far; GUI thread only."""

    settings: QSettings
    driver: DriverInfo | None = None
    hardware: HardwareConfig = field(default_factory=HardwareConfig)
    corrections: Corrections | None = None
    level_v: float | None = None
    level_reason: str = ""
    level_words: str = ""                     # the reason in a few words ("enough signal")
    outcome: object | None = None            # app.wizard.measure_session.MeasureOutcome


class WizardPage(QWidget):
    """A step. `missing()` is why Next is not possible yet (None: it is); emit `changed` when it may differ."""

    changed = Signal()
    title = ""
    subtitle = ""

    def __init__(self, state: WizardState, session: MeasureSession, parent=None):
        super().__init__(parent)
        self.state = state
        self.session = session

    def missing(self) -> str | None:
        return None

    @property
    def busy(self) -> bool:
        return False

    def enter(self) -> None:
        """The page is shown (forwards or backwards): refresh from the state."""

    def commit(self) -> None:
        """Next was pressed: put what the page settled into the state."""


def rich_label(text: str = "", selectable: bool = False) -> QLabel:
    label = QLabel(text)
    label.setTextFormat(Qt.RichText)
    label.setWordWrap(True)
    if selectable:
        label.setTextInteractionFlags(Qt.TextSelectableByMouse)
    return label


def coloured(text: str, colour: str) -> str:
    return f"<span style='color:{colour}'>{html.escape(text)}</span>"
