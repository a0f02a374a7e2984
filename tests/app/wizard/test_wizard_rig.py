"""The measurement wizard on the JACK virtual rig: PortAudio, JACK, and the rig's driver in its own process."""
from __future__ import annotations

import pytest

from analysis.recording.format import read_recording
from app.wizard import MeasureWizard
from tests.app.wizard.test_wizard_helpers import fill_driver, parameter_errors, plain, run_job
from tests.rig_xruns import ATTEMPTS, UNINJECTED_XRUN

pytestmark = pytest.mark.rig


def _ended_by_an_xrun(page) -> bool:
    """Whether the measurement just made ended on an xrun: its recording says so, or it kept too few periods
    for one and the page's failure line names the xrun."""
    outcome = page.state.outcome
    if outcome is None:
        return UNINJECTED_XRUN in plain(page.result)
    return read_recording(outcome.path).extra["measurement"]["ended_by"] == "xrun"


def _measure_until_no_xrun(qtbot, wizard):
    """Start the measurement, again after an xrun nobody injected (at most ATTEMPTS times; see tests/rig_xruns.py:
    on a loaded 2-core machine the rig's JACK server reports one now and then, and with the serial laser it ends
    the measurement, which tests/instruments/measurement/test_measure_rig.py tests on its own)."""
    page = wizard.measure_page
    for _ in range(ATTEMPTS):
        run_job(qtbot, page.start_button, page.jobs)
        if not _ended_by_an_xrun(page):
            break
    assert page.state.outcome is not None, plain(page.result)
    return page.state.outcome


def test_a_whole_run_on_the_virtual_rig(qtbot, settings, tmp_path, virtual_rig):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    wizard = MeasureWizard(settings.qsettings, rig_name=virtual_rig.name,
                           rig_runtime_dir=str(virtual_rig.paths.directory.parent))
    qtbot.addWidget(wizard)
    wizard.resize(1300, 850)
    wizard.show()
    try:
        fill_driver(wizard)
        wizard.next_button.click()
        hardware = wizard.hardware_page
        assert hardware.rig_radio.isChecked()            # the rig runs: it is the default
        assert "running" in plain(hardware.rig_status)
        run_job(qtbot, hardware.test_audio_button, hardware.audio_jobs)
        assert f"Found: JACK virtual rig '{virtual_rig.name}'" in plain(hardware.audio_result)
        wizard.next_button.click()
        assert wizard.next_button.isEnabled()            # the rig needs no corrections
        wizard.next_button.click()
        level = wizard.level_page
        run_job(qtbot, level.run_button, level.jobs)
        assert level.decision.level is not None, level.decision.reason
        assert level.panels.frames_received >= 2
        wizard.next_button.click()
        finished = []
        wizard.measurement_finished.connect(finished.append)
        outcome = _measure_until_no_xrun(qtbot, wizard)
        assert finished[-1] is outcome                  # the wizard says so (the main window goes on from it)
        assert outcome.path.exists()
        assert wizard.measure_page.panels.frames_received >= 2
        wizard.next_button.click()
        errors = parameter_errors(wizard.results_page.table)
        assert all(abs(e) < 0.01 for e in errors.values()), errors
        assert wizard.results_page.validity.overall_light.status in ("green", "yellow")
    finally:
        wizard.shutdown(20_000)
