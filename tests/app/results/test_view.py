"""The Results page on synthetic recordings of the paper's driver."""
from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QHeaderView

from analysis.derived import ParameterValue
from app.results.parameter_table import COLUMNS, NAME, SIZED_COLUMNS, STD, UNIT, VALUE

from tests.app.conftest import PAPER, open_and_wait
from tests.pace import wait_ms


def _cell(table, name: str, column: int, role=Qt.DisplayRole):
    model = table.parameter_model
    return model.data(model.index(model.row_of(name), column), role)


def _lengths(*items) -> list[int]:
    return [len(item.getData()[0]) for item in items]


@pytest.fixture
def shown(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["paper"])
    return window.results


def test_parameter_table_shows_re_within_one_percent(shown):
    value = float(_cell(shown.parameter_table, "RE", VALUE))
    assert value == pytest.approx(PAPER.parameters["RE"], rel=0.01)
    assert _cell(shown.parameter_table, "RE", UNIT) == "Ω"
    assert float(_cell(shown.parameter_table, "RE", STD)) > 0


def test_table_uses_customary_units(shown):
    assert _cell(shown.parameter_table, "LE", UNIT) == "mH"
    assert float(_cell(shown.parameter_table, "LE", VALUE)) == pytest.approx(PAPER.parameters["LE"] * 1e3, rel=0.01)
    assert _cell(shown.parameter_table, "Mms", UNIT) == "g"
    assert float(_cell(shown.parameter_table, "Mms", VALUE)) == pytest.approx(11.87, rel=0.01)


def test_every_plot_has_measured_model_and_residual_data(shown):
    for plot in (shown.impedance_plot, shown.displacement_plot):
        n_lines, n_dense, *rest = _lengths(plot.magnitude_measured, plot.magnitude_model, plot.phase_measured,
                                           plot.phase_model, plot.residual_real, plot.residual_imag)
        assert n_lines > 50 and n_dense > n_lines
        assert rest == [n_lines, n_dense, n_lines, n_lines]
    spl = shown.spl_panel
    assert spl.stack.currentWidget() is spl.plot
    assert min(_lengths(spl.plot.measured, spl.plot.model)) > 0


def test_residual_strip_is_in_sigma_units(shown):
    x, y = shown.impedance_plot.residual_real.getData()
    assert np.isfinite(y).all()
    assert np.std(y) == pytest.approx(1.0, abs=0.3)          # noise only: unit scatter


def test_model_line_follows_the_measured_points(shown):
    plot = shown.impedance_plot
    f, measured = plot.magnitude_measured.getData()
    fd, model = plot.magnitude_model.getData()
    assert np.interp(f, fd, model) == pytest.approx(measured, rel=0.01)
    _, phase = shown.displacement_plot.phase_measured.getData()
    fd, phase_model = shown.displacement_plot.phase_model.getData()
    assert np.abs(np.interp(_, fd, phase_model) - phase).max() < 5.0      # same branch, no 360 jumps


def test_fit_quality_and_validity(shown):
    headline = shown.fit_quality.headline.text()
    # In words: the model by its effects' titles, and how well it explains each channel.
    assert "LR-2" in headline and "Logarithmic creep" in headline
    assert "explains the impedance and the displacement down to their noise" in headline
    for part in ("χ²", "AIC", "BIC", "lr2"):
        assert part not in headline
    # The numbers behind it, folded away until asked for.
    details = shown.fit_quality.details
    assert not details.isVisible()
    shown.fit_quality.toggle.click()
    assert details.isVisible()
    for part in ("lr2", "creep-log", "reduced χ²", "Z ", "Hx ", "AIC", "BIC"):
        assert part in details.text()
    # a clean simulated measurement: the validity checks find nothing wrong
    assert shown.validity_box.state == "green"
    assert "green" in shown.validity_box.text().lower()


