"""Reports: content, a self-contained HTML page, and a PDF whose pages (rendered by pdftoppm) are not clipped."""
import json
import re
import shutil
import subprocess

import numpy as np
import pytest

from analysis.archive import Archive
from analysis.archive.results import StoredResult, results_document
from analysis.pipeline import analyze_recording
from analysis.recording.format import write_recording
from analysis.report import build_report, render_html, report_for_measurement, report_for_recording, write_report
from instruments.simulation import faults
from tests.builders import TYPICAL_NOISE, needs_pdftotext, pdf_text, recording

HEADER = {"driver": "Acme <W6> & co", "serial": "SN-42", "measured_at": "2024-05-01T10:00:00Z",
          "operator": "Ana", "station": "QA-1"}


@pytest.fixture(scope="module")
def stored():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    return StoredResult.from_json(results_document(analyze_recording(rec), rec))


@pytest.fixture(scope="module")
def faulty():
    rec = faults.laser_errors()
    return StoredResult.from_json(results_document(analyze_recording(rec), rec))


def test_content_has_header_lights_parameters_in_customary_units_and_fit_quality(stored):
    c = build_report(stored, HEADER, None, {"volts_per_fs": 1.5})
    assert dict(c.header)["Serial number"] == "SN-42" and dict(c.header)["Station"] == "QA-1"
    assert c.overall == "green" and [lt.channel for lt in c.lights] == ["voltage", "current", "displacement"]
    rows = {p.name: p for p in c.parameters}
    assert rows["Mms"].unit == "g" and float(rows["Mms"].value) == pytest.approx(11.87, rel=0.01)
    assert rows["Le"].unit == "mH" and rows["Cms"].unit == "mm/N" and rows["Vas"].unit == "l"
    assert rows["Bl"].std not in ("", "–")
    fit = dict(c.fit)                   # the appendix: effects by id, the fit's statistics
    assert "lr2" in fit["Effects"] and "creep-log" in fit["Effects"]
    assert fit["Method"].startswith("joint: Z and Hx fitted together")
    assert {"Reduced χ² (impedance)", "Reduced χ² (displacement)", "AIC", "BIC"} <= set(fit)
    assert ("Inputs", "1.5 V at full scale") in c.calibration and ("volts_per_fs", "1.5") in c.calibration_detail
    assert dict(c.settings)["Sample rate"] == "48000 Hz"
    assert c.has_spl


def test_findings_carry_message_and_remedy(faulty):
    c = build_report(faulty, HEADER)
    assert c.overall == "red"
    (finding,) = [f for lt in c.lights for f in lt.findings]
    assert finding.code == "laser-errors" and finding.message and finding.remedy


def test_html_is_self_contained_and_escapes_user_text(stored, faulty):
    page = render_html(build_report(faulty, HEADER))
    assert "Acme &lt;W6&gt; &amp; co" in page and "<W6>" not in page
    assert page.count("<svg") == 4                              # Z, Hx, SPL, residuals
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//|file:)""", page)
    assert "<script" not in page
    assert "Remedy:" in page and "laser-errors" in page


def test_without_displacement_there_is_no_hx_or_spl_and_a_note_says_why():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=10, displacement=False)
    s = StoredResult.from_json(results_document(analyze_recording(rec), rec))
    c = build_report(s, {})
    assert not c.has_spl and any("No displacement" in n for n in c.notes)
    page = render_html(c)
    assert page.count("<svg") == 2


needs_pdftoppm = pytest.mark.skipif(shutil.which("pdftoppm") is None,
                                    reason="pdftoppm is missing: install poppler-utils (tools/system-packages.sh)")


def _pages(pdf, tmp_path):
    from PIL import Image
    subprocess.run(["pdftoppm", "-r", "40", "-png", str(pdf), str(tmp_path / "page")], check=True)
    return [np.asarray(Image.open(p).convert("L")) for p in sorted(tmp_path.glob("page-*.png"))]


