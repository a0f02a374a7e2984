"""The driver step's form holds still while Sd is typed: the rows under it never move (issue: "typing Sd makes the
form jump under the mouse")."""
from __future__ import annotations

import pytest
from PySide6.QtWidgets import QApplication

from app.wizard import MeasureWizard


@pytest.fixture
def wizard(qtbot, settings, tmp_path):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    w = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(w)
    w.show()
    yield w
    w.shutdown(10_000)


def _laid_out() -> None:
    for _ in range(5):
        QApplication.processEvents()


@pytest.mark.parametrize("width", [1280, 1920])
def test_the_rows_under_sd_stay_where_they_are_while_sd_is_typed(qtbot, wizard, width):
    wizard.resize(width, 700)
    page = wizard.driver_page
    _laid_out()
    below = (page.impedance, page.template, page.operator_edit)

    def rows() -> list[int]:
        return [w.mapTo(page, w.rect().topLeft()).y() for w in below]
    unknown = rows()
    for mode, typed in ((0, "1"), (0, "13"), (0, "132.7"), (1, "13"), (0, "0")):
        page.sd_mode.setCurrentIndex(mode)
        page.sd_value.lineEdit().selectAll()
        qtbot.keyClicks(page.sd_value.lineEdit(), typed)
        _laid_out()
        assert rows() == unknown, (mode, typed, page.sd_note.text())