def test_spl_follows_voltage(shown):
    spl = shown.spl_panel
    _, before = spl.plot.model.getData()
    spl.voltage.setValue(spl.voltage.value() * 2)
    _, after = spl.plot.model.getData()
    assert after - before == pytest.approx(20 * np.log10(2), abs=1e-6)


def test_without_sd_the_spl_asks_for_it_and_entering_it_recomputes(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["no_sd"])
    results = window.results
    spl = results.spl_panel
    assert spl.stack.currentWidget() is spl.message
    assert "Enter Sd" in spl.message.text()
    assert results.result.parameters["Vas"].value is None
    with qtbot.waitSignal(results.result_changed):
        spl.sd.setValue(133.0)                        # cm^2
    assert spl.stack.currentWidget() is spl.plot
    assert results.result.sd_m2 == pytest.approx(0.0133)
    vas = float(_cell(results.parameter_table, "Vas", VALUE))
    assert vas == pytest.approx(10.5, rel=0.02)


def test_without_displacement_missing_values_are_greyed_with_reasons(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["no_laser"])
    results = window.results
    table = results.parameter_table
    assert _cell(table, "Bl", VALUE).startswith("n/a: not identifiable without displacement")
    assert "Bl only appears in Hx" in _cell(table, "Bl", VALUE, Qt.ToolTipRole)
    assert _cell(table, "Bl", VALUE, Qt.ForegroundRole) is not None
    row = table.parameter_model.row_of("Bl")
    assert table.columnSpan(row, VALUE) == 2
    assert _cell(table, "RE", VALUE, Qt.ForegroundRole) is None
    assert results.displacement_stack.currentWidget() is results.no_displacement
    assert "no displacement channel" in results.spl_panel.message.text()
    assert "Z only" in results.source_label.text()


def test_a_new_recording_replaces_the_old_one(qtbot, window, recordings):
    open_and_wait(qtbot, window, recordings["paper"])
    open_and_wait(qtbot, window, recordings["no_laser"])
    results = window.results
    assert results.displacement_plot.magnitude_measured.getData()[0] is None or \
        len(results.displacement_plot.magnitude_measured.getData()[0]) == 0
    assert "no-laser.wav" in window.windowTitle()


@pytest.mark.parametrize("state", ["green", "yellow", "red", "unknown", "something new"])
def test_validity_box_shows_each_state_in_its_colour(qapp, state):
    from app.widgets import style
    from app.results.view import ValidityBox
    box = ValidityBox()
    box.set_state(state)
    background, _ = style.validity_colours(state)
    assert state in box.text() and background in box.styleSheet()


def _names(table) -> list[str]:
    model = table.parameter_model
    return [model.data(model.index(row, NAME)) for row in range(model.rowCount())]


def test_parameter_table_reads_thiele_small_first_then_the_model_quantities(shown):
    table = shown.parameter_table
    names = _names(table)
    assert names[:5] == ["fs", "Qts", "Qes", "Qms", "Vas"]
    assert names[5:9] == ["Re", "Le", "Bl", "Mms"]
    assert "Sd" in names and "Sensitivity (2.83 V, 1 m)" in names      # the given Sd and the sensitivity
    section = next(row for row, name in enumerate(names) if "internal quantities" in name)
    assert {"CMES", "LCES", "RES", "L2", "R2", "lambda"} <= set(names[section + 1:])
    assert section > names.index("Sensitivity (2.83 V, 1 m)")
    # The section folds away and back with a click on its row.
    model = table.parameter_model
    qtbot_click_row = lambda: table.clicked.emit(model.index(section, NAME))      # noqa: E731
    qtbot_click_row()
    assert table.isRowHidden(model.row_of("CMES")) and not table.isRowHidden(model.row_of("fs"))
    qtbot_click_row()
    assert not table.isRowHidden(model.row_of("CMES"))


def test_parameter_units_are_written_properly(shown):
    table = shown.parameter_table
    expected = {"RE": "Ω", "LE": "mH", "Bl": "T·m", "Mms": "g", "Cms": "mm/N", "Vas": "l", "CMES": "µF",
                "SPL_2.83V_1m": "dB SPL", "Qts": ""}
    assert {name: _cell(table, name, UNIT) for name in expected} == expected