@needs_pdftoppm
def test_pdf_pages_have_ink_inside_the_margins_only(stored, faulty, tmp_path):
    for name, s, limits in (("ok", stored, None), ("faulty", faulty, None), ("limits", stored, FAILING)):
        pdf = tmp_path / f"{name}.pdf"
        write_report(build_report(s, HEADER, limits=limits and limits_file(tmp_path, **limits)), pdf=pdf)
        (tmp_path / name).mkdir()
        pages = _pages(pdf, tmp_path / name)
        assert len(pages) >= 2
        for img in pages:
            h, w = img.shape
            edge = int(0.3 * 40)        # 0.3 inch: the margins are wider, so ink there means clipping
            border = np.concatenate([img[:edge].ravel(), img[-edge:].ravel(), img[:, :edge].ravel(),
                                     img[:, -edge:].ravel()])
            assert border.min() > 240, f"{name}: ink in the page border (clipped?)"
            assert (img < 128).mean() > 2e-4                        # no blank page
        # Every page is more than a few lines that ran over (the appendix starts a page of its own).
        for img in pages:
            rows_with_ink = (img < 160).any(axis=1).mean()
            assert rows_with_ink > 0.3, f"{name}: a page of a few lines"


def test_report_of_an_archived_measurement_equals_the_fresh_one(tmp_path):
    path = tmp_path / "rec"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=3, seed=11))
    archive = Archive(tmp_path / "archive")
    from analysis.pipeline import analyze_path
    mid = archive.store(path, analyze_path(path), {"serial": "S"})
    archived = report_for_measurement(archive.get(mid))
    fresh = report_for_recording(path)
    assert archived.parameters == fresh.parameters and archived.model == fresh.model
    assert dict(archived.header)["Serial number"] == "S"
    assert dict(archived.header)["Measurement id"] == mid


# --- QA limits -------------------------------------------------------------------------------------------

def limits_file(tmp_path, name="limits.json", **parameters):
    from analysis.limits import load_limits
    path = tmp_path / name
    path.write_text(json.dumps({"format": "linpar-limits/1", "name": "paper QA", "parameters": parameters}))
    return load_limits(path)


PASSING = dict(RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"}, fs={"min": 65, "max": 75, "unit": "Hz"},
               Bl={"min": 5.0, "unit": "T*m"})
FAILING = dict(RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
               fs={"nominal": 50, "tolerance": "2%", "unit": "Hz"},
               Mms={"max": 11, "unit": "g"}, Bl={"min": 5.5, "unit": "T*m"})


def test_passing_limits_give_pass_with_margins_in_the_files_units(stored, tmp_path):
    c = build_report(stored, HEADER, limits=limits_file(tmp_path, "ok.json", **PASSING))
    assert c.qa.verdict == "pass" and c.qa.headline == "PASS" and c.qa.file == "ok.json"
    rows = {r.name: r for r in c.qa.rows}
    assert list(rows) == ["Re", "fs", "Bl"]                           # the pages' names, not RE
    assert [r.outcome for r in c.qa.rows] == ["pass"] * 3
    # fs = 70.56 Hz against 65..75 Hz: 4.44 Hz inside the max, 11 % of the half-width used.
    assert rows["fs"].margin == "inside by 4.44 Hz" and rows["fs"].used == "11 %"
    assert rows["fs"].value == "70.56 Hz"                             # 4 significant digits, as the pages
    assert rows["Bl"].used == ""                                     # one-sided: no share of a tolerance


def test_failing_limits_say_which_and_by_how_much(stored, tmp_path):
    c = build_report(stored, HEADER, limits=limits_file(tmp_path, **FAILING))
    assert c.qa.verdict == "fail" and "3 of 4" in c.qa.why
    assert "fs 19.6 Hz above max, Mms 0.844 g above max, Bl 0.27 T·m below min" in c.qa.why    # with the margins
    rows = {r.name: r for r in c.qa.rows}
    assert rows["Re"].outcome == "pass" and rows["fs"].outcome == "FAIL" and rows["Mms"].outcome == "FAIL"
    assert rows["fs"].margin == "19.6 Hz above max"    # 70.56 Hz against 50 Hz ± 1 Hz
    assert rows["fs"].used == "2056 %"
    assert rows["Mms"].margin == "0.844 g above max"   # 11.84 g against <= 11 g
    assert rows["Bl"].margin == "0.27 T·m below min"   # 5.23 T*m against >= 5.5 T*m


