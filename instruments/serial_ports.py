"""The serial ports this computer has, as its system names them (pyserial's list_ports), and an example name.

The laser's serial link reaches a PC through a USB adapter (RS422 to USB), so
its port is a USB serial port: COM3 on Windows, /dev/cu.usbserial-... on
macOS (the call-out device: the tty.* twin waits for a carrier that an RS422
adapter never gives), /dev/ttyUSB0 on Linux. The names below are examples the
Hardware page shows, never paths this program opens by itself.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass

PORT_EXAMPLES = {"win32": "COM3", "darwin": "/dev/cu.usbserial-…", "linux": "/dev/ttyUSB0"}


@dataclass(frozen=True, slots=True)
class SerialPort:
    device: str             # what to open: COM3, /dev/cu.usbserial-A1B2, /dev/ttyUSB0
    description: str        # what the driver says it is ("" when it says nothing)
    usb_id: str             # "VID:PID" in hex for a USB adapter, "" for a built-in port
    serial_number: str = ""
    manufacturer: str = ""

    @property
    def is_usb(self) -> bool:
        return bool(self.usb_id)


def port_example(platform: str | None = None) -> str:
    """A typical name of the laser's USB serial port on this system (``sys.platform`` unless given)."""
    platform = platform or sys.platform
    for prefix, example in PORT_EXAMPLES.items():
        if platform.startswith(prefix):
            return example
    return PORT_EXAMPLES["linux"]


def list_serial_ports() -> list[SerialPort]:
    """The serial ports pyserial finds, USB adapters first (the laser's is one), then by name."""
    from serial.tools import list_ports

    ports = []
    for info in list_ports.comports():
        usb_id = f"{info.vid:04X}:{info.pid:04X}" if info.vid is not None and info.pid is not None else ""
        description = "" if info.description in (None, "n/a", info.device) else str(info.description)
        ports.append(SerialPort(str(info.device), description, usb_id, str(info.serial_number or ""),
                                str(info.manufacturer or "")))
    return sorted(ports, key=lambda p: (not p.is_usb, p.device))