def test_values_show_at_most_four_digits_unless_all_digits_is_on(shown):
    table = shown.parameter_table

    def digits(text: str) -> int:
        return len(text.replace("-", "").replace(".", "").lstrip("0"))
    for name in ("RE", "fs", "Qts", "Bl", "Mms", "CMES"):
        assert digits(_cell(table, name, VALUE)) <= 4, name
    short = _cell(table, "RE", VALUE)
    table.all_digits_box.setChecked(True)
    full = _cell(table, "RE", VALUE)
    assert digits(full) > digits(short) and float(full) == pytest.approx(float(short), rel=1e-3)
    assert "±" in _cell(table, "RE", VALUE, Qt.ToolTipRole)       # every value explains itself


def test_parameter_columns_are_sized_to_their_contents_at_each_fill(shown):
    table = shown.parameter_table

    def fitted() -> bool:
        return all(table.columnWidth(column) >= table.sizeHintForColumn(column) > 0 for column in SIZED_COLUMNS)
    assert all(table.horizontalHeader().sectionResizeMode(c) == QHeaderView.Interactive for c in SIZED_COLUMNS)
    assert fitted(), [table.columnWidth(c) for c in range(len(COLUMNS))]
    table.all_digits_box.setChecked(True)
    assert fitted()
    narrow = table.columnWidth(UNIT)
    wide_unit = ParameterValue(name="RE", value=6.0, std=0.1, unit="ohm", display_unit="ohm (a unit far wider)",
                               display_scale=1.0, fitted=True)
    table.set_parameters({"RE": wide_unit})      # a new table: measured again
    assert fitted() and table.columnWidth(UNIT) > narrow


def test_residuals_beyond_the_strip_are_pinned_at_its_edge_and_counted(shown):
    """A misfit of thousands of sigma at the lowest lines (hidden physics) must not vanish off the strip."""
    import dataclasses

    from app.widgets.plots import EDGE, RESIDUAL_MAX_RANGE, beyond_range
    plot = shown.impedance_plot
    from app.results.curves import result_curves
    curves = result_curves(shown.result).impedance
    residual = np.array(curves.residual, dtype=complex)
    low = np.arange(5)                                    # the lowest lines, as hidden physics below 20 Hz
    residual[low] = 28_000.0 - 500j                       # far above: pinned at the top edge
    residual[-1] = -5e3j                                  # one far below: the imaginary part
    plot.set_curves(dataclasses.replace(curves, residual=residual), "Impedance")
    up_f, up_y = plot.residual_beyond_up.xData, plot.residual_beyond_up.yData        # as given, not log10
    down_f, down_y = plot.residual_beyond_down.xData, plot.residual_beyond_down.yData
    assert sorted(up_f) == sorted(curves.freqs[low]) and list(down_f) == [curves.freqs[-1]]
    low_edge, high_edge = plot.residual.viewRange()[1]
    assert high_edge == pytest.approx(RESIDUAL_MAX_RANGE) and np.allclose(up_y, EDGE * high_edge)
    assert np.allclose(down_y, EDGE * low_edge)              # inside the strip, where the eye finds them
    words = f"{low.size + 1} points beyond ±30σ"
    assert plot.beyond_text.startswith(words) and "2.8e+04σ" in plot.beyond_text
    assert words in plot.residual.titleLabel.text
    # Back to a good fit: no marker, no count.
    plot.set_curves(curves, "Impedance")
    assert plot.residual_beyond_up.getData()[0] is None or len(plot.residual_beyond_up.getData()[0]) == 0
    assert plot.beyond_text == ""
    assert beyond_range(curves.freqs, curves.residual, 1e9)[2] == ""