def test_a_red_measurement_fails_unjudged_and_a_missing_parameter_fails(stored, faulty, tmp_path):
    c = build_report(faulty, HEADER, limits=limits_file(tmp_path, **PASSING))
    # INVALID, its own verdict: the measurement is broken, no parameter is judged, and the why says so.
    assert c.qa.verdict == "invalid" and c.qa.headline == "INVALID: measure again"
    assert {r.outcome for r in c.qa.rows} == {"not judged"}
    assert c.qa.why.startswith("measurement invalid: ") and "the unit itself was not judged" in c.qa.why
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=10, displacement=False)
    no_laser = StoredResult.from_json(results_document(analyze_recording(rec), rec))
    c = build_report(no_laser, HEADER, limits=limits_file(tmp_path, **PASSING))
    bl = {r.name: r for r in c.qa.rows}["Bl"]
    assert c.qa.verdict == "fail" and bl.outcome == "FAIL" and bl.value == "n/a" and "not measured" in bl.note


def test_html_carries_the_verdict_banner_and_table_only_with_limits(stored, tmp_path):
    ok = render_html(build_report(stored, HEADER, limits=limits_file(tmp_path, "ok.json", **PASSING)))
    bad = render_html(build_report(stored, HEADER, limits=limits_file(tmp_path, "bad.json", **FAILING)))
    none = render_html(build_report(stored, HEADER))
    assert "id='qa-verdict'" in ok and "QA: PASS" in ok and "QA: FAIL" not in ok and "ok.json" in ok
    assert "QA: FAIL" in bad and "QA: PASS" not in bad and "19.6 Hz above max" in bad
    assert bad.index("QA: FAIL") < bad.index("<h2>Validity")              # in the header area
    assert "<h2>QA limits</h2>" in bad and bad.count("class='fail'>FAIL<") == 3
    assert "QA:" not in none and "QA limits" not in none and "qa-verdict" not in none


def _significant_digits(number: str) -> int:
    return len(number.replace("-", "").replace(".", "").lstrip("0"))


EXAMPLE_LIMITS = "resources/limits/example.json"


@needs_pdftotext
def test_the_qa_table_rounds_values_and_margins_as_the_pages_do(stored, tmp_path):
    """The QA table printed "3.0199964 Ω": every digit a noise-only sigma allows. It reads the value as the QA
    and Results pages show it (at most 4 significant digits, fewer when the sigma supports fewer), the margin
    in 3 significant digits without an exponent, under the pages' names."""
    from analysis.limits import load_limits
    from analysis.parameter_names import display_name
    limits = load_limits(EXAMPLE_LIMITS)
    c = build_report(stored, HEADER, limits=limits)
    by_limit = {display_name(lim.name): lim for lim in limits.limits}
    assert [r.name for r in c.qa.rows] == list(by_limit) and "Re" in by_limit
    for row in c.qa.rows:
        number, *unit = row.value.split(" ")
        p = stored.parameters[by_limit[row.name].name]
        true = p.value / by_limit[row.name].to_si
        decimals = len(number.split(".")[1]) if "." in number else 0
        assert _significant_digits(number) <= 4, row
        assert abs(float(number) - true) <= 0.5 * 10.0 ** -decimals + 1e-12, (row, true)   # rounded, not cut
        margin = re.search(r"[\d.]+(e[-+]?\d+)?", row.margin).group(0)
        assert "e" not in margin and _significant_digits(margin) <= 3, row
    pdf = tmp_path / "qa.pdf"
    write_report(c, pdf=pdf)
    table = pdf_text(pdf).split("QA limits")[1].split("Parameters")[0]
    assert re.search(r"^\s*Re\s+pass\s+3\.0\d{0,2} Ω", table, re.M), table
    assert not re.search(r"\d\.\d{5,}", table), table         # no 7-digit value left in the table


