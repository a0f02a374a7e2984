"""Imported curves' results document (analysis.curves.stored): the report of a Klippel LPM export overlays the
export's own fitted curve and says how far it lies from linpar's."""
from __future__ import annotations

import dataclasses
import html

import numpy as np
import pytest

from analysis.archive.results import StoredResult
from analysis.curves.fitting import fit_curves
from analysis.curves.stored import curve_header, curve_results_document
from analysis.importers import read_curve
from analysis.report import build_report, render_html, render_pdf
from analysis.report.plots import REFERENCE, figures
from tests.lpm_exports import lpm_fitted, write_exports


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    z_path, hx_path = write_exports(tmp_path_factory.mktemp("lpm"), "midwoofer")
    z, hx = read_curve(z_path, "impedance"), read_curve(hx_path, "displacement")
    result = dataclasses.replace(fit_curves(z.transfer, hx.transfer), files=(z_path, hx_path),
                                 references={"impedance": z.reference, "displacement": hx.reference})
    doc = curve_results_document(result)
    return StoredResult.from_json(doc), curve_header(result), result


def test_the_document_keeps_the_exports_fitted_curves_and_the_comparison(stored):
    back, header, result = stored
    freqs, z_fit, hx_fit = lpm_fitted("midwoofer")
    for name, expected in (("impedance", z_fit), ("displacement", hx_fit)):
        f, magnitude = back.reference_curves[name]
        np.testing.assert_allclose(f, freqs, rtol=1e-5)
        np.testing.assert_allclose(magnitude, expected, rtol=1e-4)      # what the file holds, in SI
        c = back.reference_fit[name]
        assert 0 < c["tool_vs_linpar_percent"] < 10 and c["linpar_fit_error_percent"] < c["tool_fit_error_percent"]
    # The model part is estimated before the document is written, as for a recording's.
    assert back.parameters["Mms"].std_model is not None
    assert header == {"source": "midwoofer_Z.txt + midwoofer_HX.txt"}
    assert set(back.settings) == {"impedance_band_hz", "displacement_band_hz"}


def test_the_report_overlays_the_exports_fit_and_says_how_far_apart_the_fits_are(stored):
    back, header, _ = stored
    content = build_report(back, header)
    rows = dict(content.model)
    assert dict(content.settings)["Impedance fitted"] == "2 – 225 Hz"       # as the Model rows write a band
    for name in ("impedance", "displacement"):
        row = rows[f"The export's fit ({name})"]
        assert "fit error" in row and "rms from linpar's fitted curve" in row
    plotted = {title: [line.get_label() for ax in fig.axes for line in ax.get_lines()]
               for title, fig in figures(back)}
    assert REFERENCE["label"] in plotted["Impedance"]
    assert REFERENCE["label"] in plotted["Displacement per volt (Hx)"]
    assert "The export's fit (impedance)" in html.unescape(render_html(content))
    assert render_pdf(content).startswith(b"%PDF")


def test_a_recordings_document_has_no_reference(stored):
    back, _, _ = stored
    doc = {**curve_results_document(stored[2])}
    doc.pop("reference_curves"), doc.pop("reference_fit")
    plain = StoredResult.from_json(doc)
    assert plain.reference_curves == {} and plain.reference_fit == {}
    assert not any(label == REFERENCE["label"] for _, fig in figures(plain) for ax in fig.axes
                   for label in (line.get_label() for line in ax.get_lines()))
    assert not any(key.startswith("The export's fit") for key, _ in build_report(plain, {}).model)
