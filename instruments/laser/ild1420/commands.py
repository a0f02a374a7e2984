"""The ILD1420's ASCII commands: their names, their parameters, their replies.

The names follow the manual as quoted in docs/laser-protocol.md
(GETINFO, MEASRATE, OUTPUT, GETOUTINFO_RS422, RESETCNT). The spec does not
name the command that adds the counter and time stamp to the RS422 output;
we use OUTADD_RS422, the manual family's spelling. Every name lives here
once, shared by the driver and the emulator, so a firmware that spells one
differently is a one-line change.
"""

from __future__ import annotations

import re

from analysis.bounds import LASER_RANGE_M
from instruments.laser.ild1420.frames import Reply, value_slots
from instruments.laser.sensor import LaserError, SensorInfo

GETINFO = "GETINFO"
MEASRATE = "MEASRATE"
OUTPUT = "OUTPUT"
OUTPUT_ADD = "OUTADD_RS422"
OUTPUT_INFO = "GETOUTINFO_RS422"
RESET_COUNTER = "RESETCNT"

OUTPUT_ON = f"{OUTPUT} RS422"
OUTPUT_OFF = f"{OUTPUT} NONE"

#: The sensor's factory setting.
DEFAULT_BAUDRATE = 921_600
#: Measuring rates the sensor offers.
RATES_HZ = (250.0, 500.0, 1000.0, 2000.0, 4000.0)
#: Measuring ranges of the ILD1420 family.
MEASURING_RANGES_MM = (10, 25, 50, 100, 200, 500)
#: Spec: baud [kBd] > 33 * rate [kHz] * values per measurement.
_BITS_PER_VALUE_KBD = 33

#: Parameter words of OUTADD_RS422 and the tokens GETOUTINFO_RS422 lists.
_ADD_WORDS = {"counter": "COUNTER", "timestamp": "TIMESTAMP"}


def check_rate(rate_hz: float) -> None:
    if float(rate_hz) not in RATES_HZ:
        allowed = ", ".join(f"{r:g}" for r in RATES_HZ)
        raise LaserError(f"the ILD1420 cannot measure at {rate_hz:g} Hz; it offers {allowed} Hz")


def check_bandwidth(baudrate: int, rate_hz: float, values_per_measurement: int) -> None:
    """Refuse a rate the serial line cannot carry (the sensor would send
    error 262075 instead of distances)."""
    baud_kbd = baudrate / 1000.0
    needed_kbd = _BITS_PER_VALUE_KBD * (rate_hz / 1000.0) * values_per_measurement
    if not baud_kbd > needed_kbd:
        raise LaserError(
            f"{baud_kbd:g} kBd is too slow for {rate_hz / 1000.0:g} kHz with "
            f"{values_per_measurement} values per measurement: it needs more than "
            f"{needed_kbd:g} kBd (33 x {rate_hz / 1000.0:g} kHz x {values_per_measurement}); "
            "lower the rate, send fewer values or raise the baud rate")


def check_configuration(baudrate: int, rate_hz: float, outputs: tuple[str, ...]) -> None:
    """What ``configure(rate_hz, outputs)`` must refuse before anything is sent,
    the same for the driver and the simulation: a rate the sensor does not
    offer, an unknown output, more than the line can carry."""
    check_rate(rate_hz)
    try:
        slots = value_slots(tuple(outputs))
    except ValueError as exc:
        raise LaserError(str(exc)) from exc
    check_bandwidth(baudrate, rate_hz, len(slots))


def measrate_command(rate_hz: float) -> str:
    """MEASRATE takes kHz: 'MEASRATE 0.25' ... 'MEASRATE 4'."""
    return f"{MEASRATE} {rate_hz / 1000.0:g}"


def output_add_command(outputs: tuple[str, ...]) -> str:
    """'OUTADD_RS422 COUNTER TIMESTAMP', or 'OUTADD_RS422 NONE' for the
    distance alone (the distance itself is always sent)."""
    value_slots(outputs)  # validates
    words = [_ADD_WORDS[name] for name in ("counter", "timestamp") if name in outputs]
    return f"{OUTPUT_ADD} {' '.join(words) if words else 'NONE'}"


def output_info_line(outputs: tuple[str, ...]) -> str:
    """What GETOUTINFO_RS422 answers (the emulator says it this way)."""
    value_slots(outputs)
    names = ["DISTANCE"] + [_ADD_WORDS[n] for n in ("counter", "timestamp") if n in outputs]
    return " ".join(names)


def parse_output_info(reply: Reply) -> tuple[str, ...]:
    """The outputs listed by GETOUTINFO_RS422, in sensor order."""
    found: list[str] = []
    for token in re.split(r"[\s,;]+", " ".join(reply.body).upper()):
        name = ("distance" if token.startswith("DIST") else
                "counter" if token.startswith("COUNT") else
                "timestamp" if token.startswith("TIME") else None)
        if name and name not in found:
            found.append(name)
    if "distance" not in found:
        raise LaserError(f"cannot read the output list from {OUTPUT_INFO}: {reply.body!r}")
    return tuple(found)


def parse_info(reply: Reply) -> SensorInfo:
    """SensorInfo from GETINFO's 'Key: value' lines. The measuring range is
    read from a 'Measuring range' line, else from the name (ILD1420-10)."""
    fields: dict[str, str] = {}
    for line in reply.body:
        key, sep, value = line.partition(":")
        if sep:
            fields[key.strip().lower()] = value.strip()
    name = fields.get("name", "")
    if not name:
        raise LaserError(f"GETINFO did not give a sensor name: {reply.text!r}")
    range_text = fields.get("measuring range") or fields.get("range") or ""
    match = re.search(r"(\d+(?:\.\d+)?)", range_text) or re.search(r"-(\d+)\b", name)
    if not match:
        raise LaserError(f"cannot tell the measuring range of {name!r} from GETINFO")
    # A range of 0 would divide every distance by zero; the reply is checked against its bound where it enters.
    measuring_range = LASER_RANGE_M.check(float(match.group(1)) / 1000.0, f"GETINFO of {name!r}: measuring range",
                                          LaserError)
    return SensorInfo(
        name=name,
        serial=fields.get("serial", fields.get("serial number", "")),
        measuring_range_m=measuring_range,
        firmware=fields.get("version", fields.get("firmware", "")),
        text=reply.text,
    )
