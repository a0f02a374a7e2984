"""Issue 22: which host API suits a measurement, and one card listed under several host APIs."""
from __future__ import annotations

from instruments.audio.host_apis import BEST, GOOD, POOR, UNUSABLE, card_key, judge, suitability
from instruments.audio.interface import AudioDeviceInfo
from instruments.serial_ports import SerialPort, list_serial_ports, port_example


def device(name: str, hostapi: str, inputs: int = 2, outputs: int = 2) -> AudioDeviceInfo:
    return AudioDeviceInfo(0, name, hostapi, inputs, outputs, 48000.0)


# As a Windows PC with a USB interface lists it (names as PortAudio gives them; MME cuts them at 31 characters).
WINDOWS = [device("Focusrite USB ASIO", "ASIO"),
           device("Focusrite USB (Focusrite USB Audio)", "Windows WASAPI"),
           device("Focusrite USB (Focusrite USB Au", "MME"),
           device("Focusrite USB (Focusrite USB Audio)", "Windows DirectSound")]


def test_each_host_api_is_judged_for_measurement():
    assert judge(device("x", "ASIO"))[0] == BEST
    assert judge(device("x", "Core Audio"))[0] == BEST
    assert judge(device("x", "JACK Audio Connection Kit"))[0] == BEST
    assert judge(device("USB Audio CODEC: - (hw:1,0)", "ALSA"))[0] == BEST
    for server in ("default", "pulse", "pipewire", "sysdefault"):
        rank, why = judge(device(server, "ALSA"))
        assert rank == POOR and "hw:" in why and "resamples" in why
    assert judge(device("x", "Windows WASAPI"))[0] == GOOD
    assert judge(device("x", "MME"))[0] == POOR and "resampled" in judge(device("x", "MME"))[1]
    assert judge(device("x", "Some New API"))[0] == POOR


def test_one_card_under_several_host_apis_says_which_to_choose_and_why():
    found = suitability(WINDOWS)
    wasapi_key = card_key(WINDOWS[1].name)
    assert wasapi_key == card_key(WINDOWS[2].name) == card_key(WINDOWS[3].name)   # MME's cut-off name too
    assert found[1].text.startswith("usable: ") and "Better: this card under" not in found[0].text
    assert found[2].rank == POOR and "Better: this card under Windows WASAPI" in found[2].text
    assert found[3].rank == POOR and "Better: this card under Windows WASAPI" in found[3].text
    assert "the best of this card's host APIs (also listed under MME, Windows DirectSound)" in found[1].text
    assert found[0].rank == BEST and found[0].text.startswith("suits measurement: ")   # ASIO names the card otherwise


def test_the_port_example_fits_the_system():
    assert port_example("win32") == "COM3"
    assert port_example("darwin").startswith("/dev/cu.usbserial")
    assert port_example("linux") == "/dev/ttyUSB0"


def test_serial_ports_are_listed_usb_first_with_their_ids(monkeypatch):
    from serial.tools import list_ports
    from serial.tools.list_ports_common import ListPortInfo

    def info(device, description, vid=None, pid=None, serial=None):
        port = ListPortInfo(device, skip_link_detection=True)
        port.description, port.vid, port.pid, port.serial_number = description, vid, pid, serial
        return port
    monkeypatch.setattr(list_ports, "comports", lambda: [info("COM1", "Communications Port (COM1)"),
                                                         info("COM7", "USB Serial Port (COM7)", 0x0403, 0x6001, "A1")])
    ports = list_serial_ports()
    assert ports == [SerialPort("COM7", "USB Serial Port (COM7)", "0403:6001", "A1"),
                     SerialPort("COM1", "Communications Port (COM1)", "")]


def test_a_device_that_only_records_or_only_plays_cannot_be_used_and_says_what_to_take():
    found = suitability([device("Focusrite USB ASIO", "ASIO"),
                         device("Analogue 1 + 2 (Focusrite USB Audio)", "Windows WASAPI", 2, 0),
                         device("Speakers (Focusrite USB Audio)", "Windows WASAPI", 0, 2)])
    assert found[0].rank == BEST
    assert found[1].rank == found[2].rank == UNUSABLE
    assert found[1].text.startswith("cannot be used: inputs only") and "ASIO" in found[1].text
    assert found[2].text.startswith("cannot be used: outputs only")
