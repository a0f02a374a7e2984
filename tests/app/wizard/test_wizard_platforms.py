"""The Hardware page on a system other than Linux (issue 22), faked by the platform name it is given."""
from __future__ import annotations

import pytest

from app.wizard import MeasureWizard, hardware, hardware_page

from tests.app.wizard.test_wizard_helpers import plain, to_hardware
from tests.pace import wait_ms


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


def windows_cards():
    from tests.instruments.audio.test_host_apis import WINDOWS
    return WINDOWS


def make_wizard(qtbot, settings, tmp_path, monkeypatch, saved_hardware: str | None = None):
    from instruments.serial_ports import SerialPort
    ports = [SerialPort("COM7", "USB Serial Port (COM7)", "0403:6001", "A10K2B3C", "FTDI"),
             SerialPort("COM1", "Communications Port (COM1)", "")]
    monkeypatch.setattr(hardware_page, "list_serial_ports", lambda: ports)
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    if saved_hardware is not None:
        settings.qsettings.setValue(hardware_page.SETTINGS_KEY, saved_hardware)
    wizard = MeasureWizard(settings.qsettings, rig_name="linpar-not-running-in-tests")
    qtbot.addWidget(wizard)
    wizard.show()
    to_hardware(wizard)
    return wizard


def test_the_serial_ports_are_listed_with_their_usb_ids_and_a_click_takes_one(qtbot, settings, tmp_path,
                                                                               monkeypatch):
    wizard = make_wizard(qtbot, settings, tmp_path, monkeypatch)
    page = wizard.hardware_page
    rows = [[page.port_list.topLevelItem(i).text(c) for c in range(3)] for i in range(page.port_list.topLevelItemCount())]
    assert rows == [["COM7", "USB Serial Port (COM7)", "0403:6001"], ["COM1", "Communications Port (COM1)", "not USB"]]
    assert "2 ports found" in plain(page.port_note)
    page.laser_serial.setChecked(True)
    page.port_list.itemClicked.emit(page.port_list.topLevelItem(0), 0)
    assert page.laser_port.text() == "COM7" and page.config().laser_port == "COM7"
    wizard.shutdown(10_000)


def test_the_sound_cards_show_their_host_api_and_the_choice_is_kept_by_name_and_host_api(qtbot, settings, tmp_path,
                                                                                          monkeypatch):
    import json
    wizard = make_wizard(qtbot, settings, tmp_path, monkeypatch)
    page = wizard.hardware_page
    page.device_message = "offline"           # no PortAudio asked in this test: the list is handed in
    page.soundcard_radio.setChecked(True)
    page.on_devices(windows_cards())
    listed = page.device_list
    assert [listed.topLevelItem(i).text(1) for i in range(4)] == ["ASIO", "Windows WASAPI", "MME",
                                                                 "Windows DirectSound"]
    assert [listed.topLevelItem(i).text(3) for i in range(4)] == ["suits it", "usable", "avoid", "avoid"]
    listed.setCurrentItem(listed.topLevelItem(2))
    assert "Better: this card under Windows WASAPI" in page.device_advice.text()
    listed.setCurrentItem(listed.topLevelItem(0))
    assert page.config().device == windows_cards()[0].choice
    page.commit()
    stored = json.loads(settings.qsettings.value(hardware_page.SETTINGS_KEY))
    assert stored["device"] == {"name": "Focusrite USB ASIO", "hostapi": "ASIO"}
    wizard.shutdown(10_000)


def test_a_device_stored_by_index_in_older_settings_is_asked_for_again(qtbot, settings, tmp_path, monkeypatch):
    wizard = make_wizard(qtbot, settings, tmp_path, monkeypatch, '{"kind": "soundcard", "device": 3}')
    page = wizard.hardware_page
    assert "remembered by its number" in page.audio_result.text()
    qtbot.waitUntil(lambda: not page.audio_jobs.busy, timeout=wait_ms(30))   # the list PortAudio gives here, if any
    page.on_devices(windows_cards())
    assert page.device_list.choice() is None and not wizard.next_button.isEnabled()
    assert "Choose a sound card" in wizard.reason.text()
    wizard.shutdown(10_000)


def test_a_device_that_only_records_is_listed_but_not_taken(qtbot, settings, tmp_path, monkeypatch):
    from instruments.audio.interface import AudioDeviceInfo
    wizard = make_wizard(qtbot, settings, tmp_path, monkeypatch, '{"kind": "soundcard"}')
    page = wizard.hardware_page
    qtbot.waitUntil(lambda: not page.audio_jobs.busy, timeout=wait_ms(30))
    page.on_devices([AudioDeviceInfo(0, "Analogue 1 + 2 (Focusrite USB Audio)", "Windows WASAPI", 2, 0, 48000.0)])
    page.device_list.setCurrentItem(page.device_list.topLevelItem(0))
    assert page.device_list.choice() is None and not wizard.next_button.isEnabled()
    assert "both plays and records" in wizard.reason.text() and "ASIO" in wizard.reason.text()
    assert "inputs only" in page.device_advice.text()
    wizard.shutdown(10_000)


def test_a_device_stored_with_its_old_index_beside_its_name_is_found_by_name(qtbot, settings, tmp_path, monkeypatch):
    saved = '{"kind": "soundcard", "device": {"name": "Focusrite USB ASIO", "hostapi": "ASIO", "index": 14}}'
    wizard = make_wizard(qtbot, settings, tmp_path, monkeypatch, saved)
    page = wizard.hardware_page
    assert page.audio_result.text() == ""             # nothing to say: it is known by name
    qtbot.waitUntil(lambda: not page.audio_jobs.busy, timeout=wait_ms(30))
    page.on_devices(windows_cards())
    assert page.device_list.choice() == windows_cards()[0].choice
    wizard.shutdown(10_000)
