"""The uncertainty's two parts and each curve's fit error reach what the user reads: the archive's stored result,
the report's parameter and model tables, `linpar analyze`'s text."""
from __future__ import annotations

import dataclasses

import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.pipeline import analyze_recording
from analysis.report import build_report
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def with_parts():
    """A result whose Mms std is given two parts (0.12 g noise, 0.9 g model), as the model-part estimate gives."""
    result = analyze_recording(recording(noise=TYPICAL_NOISE, n_periods=4, seed=41))
    mms = dataclasses.replace(result.parameters["Mms"], std=0.908e-3, std_noise=0.12e-3, std_model=0.9e-3)
    return dataclasses.replace(result, parameters={**result.parameters, "Mms": mms})


def test_the_archive_keeps_the_parts_and_the_fit_errors(with_parts):
    stored = StoredResult.from_json(results_document(with_parts))
    mms = stored.parameters["Mms"]
    assert (mms.std_noise, mms.std_model) == pytest.approx((0.12e-3, 0.9e-3))
    assert stored.parameters["RE"].std_noise is None                 # not estimated: not invented
    assert stored.validity.fit_error_percent == pytest.approx(with_parts.validity.fit_error_percent)


def test_the_report_names_the_parts_and_each_curves_fit_error(with_parts):
    content = build_report(StoredResult.from_json(results_document(with_parts)), {})
    (mms,) = [row for row in content.parameters if row.name == "Mms"]
    assert mms.note == "± 0.12 g noise, ± 0.90 g model"        # two significant digits, written out
    rows = dict(content.model)
    assert rows["Fit error (impedance)"].endswith("% (rms misfit in its fitted band)")
    assert "Fit error (displacement)" in rows


def test_analyze_text_has_noise_and_model_columns_and_the_fit_error(with_parts):
    text = with_parts.report()
    header = text.splitlines()[0]
    assert "noise" in header and "model" in header
    (mms,) = [line for line in text.splitlines() if line.startswith("Mms ")]
    assert mms.split()[-2:] == ["0.12", "0.9"]
    assert "fit error: impedance" in text
