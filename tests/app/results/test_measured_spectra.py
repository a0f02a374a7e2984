"""A broken lead still shows what was measured: the valid channels' spectra (and Hx) on the Results page, and one
"not measured" note above the parameter table instead of a truncated reason in every cell. Beside it, the remark
on an Re unusual for the nominal impedance entered."""
from __future__ import annotations

import numpy as np
import pytest

from analysis.recording.format import make_recording, write_recording
from app.results.parameter_table import VALUE
from instruments.simulation import faults

from tests.app.conftest import open_and_wait


def _rewritten(folder, name, current_scale=1.0, driver=None):
    rec = faults.clean()
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["current"] = signals["current"] * current_scale
    out = make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins,
                         {**dict(rec.driver or {}), **(driver or {})})
    wav, _ = write_recording(folder / name, out)
    return wav


@pytest.fixture(scope="module")
def zeroed_current(tmp_path_factory):
    return _rewritten(tmp_path_factory.mktemp("broken"), "current-zeroed", current_scale=0.0)


def test_a_broken_current_lead_shows_voltage_displacement_and_hx(qtbot, window, zeroed_current):
    outcome, = open_and_wait(qtbot, window, zeroed_current)
    results = window.results
    assert outcome.result.fit is None
    assert results.impedance_stack.currentWidget() is results.measured_spectra
    assert results.plot_tabs.tabText(0) == "Measured"
    assert results.measured_spectra.shown == ["voltage", "displacement", "Hx"]      # not the red current
    items = results.measured_spectra.getItem(0, 0).listDataItems()
    x, y = items[0].getData()                               # log10 of Hz and of volts: the plot's log axes
    s = outcome.result.spectra
    assert np.allclose(10 ** y, s.channels["voltage"].amplitude[s.excited_bins])
    assert np.allclose(10 ** x, s.freqs[s.excited_bins])
    # One note, every value cell the same two words.
    table = results.parameter_table
    model = table.parameter_model
    assert model.common_reason and table.note.isVisibleTo(results) and model.common_reason in table.note.text()
    values = {model.data(model.index(r, VALUE)) for r in range(model.rowCount()) if not model.is_section(r)
              and model.parameter(r).name != "Sd"}
    assert values == {"not measured"}


def test_a_fitted_recording_after_a_broken_one_shows_its_impedance_again(qtbot, window, zeroed_current, tmp_path):
    open_and_wait(qtbot, window, zeroed_current)
    good = _rewritten(tmp_path, "good")
    open_and_wait(qtbot, window, good)
    results = window.results
    assert results.impedance_stack.currentWidget() is results.impedance_plot
    assert results.plot_tabs.tabText(0) == "Impedance Z"
    assert not results.parameter_table.parameter_model.common_reason
    assert not results.parameter_table.note.isVisibleTo(results)


@pytest.mark.parametrize("nominal, remarked", [(8.0, True), (4.0, False)])
def test_re_unusual_for_the_nominal_impedance_draws_a_remark(qtbot, window, tmp_path, nominal, remarked):
    wav = _rewritten(tmp_path, f"nominal-{nominal:g}", driver={"nominal_impedance_ohm": nominal})
    outcome, = open_and_wait(qtbot, window, wav)
    re = outcome.result.parameters["RE"].value
    assert 2.5 < re < 3.5                                   # the paper driver: Re 3 Ω
    text = window.results.source_label.text()
    assert ("times the nominal 8 Ω entered" in text) == remarked, text
