"""One uncertainty through every output: the JSON, the archive's record, the report, QA and the exports.

Each realistic recording (tests/realistic_drivers.py: a woofer, a midrange and a subwoofer with several
physics at once, none in the model's form, known truth) is analysed once, statistically; every output is
then made from that result *without* the model part, as a caller that forgot it would. Each must carry
the same total std (noise and model parts) as `model_uncertainty` gives, name both parts, and judge the
unit the same way; a unit whose truth lies inside its limits is never failed.
"""
from __future__ import annotations

import json
import math

import pytest

from analysis.archive import Archive
from analysis.archive.results import StoredResult, calibration_of, header_of_recording, results_document
from analysis.export.parameters import parameters_csv, parameters_json
from analysis.fit.model_uncertainty import ESTIMATED, model_uncertainty
from analysis.limits import judge_result, load_limits
from analysis.pipeline import analyze_recording, result_json
from analysis.report import build_report, render_html
from tests.realistic_drivers import REALISTIC, realistic_recording

LUMPED = ("RE", "Bl", "Mms", "Kms")
LIMIT_UNITS = {"RE": "ohm", "Bl": "T*m", "Mms": "kg", "Kms": "N/m"}


def limits_file(folder, name: str, tolerance: str = "15%", fit_error=None):
    truth = REALISTIC[name].truth
    doc = {"format": "linpar-limits/1", "name": f"{name} at its truth ±{tolerance}",
           "parameters": {k: {"nominal": truth[k], "tolerance": tolerance, "unit": unit}
                          for k, unit in LIMIT_UNITS.items()}}
    if fit_error is not None:
        doc["fit_error_percent"] = fit_error
    path = folder / f"{name}-limits.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return load_limits(path)


@pytest.fixture(scope="module", params=sorted(REALISTIC))
def analysed(request):
    """(name, recording, the statistical result, the result with its model part)."""
    recording = realistic_recording(request.param, 0)
    statistical = analyze_recording(recording)
    return request.param, recording, statistical, model_uncertainty(statistical)


def test_the_model_part_is_estimated_once_and_kept_with_the_result(analysed, monkeypatch):
    name, _, statistical, full = analysed
    assert statistical.model_part is None and full.model_part.state == ESTIMATED
    assert full.validity.model_part["state"] == ESTIMATED and full.validity.model_part["seconds"] > 0
    monkeypatch.setattr("analysis.fit.model_uncertainty.fit_with", lambda *a, **k: pytest.fail("refitted"))
    assert model_uncertainty(full) is full
    assert result_json(full)["parameters"]["Mms"]["std_model"] == full.parameters["Mms"].std_model


def test_the_json_and_the_archived_document_carry_the_same_total_and_parts(analysed):
    name, recording, statistical, full = analysed
    printed = result_json(statistical)["parameters"]
    stored = results_document(statistical, recording)
    assert stored["validity"]["model_part"]["state"] == ESTIMATED
    for k in LUMPED:
        p = full.parameters[k]
        assert p.std == pytest.approx(math.hypot(p.std_noise, p.std_model))
        for doc in (printed[k], stored["parameters"][k]):
            assert (doc["std"], doc["std_noise"], doc["std_model"]) == pytest.approx(
                (p.std, p.std_noise, p.std_model), rel=1e-9), (name, k)


def test_qa_never_fails_a_unit_whose_truth_lies_inside_its_limits(analysed, tmp_path):
    name, _, statistical, full = analysed
    # With the default fit-error tolerance these recordings are not judged (their model misses the cone
    # mode by tens of %: said, with the reason); with a tolerance that accepts that, by their intervals.
    for limits in (limits_file(tmp_path, name), limits_file(tmp_path, name, fit_error={"impedance": 50,
                                                                                        "displacement": 500})):
        judged = judge_result(limits, full.parameters, full.validity)
        assert judged["verdict"] != "fail", (name, judged["why"])
        assert all(v["outcome"] != "FAIL" for v in judged["parameters"]), (name, judged["parameters"])
        # The same verdict from the statistical result run through any output's path.
        again = StoredResult.from_json(results_document(statistical))
        assert judge_result(limits, again.parameters, again.validity)["verdict"] == judged["verdict"]


def test_the_archive_record_stores_the_total_and_its_verdict(analysed, tmp_path):
    name, recording, statistical, full = analysed
    archive = Archive(tmp_path / "archive")
    truth = REALISTIC[name].truth
    archive.store_limits({"format": "linpar-limits/1", "name": "truth ±15 %",
                          "fit_error_percent": {"impedance": 50, "displacement": 500},
                          "parameters": {k: {"nominal": truth[k], "tolerance": "15%", "unit": u}
                                         for k, u in LIMIT_UNITS.items()}})
    mid = archive.store(recording, statistical, {"driver": name})
    measurement = archive.get(mid)
    record = measurement.record
    for k in ("RE", "Bl", "Mms", "Cms", "fs", "Qts"):          # the record's key parameters among them
        assert record["key_parameters"][k]["std"] == pytest.approx(full.parameters[k].std, rel=1e-9), k
        kept = measurement.result().parameters[k]
        assert (kept.std_noise, kept.std_model) == pytest.approx(
            (full.parameters[k].std_noise, full.parameters[k].std_model), rel=1e-9), k
    assert record["qa"]["verdict"] != "fail"


def test_the_report_and_the_exports_name_both_parts_and_the_fit_error(analysed):
    name, recording, statistical, full = analysed
    stored = StoredResult.from_json(results_document(statistical, recording))
    text = render_html(build_report(stored, header_of_recording(recording), None, calibration_of(recording)))
    assert "g noise" in text and "g model" in text, name          # Mms's two parts, in grams
    assert "Fit error (impedance)" in text and "Model part" in text and "models the data cannot tell apart" in text
    rows = {line.split(",")[0]: line.split(",") for line in parameters_csv(stored).splitlines()
            if not line.startswith("#")}
    header = rows["parameter"]
    mms = dict(zip(header, rows["Mms"]))
    assert float(mms["std"]) == pytest.approx(full.parameters["Mms"].std, rel=1e-9)
    assert float(mms["std_model"]) == pytest.approx(full.parameters["Mms"].std_model, rel=1e-9)
    exported = json.loads(parameters_json(stored))["parameters"]["Mms"]
    assert exported["std_noise"] == pytest.approx(full.parameters["Mms"].std_noise, rel=1e-9)