def _plotted(results) -> list:
    plots = (results.impedance_plot, results.displacement_plot)
    return [None if item.getData()[1] is None else item.getData()[1].tolist()
            for plot in plots for item in (plot.magnitude_measured, plot.magnitude_model, plot.residual_real)]


# Each open below waits for the model part too: nothing of the window's own reaches the page during the test.
def test_a_measurement_shown_in_turns_looks_as_one_shown_at_once(qtbot, window, recordings):
    from app.jobs.workers import AnalysisOutcome
    results = window.results
    open_and_wait(qtbot, window, recordings["paper"], "model_part_shown")
    paper = AnalysisOutcome(1, recordings["paper"], results.result, results.curves)
    at_once = _plotted(results)
    open_and_wait(qtbot, window, recordings["no_laser"], "model_part_shown")
    no_laser = _plotted(results)
    changed, done = [], []
    results.result_changed.connect(changed.append)
    results.show_outcome_in_turns(paper, lambda: done.append(True))
    assert _plotted(results) == no_laser and not done          # only the table in this turn: the plots later
    qtbot.waitUntil(lambda: bool(done), timeout=wait_ms(30))
    assert _plotted(results) == at_once
    assert changed == [paper.result] and results.result is paper.result


def test_a_newer_result_stops_one_shown_in_turns_and_what_waits_for_it_still_runs(qtbot, window, recordings):
    from app.jobs.workers import AnalysisOutcome
    results = window.results
    open_and_wait(qtbot, window, recordings["paper"], "model_part_shown")
    paper = AnalysisOutcome(1, recordings["paper"], results.result, results.curves)
    open_and_wait(qtbot, window, recordings["no_laser"], "model_part_shown")
    no_laser = AnalysisOutcome(2, recordings["no_laser"], results.result, results.curves)
    expected = _plotted(results)
    changed, done = [], []
    results.result_changed.connect(changed.append)
    results.show_outcome_in_turns(paper, lambda: done.append(True))
    results.show_outcome(no_laser)
    qtbot.waitUntil(lambda: bool(done), timeout=wait_ms(30))
    assert _plotted(results) == expected and results.result is no_laser.result
    assert changed == [no_laser.result]


def test_a_result_shown_behind_another_page_is_drawn_when_the_page_is_shown(qtbot, window, recordings):
    # A version the Model lab adopts while it is in front: announced at once, drawn once the Results page is shown.
    from app.jobs.workers import AnalysisOutcome
    results = window.results
    open_and_wait(qtbot, window, recordings["paper"], "model_part_shown")
    paper = AnalysisOutcome(1, recordings["paper"], results.result, results.curves)
    at_once, paper_re = _plotted(results), _cell(results.parameter_table, "RE", VALUE)
    open_and_wait(qtbot, window, recordings["no_laser"], "model_part_shown")
    no_laser, no_laser_re = _plotted(results), _cell(results.parameter_table, "RE", VALUE)
    assert no_laser != at_once
    window.pages.setCurrentWidget(window.model_lab)
    qtbot.waitUntil(lambda: not results.isVisible(), timeout=wait_ms(5))
    changed, done = [], []
    results.result_changed.connect(changed.append)
    results.show_outcome_in_turns(paper, lambda: done.append(True))
    qtbot.waitUntil(lambda: bool(done), timeout=wait_ms(30))
    assert changed == [paper.result] and results.result is paper.result
    assert _plotted(results) == no_laser and _cell(results.parameter_table, "RE", VALUE) == no_laser_re
    window.pages.setCurrentWidget(results)
    assert _plotted(results) == at_once and _cell(results.parameter_table, "RE", VALUE) == paper_re
    assert results.source_label.text().startswith(f"<b>{recordings['paper'].name}")


