"""Reports: content, a self-contained HTML page, and a PDF whose pages (rendered by pdftoppm) are not clipped."""
import re
import shutil
import subprocess

import numpy as np
import pytest

from analysis.archive import Archive
from analysis.archive.results import StoredResult, results_document
from analysis.pipeline import analyze_recording
from analysis.recording import write_recording
from analysis.report import build_report, render_html, report_for_measurement, report_for_recording, write_report
from instruments.simulation import faults
from tests.builders import TYPICAL_NOISE, recording

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
    assert rows["LE"].unit == "mH" and rows["Cms"].unit == "mm/N" and rows["Vas"].unit == "l"
    assert rows["Bl"].std not in ("", "–")
    model = dict(c.model)
    assert "lr2" in model["Effects"] and "creep-log" in model["Effects"]
    assert {"Reduced χ² (impedance)", "Reduced χ² (displacement)", "AIC", "BIC"} <= set(model)
    assert ("volts_per_fs", "1.5") in c.calibration
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
    for name, s in (("ok", stored), ("faulty", faulty)):
        pdf = tmp_path / f"{name}.pdf"
        write_report(build_report(s, HEADER), pdf=pdf)
        (tmp_path / name).mkdir()
        pages = _pages(pdf, tmp_path / name)
        assert len(pages) >= 3
        for img in pages:
            h, w = img.shape
            edge = int(0.3 * 40)        # 0.3 inch: the margins are wider, so ink there means clipping
            border = np.concatenate([img[:edge].ravel(), img[-edge:].ravel(), img[:, :edge].ravel(),
                                     img[:, -edge:].ravel()])
            assert border.min() > 240, f"{name}: ink in the page border (clipped?)"
            assert (img < 128).mean() > 2e-4                        # no blank page
        # The plot pages: axes and data lines (dark pixels spread over most of the page height).
        for img in pages[-2:]:
            rows_with_ink = (img < 160).any(axis=1).mean()
            assert rows_with_ink > 0.5


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
