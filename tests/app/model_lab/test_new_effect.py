"""The Model lab's "New effect…" dialog: write the missing effect, see it checked and previewed, save it, fit it."""
from __future__ import annotations

import html

import numpy as np
import pytest
from PySide6.QtCore import Qt

from analysis.effects import registry
from analysis.pipeline import analyze_recording
from app.model_lab.catalogue import EFFECT_ROLE
from app.model_lab.new_effect import NewEffectDialog
from app.model_lab.page import ModelLab
from tests.analysis.effects.test_user_effects import EXAMPLE

from tests.app.model_lab.test_model_lab import CLOSE_WAIT_MS, _toggle
from tests.pace import wait_ms


@pytest.fixture(scope="module")
def rms_result():
    """The paper's driver with Rms(f) = Rms*sqrt(f/fs) (the example effect file), fitted with lr2,creep-log."""
    from analysis.effects import parse_effects
    from analysis.effects.user import load_effect_file
    from analysis.model.composed import Model
    from analysis.synthesis import synthesize_recording
    from tests.builders import PAPER, TYPICAL_NOISE, multitone
    truth = {**PAPER.parameters}
    truth["r"] = truth["Bl"] ** 2 / truth["RES"]
    mt = multitone()
    model = Model(parse_effects("lr2,creep-log") + (load_effect_file(EXAMPLE),))
    rec = synthesize_recording(model, truth, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1, TYPICAL_NOISE,
                               seed=5, driver={"name": "rms", "sd_m2": 0.0133})
    return analyze_recording(rec, effects=parse_effects("lr2,creep-log"))


@pytest.fixture
def lab(qtbot, rms_result, tmp_path, monkeypatch):
    monkeypatch.setenv(registry.FOLDER_ENV, str(tmp_path))
    lab = ModelLab()
    qtbot.addWidget(lab)
    lab.resize(1400, 850)
    lab.show()
    lab.set_result(rms_result)
    yield lab
    assert lab.shutdown(CLOSE_WAIT_MS)


def _open_dialog(qtbot, lab) -> NewEffectDialog:
    qtbot.mouseClick(lab.catalogue.new_effect_button, Qt.LeftButton)
    dialog = lab.new_effect_dialog
    assert dialog is not None and dialog.isVisible()
    return dialog


def _status(dialog: NewEffectDialog) -> str:
    return html.unescape(dialog.status.text())


def _write(qtbot, dialog: NewEffectDialog, formula: str, parameter=("r", "kg/s", "0.5", "-10", "10")) -> None:
    dialog.id_edit.setText("rms-sqrt-f")
    dialog.title_edit.setText("Viscous damping rising with the square root of frequency")
    dialog.site_combo.setCurrentIndex(dialog.site_combo.findData("mechanical"))
    dialog.physics_edit.setPlainText("Air pumped through the spider and the surround.")
    dialog.formula_edit.setText(formula)
    if parameter is not None:
        dialog.set_parameter(0, *parameter)
    dialog.timer.stop()
    dialog.check()          # what the pause in typing would do


def test_the_form_is_checked_as_one_types_with_the_files_one_line(qtbot, lab):
    dialog = _open_dialog(qtbot, lab)
    assert not dialog.save_button.isEnabled()
    _write(qtbot, dialog, "r * (sqrt(w / ws) - q)")
    assert "formula, column 21: unknown name 'q'" in _status(dialog) and not dialog.save_button.isEnabled()
    _write(qtbot, dialog, "r * (sqrt(w / ws) - 1)", ("r", "kg/s", "0.5", "-10", ""))
    assert "parameters.r: expected both bounds" in _status(dialog)
    _write(qtbot, dialog, "r * (sqrt(w / ws) - 1)")
    assert "✓" in _status(dialog) and dialog.save_button.isEnabled()
    # The typed text waits for a pause, then is checked: no check per keystroke.
    dialog.formula_edit.setText("r * (sqrt(w / ws) - 1) +")
    assert dialog.timer.isActive()
    qtbot.waitUntil(lambda: "not a valid expression" in _status(dialog), timeout=wait_ms(10))


