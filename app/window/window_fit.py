"""The main window's size on the screen it opens on: never larger than the room the desktop leaves.

A first start opens at PREFERRED_SIZE, centred, when the screen has room for it, and maximized when it has
not (a 1280x720 laptop): at 1400x900 the wizard's Back/Next and the status bar fell below the screen, and a
newcomer could not leave step 1. A size remembered from a larger monitor is clamped to the current one.
The window's geometry is set to the room as well as maximized: without a window manager (a kiosk, Xvfb) the
maximized state is only a hint nobody acts on.
"""
from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QRect, QSize
from PySide6.QtGui import QGuiApplication

PREFERRED_SIZE = QSize(1400, 900)


@dataclass(frozen=True)
class Placement:
    geometry: QRect          # the window's frame, inside the available geometry
    maximized: bool


def _room(widget) -> QRect:
    """The available geometry (the screen less task bars) of the screen the widget is on, or the primary one."""
    screen = widget.screen() if widget is not None else None
    screen = screen or QGuiApplication.primaryScreen()
    return screen.availableGeometry() if screen is not None else QRect(0, 0, PREFERRED_SIZE.width(),
                                                                         PREFERRED_SIZE.height())


def first_placement(available: QRect) -> Placement:
    """A first start: the preferred size centred, or the whole room (maximized) on a screen too small for it."""
    if available.width() < PREFERRED_SIZE.width() or available.height() < PREFERRED_SIZE.height():
        return Placement(QRect(available), True)
    frame = QRect(0, 0, PREFERRED_SIZE.width(), PREFERRED_SIZE.height())
    frame.moveCenter(available.center())
    return Placement(frame, False)


def clamped_placement(remembered: QRect, available: QRect, was_maximized: bool = False) -> Placement:
    """A remembered frame made to fit the room: no larger, moved inside it; maximized when it fills the room."""
    width = min(remembered.width(), available.width())
    height = min(remembered.height(), available.height())
    frame = QRect(remembered.x(), remembered.y(), width, height)
    # Moved back inside, so that a window remembered on a monitor no longer attached is not off screen.
    frame.moveLeft(max(available.left(), min(frame.left(), available.right() + 1 - width)))
    frame.moveTop(max(available.top(), min(frame.top(), available.bottom() + 1 - height)))
    fills = width >= available.width() or height >= available.height()
    return Placement(frame, was_maximized or fills)


def fit_window(window, restored: bool) -> Placement:
    """Size `window` for its screen; restored: whether a remembered geometry was applied (then it is clamped).

    The caller shows the window with show_fitted, which maximizes it when the placement says so.
    """
    available = _room(window)
    if restored:
        placement = clamped_placement(window.geometry(), available, window.isMaximized())
    else:
        placement = first_placement(available)
    # The window's minimum (its pages' layouts) must not push it past the room either.
    window.setMinimumSize(window.minimumSize().boundedTo(available.size()))
    window.setGeometry(placement.geometry)
    window.setProperty("fit_maximized", placement.maximized)
    return placement


def show_fitted(window) -> None:
    """show(), or showMaximized() when fit_window found the screen too small for the window."""
    if window.property("fit_maximized"):
        window.showMaximized()
    else:
        window.show()
