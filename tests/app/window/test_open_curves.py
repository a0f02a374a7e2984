"""File > Open curves…'s dialog (app/window/open_curves.py): the files it gathers, and what the window does with them."""
from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QDialogButtonBox

from app.jobs.curves import CurvesRequest
from app.window.open_curves import OpenCurvesDialog


def test_the_dialog_needs_an_impedance_file_and_gives_the_request(qtbot, tmp_path):
    dialog = OpenCurvesDialog(str(tmp_path))
    qtbot.addWidget(dialog)
    open_button = dialog.buttons.button(QDialogButtonBox.Open)
    assert not open_button.isEnabled()
    dialog.impedance.setText(f"  {tmp_path / 'Z.txt'} ")
    assert open_button.isEnabled()
    assert dialog.request() == CurvesRequest(tmp_path / "Z.txt", None, False)
    dialog.hx.setText(str(tmp_path / "HX.txt"))
    dialog.mm_per_volt.setChecked(True)
    assert dialog.request() == CurvesRequest(tmp_path / "Z.txt", tmp_path / "HX.txt", True)


def test_the_menu_entry_opens_the_curves_chosen(window, monkeypatch, tmp_path):
    opened: list[CurvesRequest] = []
    monkeypatch.setattr(window, "open_curves", opened.append)

    def accept(dialog):
        dialog.impedance.setText(str(tmp_path / "Z.txt"))
        return OpenCurvesDialog.Accepted
    monkeypatch.setattr(OpenCurvesDialog, "exec", accept)
    window.menus.open_curves_action.trigger()
    assert opened == [CurvesRequest(Path(tmp_path / "Z.txt"))]
    monkeypatch.setattr(OpenCurvesDialog, "exec", lambda dialog: OpenCurvesDialog.Rejected)
    window.menus.open_curves_action.trigger()
    assert len(opened) == 1                 # cancelled: nothing opened
