"""The measurement wizard on the JACK virtual rig: PortAudio, JACK, and the rig's driver in its own process."""
from __future__ import annotations

import pytest

from app.wizard import MeasureWizard

from tests.app.wizard.test_wizard_helpers import fill_driver, job_wait_ms, parameter_errors, plain, run_job

pytestmark = pytest.mark.rig


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
        with qtbot.waitSignal(wizard.measurement_finished, timeout=job_wait_ms()) as finished:
            wizard.measure_page.start_button.click()
        outcome = finished.args[0]
        assert outcome.path.exists()
        assert wizard.measure_page.panels.frames_received >= 2
        wizard.next_button.click()
        errors = parameter_errors(wizard.results_page.table)
        assert all(abs(e) < 0.01 for e in errors.values()), errors
        assert wizard.results_page.validity.overall_light.status in ("green", "yellow")
    finally:
        wizard.shutdown(20_000)
