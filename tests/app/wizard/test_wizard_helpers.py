"""Driving the measurement wizard in GUI tests (helpers only, no tests: named test_* to sit with them)."""
from __future__ import annotations

from analysis.derived import derived_from_values
from analysis.drivers import load_driver
from tests.pace import wait_ms

PAPER = load_driver("paper")
TRUTH = {**PAPER.parameters, **derived_from_values(PAPER.parameters)}
CHECKED = ("RE", "fs", "Bl", "Mms", "Qts")
JOB_WAIT_S = 120          # a measurement and its analysis, on an idle machine: well under a minute


def job_wait_ms(times: float = 1) -> int:
    """The timeout of a wait for `times` session jobs, at the machine's pace when the wait begins."""
    return wait_ms(times * JOB_WAIT_S)


def plain(label) -> str:
    """What a rich-text label shows, as a user reads it."""
    from PySide6.QtGui import QTextDocument
    document = QTextDocument()
    document.setHtml(label.text())
    return document.toPlainText()


def run_job(qtbot, button, jobs, timeout: int | None = None) -> None:
    """Click the button that starts a session job and wait until the job is over."""
    with qtbot.waitSignal(jobs.busy_changed, timeout=timeout or job_wait_ms(), check_params_cb=lambda busy: not busy):
        button.click()


def fill_driver(wizard, name: str = "W18-PAPER", serial: str = "0042", template: str = "woofer") -> None:
    page = wizard.driver_page
    page.name_edit.setText(name)
    page.serial_edit.setText(serial)
    page.sd_value.setValue(133.0)
    page.impedance.setValue(4.0)
    page.template.setCurrentIndex(page.template.findData(template))


def to_hardware(wizard, template: str = "woofer") -> None:
    fill_driver(wizard, template=template)
    wizard.next_button.click()
    assert wizard.current is wizard.hardware_page


def choose_simulator(wizard, realtime: bool) -> None:
    page = wizard.hardware_page
    page.simulator_radio.setChecked(True)
    page.laser_analog.setChecked(True)
    page.realtime_check.setChecked(realtime)


def skip_to_measure(qtbot, wizard, realtime: bool, level: float = 0.3, template: str = "woofer") -> None:
    """Driver -> simulator -> no corrections -> a level by hand -> the Measure step."""
    to_hardware(wizard, template)
    choose_simulator(wizard, realtime)
    wizard.next_button.click()
    wizard.calibration_page.without.setChecked(True)
    wizard.next_button.click()
    level_page = wizard.level_page
    level_page.manual.setChecked(True)
    level_page.manual_level.setValue(level)
    wizard.next_button.click()
    assert wizard.current is wizard.measure_page


def parameter_errors(table) -> dict[str, float]:
    model = table.parameter_model
    return {name: model.parameter(model.row_of(name)).value / TRUTH[name] - 1.0 for name in CHECKED}