def test_a_step_that_fails_still_runs_what_waits_for_the_page(qtbot, window, recordings, monkeypatch):
    from app.jobs.workers import AnalysisOutcome
    results = window.results
    open_and_wait(qtbot, window, recordings["paper"], "model_part_shown")
    paper = AnalysisOutcome(1, recordings["paper"], results.result, results.curves)

    def broken(*args):
        raise RuntimeError("a plot failed")

    monkeypatch.setattr(results.impedance_plot, "set_curves", broken)
    done = []
    with qtbot.captureExceptions() as exceptions:
        results.show_outcome_in_turns(paper, lambda: done.append(True))
        qtbot.waitUntil(lambda: bool(done), timeout=wait_ms(30))
    assert done == [True]
    assert [str(e[1]) for e in exceptions] == ["a plot failed"]


def _table_of(qtbot, width: int, parameters: dict):
    from app.results.parameter_table import ParameterTable
    table = ParameterTable()
    qtbot.addWidget(table)
    table.set_parameters(parameters)
    table.resize(width, 400)
    table.show()
    qtbot.waitExposed(table)
    return table


def _mixed_parameters() -> dict:
    return {
        "Qts": ParameterValue(name="Qts", value=0.463812, std=1.3e-6, unit="1", display_unit="1", display_scale=1.0),
        "Cms": ParameterValue(name="Cms", value=4.2963e-4, std=1.9e-9, unit="m/N", display_unit="mm/N",
                              display_scale=1e3),
        "Vas": ParameterValue(name="Vas", value=None, std=None, unit="m^3", display_unit="l", display_scale=1e3,
                              reason="no Sd: enter the diaphragm's area to derive Vas"),
        "L2": ParameterValue(name="L2", value=1.23e-4, std=2e-7, unit="H", display_unit="mH", display_scale=1e3,
                             fitted=True),
        "SPL_1W_1m": ParameterValue(name="SPL_1W_1m", value=90.03, std=1.6e-5, unit="dB", display_unit="dB SPL",
                                    display_scale=1.0),
    }


def _spanned_width(table) -> int:
    return table.columnWidth(VALUE) + table.columnWidth(STD)


def test_a_narrow_table_shows_every_value_whole_and_elides_the_names(qtbot):
    """At 1280x720 the Model lab's table is ~350 px wide: the values used to give way ("0.46…" for Qts) to a
    name column as wide as its longest name. Now the names give way; a spanned cell (the section title, the
    reason of a missing value) widens no column."""
    table = _table_of(qtbot, 300, _mixed_parameters())
    model = table.parameter_model
    alone = [model.row_of(name) for name in ("Qts", "Cms", "L2")]      # not Vas's reason, not the section
    for column in (VALUE, STD, UNIT):
        widest = max(table.sizeHintForIndex(model.index(row, column)).width() for row in alone)
        assert table.columnWidth(column) >= widest, column
    metrics = table.fontMetrics()
    for name in ("Qts", "Cms"):
        text = _cell(table, name, VALUE)
        assert len(text) >= 6 and metrics.horizontalAdvance(text) < table.columnWidth(VALUE), (name, text)
    longest_name = metrics.horizontalAdvance(_cell(table, "SPL_1W_1m", NAME))
    assert table.columnWidth(NAME) < longest_name      # the names give way
    assert sum(table.columnWidth(c) for c in range(len(COLUMNS))) <= table.viewport().width() + 1


def test_a_wide_table_gives_names_and_reasons_their_room(qtbot):
    """With room to spare the names are whole and a missing value's reason, spanned over the value and the
    sigma, has the rest of the width (it elided to "n/a: no Sd: ent…" when the names took the rest)."""
    table = _table_of(qtbot, 700, _mixed_parameters())
    metrics = table.fontMetrics()
    assert table.columnWidth(NAME) >= metrics.horizontalAdvance(_cell(table, "SPL_1W_1m", NAME))
    assert _spanned_width(table) > metrics.horizontalAdvance(_cell(table, "Vas", VALUE)) + 8
    table.resize(300, 400)                             # narrowed: the names give way again
    qtbot.waitUntil(lambda: table.columnWidth(NAME) < metrics.horizontalAdvance(_cell(table, "SPL_1W_1m", NAME)))
    assert metrics.horizontalAdvance(_cell(table, "Qts", VALUE)) < table.columnWidth(VALUE)


