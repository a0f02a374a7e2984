"""instruments.measurement.analysis_step.with_delay_verdict: a serial laser's delay the data cannot place is red."""
from __future__ import annotations

from analysis.laser_delay import DelaySearch
from analysis.pipeline import AnalysisResult
from analysis.validity.result import ResultValidity
from instruments.measurement.analysis_step import with_delay_verdict


def result(displacement_status="green") -> AnalysisResult:
    channels = {name: {"status": "green", "findings": []} for name in ("voltage", "current")}
    channels["displacement"] = {"status": displacement_status, "findings": []}
    return AnalysisResult(spectra=None, fit=None, parameters={}, sd_m2=None,
                          validity=ResultValidity.from_json({"overall": "green", "channels": channels}))


def test_a_delay_the_data_place_changes_no_light_and_is_reported():
    found = DelaySearch(8.1e-3, 0.99, 0.5, 1e6, True)
    judged = with_delay_verdict(result(), found).validity.as_json()
    assert judged["overall"] == "green" and judged["channels"]["displacement"]["findings"] == []
    assert judged["laser_delay"] == found.as_json()


def test_a_delay_the_data_cannot_place_makes_the_displacement_and_the_measurement_red():
    before = result()
    judged = with_delay_verdict(before, DelaySearch(3e-3, 0.3, 0.29, 4.0, False)).validity.as_json()
    finding, = judged["channels"]["displacement"]["findings"]
    assert finding["code"] == "laser-delay-not-found" and finding["severity"] == "red"
    assert "cannot be placed" in finding["message"] and "measure again" in finding["remedy"]
    assert judged["channels"]["displacement"]["status"] == "red" and judged["overall"] == "red"
    assert before.validity.overall == "green"          # the result it was given is left as it was


def test_without_a_displacement_there_is_nothing_to_place():
    judged = with_delay_verdict(result("absent"), DelaySearch(0.0, 0.0, 0.0, 0.0, False)).validity.as_json()
    assert judged["overall"] == "green" and judged["channels"]["displacement"]["findings"] == []
