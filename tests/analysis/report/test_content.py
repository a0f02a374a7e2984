"""What a report says (analysis.report.content) of imported curves: what was fitted, how each line was weighted,
who calibrated them, and the bands in plain Hz."""
import dataclasses

import pytest

from analysis.archive.results import StoredResult
from analysis.curves.fitting import fit_curves
from analysis.curves.stored import curve_header, curve_results_document
from analysis.importers import read_curve
from analysis.report import build_report
from tests.lpm_exports import write_exports


@pytest.fixture(scope="module")
def impedance_only(tmp_path_factory):
    """An impedance curve from 2 Hz to 20 kHz read as File > Open curves reads it, and its report."""
    z_path, _ = write_exports(tmp_path_factory.mktemp("lpm"), "midwoofer")
    result = dataclasses.replace(fit_curves(read_curve(z_path, "impedance").transfer), files=(z_path,))
    return build_report(StoredResult.from_json(curve_results_document(result)), curve_header(result))


def test_an_imported_impedance_is_described_as_what_was_fitted_and_who_calibrated_it(impedance_only):
    """The report said "Z and Hx fitted together, each line weighted by its noise" of a curve with no Hx whose
    noise was estimated, and "not recorded with this measurement" of a third party's calibration."""
    fit = dict(impedance_only.fit)
    assert fit["Method"] == "joint: Z fitted alone, each line weighted by the noise estimated from its curve's scatter"
    (key, words), = impedance_only.calibration
    assert key == "Calibration" and "imported" in words and "calibrated by whoever measured them" in words


def test_an_imported_band_reads_in_plain_hz(impedance_only):
    assert dict(impedance_only.settings)["Impedance fitted"] == "2 – 20000 Hz"       # was "2 – 2e+04 Hz"


def test_a_recordings_method_and_calibration_are_as_before(stored):
    c = build_report(stored, {}, None, {"volts_per_fs": 1.5})
    assert dict(c.fit)["Method"] == "joint: Z and Hx fitted together, each line weighted by its noise"
    assert ("Inputs", "1.5 V at full scale") in c.calibration
    assert dict(build_report(stored, {}).calibration)["Calibration"] == "not recorded with this measurement"


def test_the_html_appendix_has_no_calibration_section_when_none_was_recorded(impedance_only, stored):
    """It said "Calibration as recorded: not recorded" of imported curves whose first page says who calibrated
    them; the PDF leaves the section out, as the HTML now does."""
    from analysis.report import render_html
    html = render_html(impedance_only)
    assert "Calibration as recorded" not in html and "calibrated by whoever measured them" in html
    with_keys = build_report(stored, {}, None, {"volts_per_fs": 1.5})
    assert "Calibration as recorded" in render_html(with_keys)
