"""The Hardware page's device lists at 1280x720 and 1920x1080 (tools/screenshots.py --only hardware).

    QT_QPA_PLATFORM=offscreen .venv/bin/python tools/screenshots.py [OUTDIR] --only hardware

hardware-here-<W>x<H>.png: the sound cards PortAudio and the serial ports
pyserial find on the machine that runs this (a build server: few or none).
hardware-windows-example-<W>x<H>.png: the lists handed what a Windows PC with
a USB audio interface and the laser's USB serial adapter lists (names as
PortAudio and pyserial give them there), to show the host-API advice; an
example, not measured on Windows.
"""
from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QApplication

# A USB interface and the built-in card, as PortAudio lists them on Windows: full duplex under ASIO only,
# inputs and outputs apart under MME, DirectSound and WASAPI (MME cuts names at 31 characters).
WINDOWS_CARDS = (("Focusrite USB ASIO", "ASIO", 2, 2), ("Realtek ASIO", "ASIO", 2, 2),
                 ("Analogue 1 + 2 (Focusrite USB A", "MME", 2, 0), ("Speakers (Focusrite USB Audio)", "MME", 0, 2),
                 ("Analogue 1 + 2 (Focusrite USB Audio)", "Windows DirectSound", 2, 0),
                 ("Analogue 1 + 2 (Focusrite USB Audio)", "Windows WASAPI", 2, 0),
                 ("Speakers (Focusrite USB Audio)", "Windows WASAPI", 0, 2))


def windows_example():
    from instruments.audio.interface import AudioDeviceInfo
    from instruments.serial_ports import SerialPort
    cards = [AudioDeviceInfo(i, name, api, n_in, n_out, 48000.0) for i, (name, api, n_in, n_out)
             in enumerate(WINDOWS_CARDS)]
    ports = [SerialPort("COM7", "USB Serial Port (COM7)", "0403:6001", "A10K2B3C", "FTDI"),
             SerialPort("COM1", "Communications Port (COM1)", "")]
    return cards, ports


def hardware_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    from tools.screenshot_kit import grab_small_and_large, settle
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    wizard.driver_page.name_edit.setText("W18-PAPER")
    wizard.next_button.click()
    page = wizard.hardware_page
    page.laser_serial.setChecked(True)
    page.soundcard_radio.setChecked(True)
    for _ in range(100):            # the list PortAudio gives here (asked when the sound card was chosen)
        if not page.audio_jobs.busy:
            break
        settle(app, 100)
    page.on_refresh_ports()
    written = grab_small_and_large(app, window, out, "hardware-here")

    cards, ports = windows_example()
    page.on_devices(cards)
    page.device_list.setCurrentItem(page.device_list.topLevelItem(0))
    page.on_refresh_ports(ports)
    page.port_list.itemClicked.emit(page.port_list.topLevelItem(0), 0)
    settle(app)
    scroll = page.parentWidget().parentWidget()      # the wizard's QScrollArea (its viewport, then itself)
    written += grab_small_and_large(app, window, out, "hardware-windows-example",
                                    prepare=lambda: scroll.ensureWidgetVisible(page.port_list, 0, 40))
    return written
