"""The measurement wizard on the in-process simulator: a whole run, what blocks Next, cancel, the hand-off."""
from __future__ import annotations

import threading

import pytest

from app.wizard import MeasureWizard
from app.wizard.calibration_page import settings_key

from tests.app.wizard.test_wizard_helpers import (
    choose_simulator, fill_driver, job_wait_ms, parameter_errors, plain, run_job, skip_to_measure, to_hardware)
from tests.pace import wait_ms


@pytest.fixture
def wizard(qtbot, settings, tmp_path):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    w = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(w)
    w.resize(1300, 850)
    w.show()
    yield w
    w.shutdown(10_000)


def test_a_whole_run_ends_in_the_simulated_drivers_parameters(qtbot, window, settings, tmp_path):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    to_hardware(wizard)
    choose_simulator(wizard, realtime=False)
    hardware = wizard.hardware_page
    run_job(qtbot, hardware.test_audio_button, hardware.audio_jobs)
    assert "Found:" in hardware.audio_result.text() and "current" in hardware.audio_result.text()
    wizard.next_button.click()

    calibration = wizard.calibration_page
    assert not wizard.next_button.isEnabled()                 # nothing stored for the simulator yet
    run_job(qtbot, calibration.measure_button, calibration.jobs)
    assert "Resistor OK" in calibration.result.text()
    assert settings.qsettings.value(settings_key("simulator"))      # stored
    assert wizard.next_button.isEnabled()
    wizard.next_button.click()

    level = wizard.level_page
    run_job(qtbot, level.run_button, level.jobs)
    assert level.decision is not None and level.decision.level is not None
    assert "Chosen:" in level.decision_label.text() and "Why:" in level.decision_label.text()
    assert level.probes.rowCount() == len(level.decision.probes) >= 1
    assert level.panels.frames_received >= 2
    wizard.next_button.click()

    measure = wizard.measure_page
    with qtbot.waitSignal(window.measurement_shown, timeout=job_wait_ms()) as finished:
        measure.start_button.click()
    outcome = finished.args[0]
    assert outcome.path.exists() and outcome.path.with_suffix(".json").exists()
    assert measure.panels.frames_received >= 2
    wizard.next_button.click()

    results = wizard.results_page
    assert wizard.current is results
    errors = parameter_errors(results.table)
    assert all(abs(e) < 0.01 for e in errors.values()), errors
    assert results.validity.overall_light.status == "green"
    # The measurement went to the Results page, and from there to the Model lab and QA.
    assert window.results.result.source == outcome.path
    assert window.model_lab.base is window.results.result
    assert window.qa.result is window.results.result
    assert window.settings.recent_files()[0] == str(outcome.path.resolve())
    results.open_button.click()
    assert window.pages.currentWidget() is window.results


def test_next_is_disabled_with_a_reason_until_the_name_is_given(qtbot, wizard):
    assert wizard.current is wizard.driver_page
    assert not wizard.next_button.isEnabled()
    assert "name" in wizard.reason.text() and wizard.reason.isVisible()
    fill_driver(wizard)
    assert wizard.next_button.isEnabled() and wizard.reason.text() == ""
    wizard.driver_page.name_edit.clear()
    assert not wizard.next_button.isEnabled() and "name" in wizard.reason.text()


def test_a_rig_that_is_not_running_blocks_next_and_says_how_to_start_it(qtbot, wizard):
    to_hardware(wizard)
    page = wizard.hardware_page
    assert page.simulator_radio.isChecked()          # nothing else there: the in-process simulator
    assert wizard.next_button.isEnabled()
    # A JACK rig nobody started is not a fault: said plainly, never in the error colour.
    from app.wizard.base import ERROR_COLOUR
    if page.rig_radio.isEnabled():
        assert "not started" in page.rig_status.text() and ERROR_COLOUR not in page.rig_status.text()
    page.rig_radio.setChecked(True)
    assert not wizard.next_button.isEnabled()
    assert "linpar rig start" in wizard.reason.text()
    assert not page.test_audio_button.isEnabled()


def test_a_channel_map_with_two_signals_on_one_input_blocks_next(qtbot, wizard, monkeypatch):
    to_hardware(wizard)
    page = wizard.hardware_page
    page.devices = ["a card"]                 # no PortAudio in this test: the list is not asked for
    page.device_message = "offline"
    page.soundcard_radio.setChecked(True)
    page.channel_form.spins["current"].setValue(0)       # voltage is on 0 too
    assert not wizard.next_button.isEnabled()
    assert wizard.reason.text()


def test_cancel_stops_the_measurement_and_nothing_is_shown(qtbot, wizard):
    skip_to_measure(qtbot, wizard, realtime=True, template="midrange")     # short periods: a frame comes soon
    measure = wizard.measure_page
    with qtbot.waitSignal(measure.panels.repainted, timeout=job_wait_ms()):
        measure.start_button.click()
    assert measure.jobs.cancel_button.isVisible() and not wizard.next_button.isEnabled()
    assert not wizard.back_button.isEnabled()
    assert "Wait for the measurement" in wizard.reason.text()
    with qtbot.waitSignal(wizard.session.cancelled, timeout=wait_ms(10)):
        measure.jobs.cancel_button.click()
    assert "cancelled" in measure.result.text().lower()
    assert wizard.state.outcome is None
    assert not wizard.next_button.isEnabled() and wizard.back_button.isEnabled()
    assert measure.start_button.isEnabled()


