"""The QA page: the lights with their findings, pass/fail against limits, the report export."""
from __future__ import annotations

import copy
import json

import pytest

import app.qa.view as qa_view
from analysis.recording.format import make_recording, write_recording
from analysis.validity.findings import NO_SIGNAL
from app.qa.view import NO_LIMITS, NO_REPORT, QAView
from instruments.simulation import faults
from tests.builders import needs_pdftotext, pdf_text

from tests.app.wizard.test_wizard_helpers import plain
from tests.pace import wait_ms

from tests.app.conftest import open_and_wait

LIMITS = {"format": "linpar-limits/1", "name": "paper QA", "parameters": {
    "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
    "fs": {"nominal": 70, "tolerance": 7, "unit": "Hz"},
    "Bl": {"min": 5.5, "unit": "T*m"}}}


@pytest.fixture(scope="module")
def faulty(tmp_path_factory):
    wav, _ = write_recording(tmp_path_factory.mktemp("faults") / "current-disconnected", faults.current_disconnected())
    return wav


@pytest.fixture
def limits_file(tmp_path):
    path = tmp_path / "limits.json"
    path.write_text(json.dumps(LIMITS), encoding="utf-8")
    return path


def test_a_faulty_recording_shows_a_red_light_and_its_message(qtbot, window, faulty):
    outcome, = open_and_wait(qtbot, window, faulty)
    window.pages.setCurrentWidget(window.qa)
    qa = window.qa
    assert qa.overall_light.status == "red"
    current = qa.channels["current"]
    assert current.light.status == "red"
    finding = outcome.result.validity.as_json()["channels"]["current"]["findings"][0]
    shown = plain(current.details)
    assert finding["message"] in shown and finding["remedy"] in shown
    assert current.details.isVisible() and current.details.width() > 100
    assert qa.channels["voltage"].light.status == "green"
    # A broken measurement is INVALID in its own word and colour (not FAIL's red): the unit was not judged.
    assert qa.verdict == "invalid"
    verdict = plain(qa.verdict_label)
    assert verdict.startswith("INVALID: measure again") and "measurement invalid" in verdict and "FAIL" not in verdict
    from analysis.report.qa import VERDICT_COLOURS
    assert VERDICT_COLOURS["invalid"][0] in qa.verdict_label.styleSheet()
    assert VERDICT_COLOURS["fail"][0] not in qa.verdict_label.styleSheet()
    assert "the unit itself was not judged" in verdict


@pytest.fixture(scope="module")
def zeroed_current(tmp_path_factory):
    """A broken current lead read as exact zeros: nothing can be fitted (it used to be a modal error only)."""
    rec = faults.clean()
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["current"] = signals["current"] * 0.0
    broken = make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins)
    wav, _ = write_recording(tmp_path_factory.mktemp("faults") / "current-zeroed", broken)
    return wav


@needs_pdftotext
def test_a_zeroed_current_is_judged_red_not_refused(qtbot, window, zeroed_current, dialogs, limits_file, tmp_path):
    outcome, = open_and_wait(qtbot, window, zeroed_current)
    assert dialogs == [] and outcome.result.fit is None
    qa = window.qa
    assert qa.channels["current"].light.status == "red" and qa.channels["voltage"].light.status == "green"
    assert "no signal" in plain(qa.channels["current"].details)
    assert f"[{NO_SIGNAL}]" in plain(qa.channels["current"].details)        # the finding's code, on the light
    assert qa.verdict == "invalid"
    assert "Nothing could be fitted" in window.results.fit_quality.text()
    assert "Nothing to model" in window.model_lab.empty.text()
    # Against limits: FAIL, no row judged, and the verdict says which finding, what to do, and that the unit
    # itself was not judged.
    assert qa.load_limits(limits_file)
    assert {qa.table.item(r, 3).text() for r in range(qa.table.rowCount())} == {"not judged"}
    verdict = plain(qa.verdict_label)
    assert verdict.startswith("INVALID: measure again") and "NOT JUDGED" not in verdict
    assert "measurement invalid: current" in verdict and f"[{NO_SIGNAL}]" in verdict
    assert "check the current sense" in verdict and "the unit itself was not judged" in verdict
    # The report of the broken measurement is written, and says why.
    assert qa.export_button.isEnabled()
    target = tmp_path / "broken-report.pdf"
    with qtbot.waitSignal(qa.report_written, timeout=wait_ms(60)):
        qa.export_to(target)
    assert "Written" in qa.export_label.text()
    text = " ".join(pdf_text(target).split())
    assert "QA: INVALID: measure again" in text and "QA: FAIL" not in text and "measurement invalid: current" in text and f"{NO_SIGNAL}: current: only 0%" in text
    assert "the unit itself was not judged" in text
    assert "Remedy: check the current sense" in text and "Nothing was fitted" in text