_pdf_text = pdf_text


@needs_pdftotext
def test_pdf_carries_the_verdict_on_its_first_page(stored, tmp_path):
    for name, limits, verdict, other in (("ok", PASSING, "QA: PASS", "QA: FAIL"),
                                         ("bad", FAILING, "QA: FAIL", "QA: PASS")):
        pdf = tmp_path / f"{name}.pdf"
        write_report(build_report(stored, HEADER, limits=limits_file(tmp_path, f"{name}.json", **limits)), pdf=pdf)
        first_page = _pdf_text(pdf).split("\f")[0]
        assert verdict in first_page and other not in first_page and f"{name}.json" in first_page
        assert "QA limits" in first_page
    assert re.search(r"fs\s+FAIL\s+70\.5\d+ Hz", first_page) and "19.6 Hz above max" in first_page
    plain = tmp_path / "none.pdf"
    write_report(build_report(stored, HEADER), pdf=plain)
    text = _pdf_text(plain)
    assert "QA:" not in text and "QA limits" not in text


# --- the customer's pages -----------------------------------------------------------------------------------

WIZARD_CALIBRATION = {"calibration": {"sound_card": {"volts_per_fs_out": 10.0, "volts_per_fs_voltage_sense": 12.5,
                                                     "volts_per_fs_current_sense": 1.0, "shunt_ohm": 0.1,
                                                     "current_amp_gain": 5.0},
                                      "laser": {"volts_per_fs_laser": 10.0, "laser_m_per_volt": 0.002}}}


def test_customer_rows_use_the_workstations_names_order_and_sd():
    from analysis.parameter_names import THIELE_SMALL, display_name
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    result = StoredResult.from_json(results_document(analyze_recording(rec), rec))
    c = build_report(result, {**HEADER, "source": "/tmp/tmpx81k2/session-7/woofer-12.wav"}, None,
                     WIZARD_CALIBRATION)
    names = [p.name for p in c.parameters]
    wanted = [display_name(n) for n in THIELE_SMALL if n in result.parameters or n == "Sd"]
    assert names == wanted and names[:5] == ["fs", "Qts", "Qes", "Qms", "Vas"]
    assert "Sensitivity (1 W into Re, 1 m)" in names and "RE" not in names and "CMES" not in names
    sd = next(p for p in c.parameters if p.name == "Sd")
    assert sd.value == f"{result.sd_m2 * 1e4:.6g}" and sd.unit == "cm²"
    assert "CMES" in {p.name for p in c.internal}            # the model's own quantities: the appendix
    # Values rounded to their sigma: as many decimals as the sigma's second significant digit, no exponent.
    for p in c.parameters:
        if p.std not in ("", "–"):
            assert "e" not in p.std.lower() and "e" not in p.value.lower()
            decimals = len(p.std.split(".")[1]) if "." in p.std else 0
            assert (len(p.value.split(".")[1]) if "." in p.value else 0) == decimals, (p.name, p.value, p.std)
    assert dict(c.header)["Source"] == "woofer-12.wav"
    model = dict(c.model)["Model"]
    assert "physics.md" not in model and "LR-2" in model and "lr2" not in model
    calibration = dict(c.calibration)
    assert calibration["Current input"].startswith("2 A at full scale")     # 1 V / (0.1 ohm * 5)
    assert calibration["Laser input"].startswith("20 mm at full scale")     # 10 V * 2 mm/V
    assert calibration["Output to the driver"] == "10 V at full scale"


