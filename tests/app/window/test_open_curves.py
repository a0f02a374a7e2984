"""File > Open curves…'s dialog (app/window/open_curves.py): the files it gathers, and what the window does with them."""
from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtWidgets import QDialogButtonBox

from app.jobs.curves import CurvesRequest
from app.window.open_curves import OpenCurvesDialog
from tests.app.conftest import PAPER, analysis_wait_ms
from tests.uiv_files import REAL_UIV, write_uiv_and_zma


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


def test_the_dialog_offers_uiv_spectra_as_a_kind_of_its_own(qtbot, tmp_path):
    dialog = OpenCurvesDialog(str(tmp_path))
    qtbot.addWidget(dialog)
    open_button = dialog.buttons.button(QDialogButtonBox.Open)
    dialog.impedance.setText(str(tmp_path / "Z.txt"))
    assert dialog.curves_choice.isChecked() and not dialog.uiv.isEnabled()
    dialog.uiv_choice.setChecked(True)
    # The other kind's rows are greyed, not hidden: Z and Hx do not go with the spectra.
    assert dialog.uiv.isEnabled() and not dialog.impedance.isEnabled() and not dialog.hx.isEnabled()
    assert not open_button.isEnabled()                  # the spectra file is what it needs now
    dialog.uiv.setText(f" {tmp_path / 'UIV.csv'}  ")
    assert open_button.isEnabled()
    assert dialog.request() == CurvesRequest(uiv=tmp_path / "UIV.csv")
    dialog.curves_choice.setChecked(True)
    assert dialog.request() == CurvesRequest(tmp_path / "Z.txt")


def _open(qtbot, window, request: CurvesRequest, signal: str):
    with qtbot.waitSignal(getattr(window, signal), timeout=analysis_wait_ms(4)) as blocker:
        window.open_curves(request)
    return blocker.args


def test_the_window_analyses_uiv_spectra_as_linpar_analyze_uiv(qtbot, window, dialogs, tmp_path):
    uiv, _ = write_uiv_and_zma(tmp_path)
    outcome, = _open(qtbot, window, CurvesRequest(uiv=uiv), "model_part_shown")
    assert not dialogs and window.results.result is outcome.result and outcome.path == uiv
    assert outcome.result.parameters["Bl"].value == pytest.approx(PAPER.parameters["Bl"], rel=1e-3)
    for plot in (window.results.impedance_plot, window.results.displacement_plot):
        x, _ = plot.phase_measured.getData()             # complex spectra: the phase is measured too
        assert x is not None and len(x) > 50
    assert "uiv.csv" in window.windowTitle()


@pytest.mark.skipif(not REAL_UIV.exists(), reason=f"the real U/I/V spectra are kept outside the repository and "
                                                    f"missing here: {REAL_UIV}")
def test_real_uiv_spectra_given_as_the_impedance_say_so_in_one_line(qtbot, window, dialogs):
    message, = _open(qtbot, window, CurvesRequest(REAL_UIV), "analysis_failed")
    kind, title, text = dialogs[0]
    assert len(dialogs) == 1 and kind == "warning" and REAL_UIV.name in title and text == message
    assert text.startswith(f"{REAL_UIV.name} holds complex U, I and laser spectra")
    assert "“U, I and laser spectra”" in text and "\n" not in text and "--uiv" not in text
    assert not window.busy and window.results.result is None
    # The real file, given as what it is, is analysed.
    outcome, = _open(qtbot, window, CurvesRequest(uiv=REAL_UIV), "model_part_shown")
    assert len(dialogs) == 1 and outcome.result.fit is not None
    assert 3 < outcome.result.parameters["RE"].value < 8 and outcome.result.parameters["Bl"].value > 1
