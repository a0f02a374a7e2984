"""The first window fits the screen: at most the room the desktop leaves, maximized on a small screen, a size
remembered on a larger monitor clamped to the current one (app/window/window_fit.py)."""
from __future__ import annotations

import pytest
from PySide6.QtCore import QRect

import app.window.window_fit as window_fit
from app.window.window_fit import PREFERRED_SIZE, clamped_placement, first_placement

LAPTOP = QRect(0, 0, 1280, 720)
LAPTOP_WITH_PANEL = QRect(0, 27, 1280, 693)        # a top panel takes 27 px
DESKTOP = QRect(0, 0, 1920, 1080)


def _inside(frame: QRect, room: QRect) -> bool:
    return room.contains(frame.topLeft()) and room.contains(frame.bottomRight())


@pytest.mark.parametrize("room", [LAPTOP, LAPTOP_WITH_PANEL])
def test_a_small_screen_gets_the_whole_room_maximized(room):
    placement = first_placement(room)
    assert placement.maximized and placement.geometry == room


def test_a_large_screen_gets_the_preferred_size_centred():
    placement = first_placement(DESKTOP)
    assert not placement.maximized and placement.geometry.size() == PREFERRED_SIZE
    assert _inside(placement.geometry, DESKTOP) and placement.geometry.center() == DESKTOP.center()


@pytest.mark.parametrize("remembered", [QRect(100, 60, 1800, 1000), QRect(1500, 900, 1400, 900),
                                        QRect(-3000, -200, 1200, 700)])
def test_a_remembered_size_is_clamped_and_moved_onto_the_screen(remembered):
    placement = clamped_placement(remembered, LAPTOP_WITH_PANEL)
    assert _inside(placement.geometry, LAPTOP_WITH_PANEL), placement.geometry
    assert placement.geometry.width() <= remembered.width() and placement.geometry.height() <= remembered.height()


def test_a_remembered_size_that_fits_is_kept():
    remembered = QRect(200, 100, 1200, 800)
    placement = clamped_placement(remembered, DESKTOP)
    assert placement.geometry == remembered and not placement.maximized


@pytest.fixture
def screen_of(monkeypatch):
    def use(room: QRect) -> None:
        monkeypatch.setattr(window_fit, "_room", lambda widget: QRect(room))
    return use


@pytest.mark.parametrize("room, maximized", [(LAPTOP, True), (LAPTOP_WITH_PANEL, True), (DESKTOP, False)])
def test_the_first_window_fits_each_screen(qtbot, settings, screen_of, room, maximized):
    from app.window.main_window import MainWindow
    screen_of(room)
    window = MainWindow(settings)
    qtbot.addWidget(window)
    assert _inside(window.geometry(), room), window.geometry()
    assert bool(window.property("fit_maximized")) is maximized
    # Its pages' layouts can live in that room: Qt would otherwise grow the window past the screen.
    hint = window.minimumSizeHint()
    assert hint.width() <= room.width() and hint.height() <= room.height(), hint


def test_a_window_saved_on_a_large_monitor_opens_inside_a_small_one(qtbot, settings, screen_of):
    from app.window.main_window import MainWindow
    screen_of(DESKTOP)
    big = MainWindow(settings)
    qtbot.addWidget(big)
    big.setGeometry(QRect(300, 100, 1600, 950))
    settings.save_window(big.saveGeometry(), big.saveState())
    screen_of(LAPTOP_WITH_PANEL)
    window = MainWindow(settings)
    qtbot.addWidget(window)
    assert _inside(window.geometry(), LAPTOP_WITH_PANEL), window.geometry()