def test_limits_give_pass_and_fail_per_parameter(qtbot, window, recordings, limits_file):
    if not qa_view.available(qa_view.LIMITS_MODULE):
        pytest.skip("analysis/limits.py is not in this installation")
    open_and_wait(qtbot, window, recordings["paper"])
    qa = window.qa
    assert qa.load_button.isEnabled()
    assert qa.load_limits(limits_file)
    rows = {qa.table.item(r, 0).text(): qa.table.item(r, 3).text() for r in range(qa.table.rowCount())}
    assert rows == {"Re": "pass", "fs": "pass", "Bl": "FAIL"}          # the paper's Bl is 5.23 T*m
    assert qa.verdict == "fail"
    # The FAIL banner names the failing parameter with its margin, in the limits file's unit.
    verdict = plain(qa.verdict_label)
    assert verdict.startswith("FAIL") and "Bl 0.27 T·m below min" in verdict, verdict
    assert "value ± 2 σ" in qa.table.item(0, 3).toolTip()
    assert "Fit error (rms misfit of each curve): impedance" in verdict and "(tolerance 5 %)" in verdict
    assert window.settings.qsettings.value("qa/limits_file") == str(limits_file)
    looser = copy.deepcopy(LIMITS)          # the module's LIMITS stay as other tests expect them
    looser["parameters"]["Bl"] = {"min": 5.0, "unit": "T*m"}
    limits_file.write_text(json.dumps(looser), encoding="utf-8")
    assert qa.load_limits(limits_file)
    assert qa.verdict == "pass"


def test_a_broken_limits_file_says_why_and_judges_nothing(qtbot, settings, tmp_path):
    if not qa_view.available(qa_view.LIMITS_MODULE):
        pytest.skip("analysis/limits.py is not in this installation")
    qa = QAView(settings.qsettings)
    qtbot.addWidget(qa)
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "linpar-limits/1", "parameters": {"RE": {"nominal": 3}}}', encoding="utf-8")
    assert not qa.load_limits(bad)
    assert "unit" in plain(qa.limits_label) and qa.table.rowCount() == 0


def test_without_the_limits_and_report_packages_the_buttons_say_why(qtbot, settings, monkeypatch):
    monkeypatch.setattr(qa_view, "available", lambda module: False)
    qa = QAView(settings.qsettings)
    qtbot.addWidget(qa)
    assert not qa.load_button.isEnabled() and qa.load_button.toolTip() == NO_LIMITS
    assert NO_LIMITS in plain(qa.limits_label)
    assert not qa.export_button.isEnabled() and qa.export_label.text() == NO_REPORT


def test_the_report_is_written_off_the_gui_thread(qtbot, window, recordings, tmp_path):
    if not qa_view.available(qa_view.REPORT_MODULE):
        pytest.skip("analysis/report is not in this installation")
    open_and_wait(qtbot, window, recordings["paper"])
    qa = window.qa
    assert qa.export_button.isEnabled()
    target = tmp_path / "paper-report.html"
    with qtbot.waitSignal(qa.report_written, timeout=wait_ms(60)) as written:
        qa.export_to(target)
        assert not qa.export_jobs.progress.isHidden() and not qa.export_jobs.cancel_button.isHidden()
    assert str(target) in written.args[0]
    assert target.exists() and "paper" in target.read_text(encoding="utf-8").lower()
    assert qa.export_jobs.progress.isHidden()
    assert "Written" in qa.export_label.text()


def test_a_cancelled_export_writes_nothing(qtbot, window, recordings, tmp_path):
    if not qa_view.available(qa_view.REPORT_MODULE):
        pytest.skip("analysis/report is not in this installation")
    open_and_wait(qtbot, window, recordings["paper"])
    qa = window.qa
    target = tmp_path / "cancelled.pdf"
    qa.export_to(target)
    with qtbot.waitSignal(qa.export_jobs.busy_changed, timeout=wait_ms(60)):
        qa.export_jobs.cancel_button.click()
    assert "cancelled" in qa.export_label.text()
    assert not target.exists()


def test_the_report_carries_the_loaded_limits_verdict(qtbot, window, recordings, limits_file, tmp_path):
    if not (qa_view.available(qa_view.REPORT_MODULE) and qa_view.available(qa_view.LIMITS_MODULE)):
        pytest.skip("analysis/report or analysis/limits.py is not in this installation")
    open_and_wait(qtbot, window, recordings["paper"])
    qa = window.qa
    assert qa.load_limits(limits_file) and qa.verdict == "fail"            # Bl 5.23 T*m against >= 5.5
    target = tmp_path / "paper-qa.html"
    with qtbot.waitSignal(qa.report_written, timeout=wait_ms(60)):
        qa.export_to(target)
    page = target.read_text(encoding="utf-8")
    assert "QA: FAIL" in page and "limits.json" in page and "paper QA" in page