@needs_pdftotext
def test_pdf_reads_as_a_customer_document_with_an_appendix(tmp_path):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    result = StoredResult.from_json(results_document(analyze_recording(rec), rec))
    pdf = tmp_path / "r.pdf"
    write_report(build_report(result, {**HEADER, "source": str(tmp_path / "woofer-12.wav")}, None,
                              WIZARD_CALIBRATION), pdf=pdf)
    text = pdf_text(pdf)
    customer, appendix = text.split("Appendix: engineering detail")
    assert re.search(r"^\s*Sd\s+\d+", customer, re.M) and re.search(r"^\s*Re\s+3\.0", customer, re.M)
    assert customer.index(" fs ") < customer.index(" Qts ") < customer.index(" Vas ") < customer.index(" Bl ")
    assert "physics.md" not in text and str(tmp_path) not in text and "woofer-12.wav" in customer
    assert "volts_per_fs" not in customer and re.search(r"Current input\s+2 A at full scale", customer)
    assert "CMES" in appendix and "Correlations" in appendix and "volts_per_fs_current_sense" in appendix
    assert "CMES" not in customer


def test_pdf_export_is_quiet(caplog, stored, tmp_path):
    import logging
    with caplog.at_level(logging.INFO):
        write_report(build_report(stored, HEADER), pdf=tmp_path / "q.pdf")
    assert [r for r in caplog.records if r.name.startswith(("fontTools", "matplotlib"))] == []


def test_customer_numbers_never_read_as_pythons_exponent():
    """A wizard measurement with a misfit printed "1e+02 %" (Le's relative sigma), a fit error of "1.2e+02 %" and
    a reduced χ² of "2.75e+08" on the customer's page."""
    from analysis.derived import ParameterValue
    from analysis.report.content import _chi2_text
    from analysis.report.numbers import parameter_cells, readable_number
    le = ParameterValue(name="LE", value=0.11e-3, std=0.11e-3, unit="H", display_unit="mH", display_scale=1e3)
    assert parameter_cells(le)[3] == "100 %"
    assert readable_number(123.0) == "120" and readable_number(0.0025) == "0.0025"
    assert readable_number(2.75e8, 3) == "2.75 × 10⁸" and readable_number(4.2e-6) == "4.2 × 10⁻⁶"
    assert _chi2_text({"chi2_red": {"impedance": 2.75e8, "displacement": 1.14}}) == \
        "2.75 × 10⁸ (impedance), 1.14 (displacement)"


def _words(pdf) -> list[tuple[str, float, float, float]]:
    """(word, xMin, xMax, (page, yMin)) of every word pdftotext finds, in points."""
    html = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], check=True, capture_output=True, text=True).stdout
    word = r'<word xMin="([\d.]+)" yMin="([\d.]+)" xMax="([\d.]+)" yMax="[\d.]+">([^<]*)</word>'
    return [(w, float(x0), float(x1), (page, float(y0))) for page, text in enumerate(html.split("<page")[1:])
            for x0, y0, x1, w in re.findall(word, text)]


@needs_pdftotext
def test_the_appendix_never_prints_a_key_over_its_value(tmp_path):
    """The appendix's 'Calibration as recorded' printed calibration.sound_card.volts_per_fs_current_sense over its
    own value in a 2-inch key column: a long key's column is widened, or the key takes a line of its own."""
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    result = StoredResult.from_json(results_document(analyze_recording(rec), rec))
    calibration = {"calibration": {**WIZARD_CALIBRATION["calibration"],
                                   "a_much_longer_key_than_any_column_can_hold_beside_its_value_x": 7.0}}
    pdf = tmp_path / "r.pdf"
    write_report(build_report(result, HEADER, None, calibration), pdf=pdf)
    words = _words(pdf)
    keys = [w for w in words if w[0].startswith("calibration.")]
    assert len(keys) >= 8
    for key, x0, x1, y in keys:
        beside = [w for w in words if w[3][0] == y[0] and abs(w[3][1] - y[1]) < 2 and x0 < w[1] < x1 and w[0] != key]
        assert not beside, (key, beside)