def test_the_measurement_runs_off_the_gui_thread(qtbot, wizard, monkeypatch):
    import app.wizard.tasks as tasks
    threads = []
    real = tasks.run_measurement

    def spy(*args, **kwargs):
        threads.append(threading.current_thread())
        return real(*args, **kwargs)
    monkeypatch.setattr(tasks, "run_measurement", spy)
    skip_to_measure(qtbot, wizard, realtime=False)
    with qtbot.waitSignal(wizard.measurement_finished, timeout=job_wait_ms()):
        wizard.measure_page.start_button.click()
    assert threads and threads[0] is not threading.main_thread()


def test_the_measurement_begins_once_the_emptied_panels_are_drawn(qtbot, wizard, monkeypatch):
    """The Start click's turns are the GUI's: the measurement's own start-up (devices, imports) held the GIL
    against them, so its job waits for the panels' clear (app.wizard.measure_session.PANELS_DRAWN_WAIT_S)."""
    import app.wizard.measure_session as session
    import app.wizard.tasks as tasks
    monkeypatch.setattr(session, "PANELS_DRAWN_WAIT_S", wait_ms(60) / 1000)    # never the bound that ends the wait
    emptied, begun_after_emptied = [], []
    panels = wizard.measure_page.panels
    clear = panels.clear

    def noting_clear(*args, then=None, **kwargs):
        clear(*args, then=lambda: (emptied.append(True), then()), **kwargs)
    monkeypatch.setattr(panels, "clear", noting_clear)
    real = tasks.run_measurement

    def spy(*args, **kwargs):
        begun_after_emptied.append(bool(emptied))
        return real(*args, **kwargs)
    monkeypatch.setattr(tasks, "run_measurement", spy)
    skip_to_measure(qtbot, wizard, realtime=False)
    with qtbot.waitSignal(wizard.measurement_finished, timeout=job_wait_ms()):
        wizard.measure_page.start_button.click()
    assert begun_after_emptied == [True]


def test_a_failing_device_is_a_message_not_a_crash(qtbot, wizard, monkeypatch):
    from instruments.audio.errors import AudioError
    import app.wizard.hardware as hardware

    def broken(config, calibration=None):
        raise AudioError("sound card 'X' not found")
    monkeypatch.setattr(hardware, "open_audio", broken)
    to_hardware(wizard)
    choose_simulator(wizard, realtime=False)
    page = wizard.hardware_page
    run_job(qtbot, page.test_audio_button, page.audio_jobs)
    assert "Failed: sound card 'X' not found" in plain(page.audio_result)
    assert wizard.next_button.isEnabled()          # a test is advice; the user may go on


def test_a_large_signal_step_measured_again_is_said_with_its_reason(qtbot, wizard, tmp_path):
    """The plan's outcome as the Measure step shows it: a step measured again at its level (its laser stream
    misplaced in time) is named with the plan's words, escaped, beside the count of steps."""
    from app.wizard.plans import DriverInfo
    from app.wizard.tasks import LargeSignalMeasured
    from instruments.measurement.large_signal_plan import LargeSignalOutcome, PlanStep

    wizard.state.driver = DriverInfo("woofer", "1", 0.0133, 8.0, "large-signal")
    again = "measured again at the same level: the displacement at 4 V changed by 10% <from period to period>"
    steps = (PlanStep(1, 2.0, None, None), PlanStep(2, 4.0, None, None, message=again),
             PlanStep(3, 4.0, None, None), PlanStep(4, 6.0, None, None, partial=True, message="cancelled"))
    plan = LargeSignalOutcome(steps, "cancelled", "cancelled during step 4 (6 V)", tmp_path / "summary.json")
    wizard.measure_page.on_large_signal(LargeSignalMeasured(plan, None, "no usable step"))
    shown = plain(wizard.measure_page.result)
    assert "4 step(s) recorded" in shown and f"Step 2 (4 V): {again}." in shown
    assert "Step 4" not in shown and "Step 1" not in shown      # the stop's words are the plan's; step 1 has none
    assert wizard.measure_page.missing().startswith("No curves were identified")     # not "the curves are on…"


def test_the_large_signal_template_runs_the_plan_and_hands_the_curves_over(qtbot, wizard):
    """On the simulator (the paper's driver, linear): the plan steps up to the excursion set here, each step a
    recording, and the identification of the steps goes to the Large-signal page (flat curves: no nonlinearity)."""
    skip_to_measure(qtbot, wizard, realtime=False, level=0.5, template="large-signal")
    page = wizard.measure_page
    assert page.large_signal.isVisible() and "large-signal plan" in page.start_button.text()
    page.large_signal.excursion.setValue(1.0)
    with qtbot.waitSignal(page.large_signal_measured, timeout=job_wait_ms(4)) as handed:
        page.start_button.click()
    done = handed.args[0]
    assert done.plan.stopped_by == "excursion" and len(done.plan.steps) >= 2
    assert all(p.is_file() for p in done.plan.recordings)
    assert done.result.model.Bl.coefficients[0] == pytest.approx(5.23, rel=0.01)
    assert "step(s) recorded" in plain(page.result)
    assert page.missing() == "The curves are on the Large-signal page."
