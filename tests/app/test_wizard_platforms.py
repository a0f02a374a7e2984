"""The Hardware page on a system other than Linux (issue 22), faked by the platform name it is given."""
from __future__ import annotations

import pytest

from app.wizard import MeasureWizard, hardware, hardware_page

from .test_wizard_helpers import plain, to_hardware


@pytest.fixture
def elsewhere(monkeypatch):
    """The page and find_virtual_rig believe they run on Windows."""
    real = hardware.virtual_rig_unavailable
    for module in (hardware, hardware_page):
        monkeypatch.setattr(module, "virtual_rig_unavailable", lambda platform=None: real("win32"))


def test_the_rig_is_linux_only_and_says_why_elsewhere():
    assert hardware.virtual_rig_unavailable("linux") is None
    for platform in ("win32", "darwin"):
        why = hardware.virtual_rig_unavailable(platform)
        assert "Linux" in why and "in-process simulator" in why


def test_off_linux_the_page_offers_the_simulator_and_not_the_rig(qtbot, settings, tmp_path, elsewhere):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    settings.qsettings.setValue(hardware_page.SETTINGS_KEY, '{"kind": "rig"}')     # last time: the rig
    wizard = MeasureWizard(settings.qsettings)
    qtbot.addWidget(wizard)
    wizard.show()
    to_hardware(wizard)
    page = wizard.hardware_page
    assert hardware.find_virtual_rig() is None
    assert not page.rig_radio.isEnabled() and not page.rig_refresh.isEnabled()
    assert page.simulator_radio.isChecked() and wizard.next_button.isEnabled()
    assert "Linux only" in plain(page.rig_status) and "in-process simulator" in plain(page.rig_status)
    wizard.shutdown(10_000)
