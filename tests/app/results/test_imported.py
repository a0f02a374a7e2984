"""Imported curves on the Results page (File > Open curves…): a Klippel LPM export of a realistic driver
(tests/lpm_exports.py) shown with linpar's fit and the export's own fitted curve, and the report of it."""
from __future__ import annotations

import html
from pathlib import Path

import pytest

from app.jobs.curves import CurvesRequest
from app.results.imported import REFERENCE_NAME
from app.results.parameter_table import STD, VALUE
from tests.app.conftest import analysis_wait_ms
from tests.lpm_exports import DRIVERS, truth, write_exports
from tests.lpm_files import write_lpm


def _points(item) -> int:
    x, _ = item.getData()
    return 0 if x is None else len(x)


def _legend_names(plot) -> list[str]:
    return [label.text for _, label in plot.magnitude.legend.items]


def _cell(table, name: str, column: int):
    model = table.parameter_model
    return model.data(model.index(model.row_of(name), column))


def _open(qtbot, window, request: CurvesRequest, signal: str = "model_part_shown"):
    """Open `request` and wait for `signal` (by default the model part's end: no job left behind the test)."""
    with qtbot.waitSignal(getattr(window, signal), timeout=analysis_wait_ms(4)) as blocker:
        window.open_curves(request)
    return blocker.args


@pytest.fixture(scope="module")
def midwoofer(tmp_path_factory) -> tuple[Path, Path]:
    return write_exports(tmp_path_factory.mktemp("lpm"), "midwoofer")


def test_an_lpm_export_shows_three_traces_the_parameters_and_the_comparison(qtbot, window, midwoofer, dialogs,
                                                                            tmp_path):
    z, hx = midwoofer
    outcome, = _open(qtbot, window, CurvesRequest(z, hx))
    view = window.results
    assert view.result is outcome.result and not dialogs
    for plot in (view.impedance_plot, view.displacement_plot):
        assert _points(plot.magnitude_measured) > 50 and _points(plot.magnitude_model) > 50
        assert plot.magnitude_reference is not None and _points(plot.magnitude_reference) > 50
        assert REFERENCE_NAME in _legend_names(plot)
        assert _points(plot.phase_measured) == 0          # magnitude only: no measured phase to draw
    # The parameters the export's driver has, with a noise and a model part.
    expected = truth(DRIVERS["midwoofer"])
    for name, scale in (("RE", 1.0), ("Bl", 1.0), ("Mms", 1e3)):
        assert float(_cell(view.parameter_table, name, VALUE)) == pytest.approx(expected[name] * scale, rel=0.05)
        assert float(_cell(view.parameter_table, name, STD)) > 0
    mms = view.result.parameters["Mms"]
    assert mms.std_noise is not None and mms.std_model is not None and mms.std_model > 0
    # The fit error per channel, and how far the two fits are apart (the CLI's numbers).
    assert "Fit error" in view.fit_quality.text() and "displacement" in view.fit_quality.text()
    source = html.unescape(view.source_label.text())
    assert "midwoofer_Z.txt" in source and "midwoofer_HX.txt" in source
    for channel in ("impedance", "displacement"):
        assert f"The export's own fit of {channel}" in source and "rms from linpar's fitted curve" in source
    assert "no validity checks" in view.validity_box.text()     # imported curves: nothing was checked
    assert window.settings.recent_files() == []           # Open recent is for recordings
    # The report of it carries the export's fit beside linpar's.
    report = tmp_path / "midwoofer-report.html"
    with qtbot.waitSignal(window.qa.report_written, timeout=analysis_wait_ms()):
        window.qa.export_to(report)
    text = html.unescape(report.read_text(encoding="utf-8"))
    assert "The export's fit (impedance)" in text
    assert "midwoofer_Z.txt + midwoofer_HX.txt" in text
    # File > Export data… of it: the parameters, not an attempt to read Z.txt as a recording.
    assert window.menus.export_data_to(tmp_path / "midwoofer.csv") and not dialogs
    assert "Mms" in (tmp_path / "midwoofer.csv").read_text(encoding="utf-8")


def test_a_bad_export_is_one_line_and_the_result_shown_stays(qtbot, window, midwoofer, dialogs, tmp_path):
    z, hx = midwoofer
    _open(qtbot, window, CurvesRequest(z, hx))
    shown = window.results.result
    bad = tmp_path / "bad_Z.txt"
    lines = z.read_text(encoding="latin-1").splitlines()
    fields = lines[10].split("\t")
    lines[10] = "\t".join([fields[0], "five", *fields[2:]])        # text where a number belongs
    bad.write_text("\r\n".join(lines), encoding="latin-1")
    message, = _open(qtbot, window, CurvesRequest(bad, hx), "analysis_failed")
    assert len(dialogs) == 1
    kind, title, text = dialogs[0]
    assert kind == "warning" and "bad_Z.txt" in title
    assert text == message and "bad_Z.txt" in text and "line" in text
    assert "Traceback" not in text and "\n" not in text
    assert window.results.result is shown and not window.busy      # nothing else lost


def test_an_export_without_its_fitted_column_shows_two_traces(qtbot, window, tmp_path):
    from tests.lpm_exports import lpm_frequencies, measured
    freqs = lpm_frequencies()
    z, hx = measured(DRIVERS["midwoofer"], freqs)
    z_path = write_lpm(tmp_path / "Z.txt", "impedance", z, freqs=freqs)
    hx_path = write_lpm(tmp_path / "HX.txt", "displacement", hx, freqs=freqs)
    _open(qtbot, window, CurvesRequest(z_path, hx_path))
    for plot in (window.results.impedance_plot, window.results.displacement_plot):
        assert plot.magnitude_reference is None and REFERENCE_NAME not in _legend_names(plot)
    assert "export's own fit" not in html.unescape(window.results.source_label.text())