def test_the_preview_draws_the_effects_signature_over_the_misfit(qtbot, lab):
    dialog = _open_dialog(qtbot, lab)
    _write(qtbot, dialog, "r * (sqrt(w / ws) - 1)")
    assert set(dialog.plots) == {"impedance", "displacement"}
    _, change = dialog.plots["displacement"].change.getData()
    _, misfit = dialog.plots["displacement"].misfit.getData()
    assert np.isfinite(change).all() and np.abs(change).max() > 0.1          # per cent
    # More damping above fs lowers |Hx| there, as the misfit the current version leaves does (same sign).
    above = len(change) // 2
    assert np.sign(np.median(change[above:])) == np.sign(np.median(misfit[above:]))


def test_saving_writes_the_user_folder_joins_the_catalogue_and_the_fit_reaches_the_noise(qtbot, lab, tmp_path):
    before = max(lab.current.fitted.fit.chi2_red_by_channel().values())
    assert before > 100
    dialog = _open_dialog(qtbot, lab)
    _write(qtbot, dialog, "r * (sqrt(w / ws) - 1)")
    dialog.save_button.click()
    assert not dialog.isVisible()
    saved = tmp_path / "rms-sqrt-f.toml"
    assert saved.is_file() and [e.id for e in registry.user_effects()] == ["rms-sqrt-f"]
    head = lab.catalogue.user_head
    assert [head.child(i).data(0, EFFECT_ROLE).id for i in range(head.childCount())] == ["rms-sqrt-f"]
    assert "r * (sqrt(w / ws) - 1)" in lab.catalogue.detail.toPlainText()
    version = _toggle(qtbot, lab, "rms-sqrt-f", True)
    chi2 = version.fitted.fit.chi2_red_by_channel()
    assert version.fitted.fit.model.effect_ids == ("lr2", "creep-log", "rms-sqrt-f")
    assert max(chi2.values()) < 1.5, chi2
    # The file the next start reads is the one written.
    again = registry.load_user_effects(folder=tmp_path, packages=False)
    assert [e.id for e in again] == ["rms-sqrt-f"] and again[0].formula.text == "r * (sqrt(w / ws) - 1)"


def test_bad_files_of_the_user_folder_are_said_in_the_branch(qtbot, lab):
    lab.catalogue.set_problems(["/x/bad.toml: site: unknown site 'coil'; expected one of electrical, ..."])
    head = lab.catalogue.user_head
    texts = [head.child(i).text(0) + " " + head.child(i).text(1) for i in range(head.childCount())]
    assert any("1 file(s) not read" in text and "bad.toml: site" in text for text in texts)


def test_the_preview_has_a_phase_panel_beside_the_size_one(qtbot, lab):
    dialog = _open_dialog(qtbot, lab)
    _write(qtbot, dialog, "r * (sqrt(w / ws) - 1)")
    assert set(dialog.phase_plots) == {"impedance", "displacement"}
    size_plot, phase_plot = dialog.plots["impedance"], dialog.phase_plots["impedance"]
    assert size_plot.isVisible() and phase_plot.isVisible()
    left = lambda widget: widget.mapToGlobal(widget.rect().topLeft()).x()
    assert left(phase_plot) > left(size_plot)          # beside it, on its right
    _, change = phase_plot.change.getData()
    _, misfit = phase_plot.misfit.getData()
    # Damping rising with frequency turns Z's phase near fs: a change in degrees, and a misfit the same.
    assert np.isfinite(change).all() and np.abs(change).max() > 0.1
    assert np.isfinite(misfit).all() and np.abs(misfit).max() > 0.1


def test_the_site_starts_at_the_one_the_diagnosis_named(qtbot, rms_result):
    from analysis.effects.base import Site
    dialog = NewEffectDialog(rms_result.fit, site=Site.DISPLACEMENT)
    qtbot.addWidget(dialog)
    assert dialog.site_combo.currentData() == "displacement"
    plain = NewEffectDialog(rms_result.fit)
    qtbot.addWidget(plain)
    assert plain.site_combo.currentData() == "mechanical"