def test_a_broken_lead_s_not_measured_cells_are_whole(qtbot):
    unmeasured = {name: ParameterValue(name=name, value=None, std=None, unit="1", display_unit="1",
                                       display_scale=1.0, reason="the current lead is broken")
                  for name in ("fs", "Qts", "RE", "Bl")}
    table = _table_of(qtbot, 500, unmeasured)
    text = _cell(table, "Qts", VALUE)
    assert text == "not measured"
    assert _spanned_width(table) > table.fontMetrics().horizontalAdvance(text) + 8


def test_new_numbers_for_the_same_parameters_show_as_a_new_table_would(qtbot):
    # A refit of the same model, its model part arrived, Sd edited: the same rows with other numbers.
    import dataclasses
    from app.results.parameter_table import ParameterTable
    table = _table_of(qtbot, 300, _mixed_parameters())
    bolder = {name: p if p.value is None else dataclasses.replace(p, value=p.value * 1234.5678, std=p.std * 3.3)
              for name, p in _mixed_parameters().items()}
    table.set_parameters(bolder)
    fresh = ParameterTable()
    qtbot.addWidget(fresh)
    fresh.set_parameters(bolder)
    model, expected = table.parameter_model, fresh.parameter_model
    assert model.rowCount() == expected.rowCount()
    for row in range(model.rowCount()):
        for column in range(len(COLUMNS)):
            for role in (Qt.DisplayRole, Qt.ToolTipRole, Qt.FontRole, Qt.ForegroundRole, Qt.TextAlignmentRole):
                assert model.index(row, column).data(role) == expected.index(row, column).data(role), (row, column)
    assert _cell(table, "Qts", VALUE) != _cell(_table_of(qtbot, 300, _mixed_parameters()), "Qts", VALUE)
    alone = [model.row_of(name) for name in ("Qts", "Cms", "L2")]
    for column in (VALUE, STD):         # the wider numbers fit their columns
        widest = max(table.sizeHintForIndex(model.index(row, column)).width() for row in alone)
        assert table.columnWidth(column) >= widest, column


def test_a_table_of_other_parameters_replaces_the_rows(qtbot):
    table = _table_of(qtbot, 500, _mixed_parameters())
    fewer = {name: p for name, p in _mixed_parameters().items() if name != "L2"}
    table.set_parameters(fewer)
    assert _names(table) == [_cell_name for _cell_name in _names(_table_of(qtbot, 500, fewer))]
    assert "L2" not in " ".join(_names(table))


def test_imported_curves_whose_numbers_are_no_drivers_say_what_was_found_and_the_remedy_on_the_page(qtbot):
    """The page said "Validity: red — imported curves: ... no validity checks" and nothing of why."""
    import dataclasses

    from analysis.curves.fitting import fit_curves
    from analysis.validity.fit import INVALID, qa_blocker
    from app.results.view import ValidityBox, imported_meaning
    from tests.analysis.curves.test_fitting import curve
    from tests.builders import DRIVERS
    z, hx = (curve(DRIVERS["paper"], name, noise=0.003, seed=seed) for seed, name in enumerate(("impedance",
                                                                                                "displacement")))
    in_mm = fit_curves(z, dataclasses.replace(hx, value=hx.value * 1e3), sd_m2=0.0133).validity
    box = ValidityBox()
    qtbot.addWidget(box)
    box.set_state(str(in_mm.overall), imported_meaning(in_mm))
    assert "Validity: red" in box.text() and "--mm-per-volt" in box.text() and "no validity checks" not in box.text()
    verdict, why = qa_blocker(in_mm)
    assert verdict == INVALID and why.startswith("the curves as read are no driver's") and "measure" not in why
    right = fit_curves(z, hx, sd_m2=0.0133).validity
    assert imported_meaning(right) == right.imported.note and "no validity checks" in right.imported.note
