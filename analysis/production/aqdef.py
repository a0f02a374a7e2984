"""Q-DAS AQDEF (.dfq): the selected population for a quality department's SPC software (qs-STAT, procella ...).

Written from public descriptions of the format (docs/production.md names them):
Hexagon's Q-DAS data-format pages (the K-field lists K1xxx part, K2xxx
characteristic, K00xx value and their defined contents) and published .dfq
examples. A .dfq is the description (K1xxx, K2xxx) and the values (K00xx) in
one text file, one K-field per line, "Kxxxx/i value", i the characteristic
(or part) the field belongs to. Values are written as K-fields too (not the
binary-separated value lines), one block K0001/1 ... K0001/n per unit.

    K0100      number of characteristics in the file
    K1001/p    part number (the driver)            K1002/p  part description
    K2001/i    characteristic number (parameter)   K2002/i  its description
    K2004/i    characteristic type: 0 variable     K2142/i  unit
    K2101/i    nominal (centre of two limits)      K2110/i, K2111/i  lower, upper specification limit
    K0001/i    the value                           K0002/i  attribute: 0 valid, 129 invalid (shown, not
                                                            counted: a red or unjudgeable measurement),
                                                            255 placeholder (not measured)
    K0004/i    date/time DD.MM.YYYY/HH:MM:SS (UTC)  K0014/i  part ident (the serial number)
    K0009/i    text: the linpar id, station and operator

Values and limits are in the parameters' customary units (Hz, ohm, mH, g, mm/N, ...),
in ASCII spellings. The file is Windows-1252 with CRLF line ends, as the
Windows tools expect; a character it cannot hold becomes '?'.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from analysis.errors import LinparError
from analysis.text_boundary import cleaned, spreadsheet_cell

ENCODING = "cp1252"
VALID, INVALID, PLACEHOLDER = 0, 129, 255
LENGTHS = {"K1001": 30, "K1002": 80, "K2001": 40, "K2002": 80, "K2142": 20, "K0014": 40, "K0009": 255}
DESCRIPTIONS = {"RE": "Voice-coil resistance RE", "LE": "Voice-coil inductance LE", "fs": "Resonance frequency fs",
                "Bl": "Force factor Bl", "Mms": "Moving mass Mms", "Cms": "Suspension compliance Cms",
                "Rms": "Mechanical resistance Rms", "Qms": "Mechanical Q Qms", "Qes": "Electrical Q Qes",
                "Qts": "Total Q Qts", "Vas": "Equivalent volume Vas", "SPL_2.83V_1m": "Sensitivity 2.83 V / 1 m"}
_ASCII_UNITS = {"Ω": "Ohm", "ohm": "Ohm", "µ": "u", "μ": "u", "·": "*", "²": "^2", "³": "^3"}
_LINE = re.compile(r"^K(\d{4})(?:/(\d+))?(?: (.*))?$")


def _text(value, key: str) -> str:
    # One line per K-field, and no cell a spreadsheet would run as a formula when the .dfq is opened as text.
    return spreadsheet_cell(cleaned(str(value), 10**6))[: LENGTHS.get(key, 255)]


def ascii_unit(unit: str) -> str:
    for a, b in _ASCII_UNITS.items():
        unit = unit.replace(a, b)
    return "" if unit in ("-", "1") else unit


def _number(value: float) -> str:
    return f"{value:.10g}"


def _date(iso: str) -> str:
    """'2024-05-01T10:00:00Z' -> '01.05.2024/10:00:00'."""
    day, _, time = iso.rstrip("Z").partition("T")
    y, m, d = day.split("-")
    return f"{d}.{m}.{y}/{(time or '00:00:00')[:8]}"


def write_dfq(population, stats_parameters, excluded_ids=()) -> str:
    """The .dfq text of a population (analysis.archive.population.Population): one part per driver, one
    characteristic per parameter of `stats_parameters` (name -> analysis.production.summary.ParameterStats,
    which carry the units and the limits)."""
    excluded = set(excluded_ids)
    drivers = list(dict.fromkeys(population.drivers)) or ["linpar"]
    names = list(stats_parameters)
    lines = [f"K0100 {len(drivers) * len(names)}"]
    for p, driver in enumerate(drivers):
        first = p * len(names) + 1
        lines += [f"K1001/{p + 1} {_text(driver or 'unnamed driver', 'K1001')}",
                  f"K1002/{p + 1} {_text(f'loudspeaker driver {driver}, linpar parameters', 'K1002')}"]
        for c, name in enumerate(names):
            ps, i = stats_parameters[name], first + c
            lines += [f"K2001/{i} {_text(name, 'K2001')}",
                      f"K2002/{i} {_text(DESCRIPTIONS.get(name, name), 'K2002')}",
                      f"K2004/{i} 0"]
            low, high = (None if v is None else v * ps.display_scale
                         for v in (ps.capability.low, ps.capability.high))
            if ps.display_scale < 0:
                low, high = high, low
            if low is not None and high is not None:
                lines.append(f"K2101/{i} {_number((low + high) / 2)}")
            lines += [f"{key}/{i} {_number(v)}" for key, v in (("K2110", low), ("K2111", high)) if v is not None]
            lines.append(f"K2142/{i} {_text(ascii_unit(ps.display_unit), 'K2142')}")
        for u, mid in enumerate(population.ids):
            if population.drivers[u] != driver:
                continue
            about = f"linpar {mid} station {population.stations[u]} operator {population.operators[u]}"
            for c, name in enumerate(names):
                i, value = first + c, population.value(name, u)
                attribute = (PLACEHOLDER if value is None else
                             INVALID if mid in excluded or population.validity[u] == "red" else VALID)
                shown = 0.0 if value is None else value * stats_parameters[name].display_scale
                lines += [f"K0001/{i} {_number(shown)}", f"K0002/{i} {attribute}",
                          f"K0004/{i} {_date(population.measured_at[u])}",
                          f"K0014/{i} {_text(population.serials[u], 'K0014')}",
                          f"K0009/{i} {_text(about, 'K0009')}"]
    return "\r\n".join(lines) + "\r\n"


def encode(text: str) -> bytes:
    return text.encode(ENCODING, errors="replace")


@dataclass
class Dfq:
    """What read_dfq finds: part and characteristic fields by index, and the value records in order."""

    characteristics_count: int = 0
    parts: dict[int, dict[str, str]] = field(default_factory=dict)
    characteristics: dict[int, dict[str, str]] = field(default_factory=dict)
    values: list[dict[int, dict[str, str]]] = field(default_factory=list)   # per unit: characteristic -> fields


class DfqFormatError(LinparError, ValueError):
    """A .dfq line that read_dfq cannot read."""


def read_dfq(data: bytes) -> Dfq:
    """Read K-field lines (the subset write_dfq writes) back; DfqFormatError on a line that is none."""
    out, record = Dfq(), None
    part, part_of = 0, {}           # the part each characteristic was declared under
    for n, line in enumerate(data.decode(ENCODING).split("\r\n"), 1):
        if not line:
            continue
        m = _LINE.match(line)
        if m is None:
            raise DfqFormatError(f"line {n}: not a K-field line: {line[:40]!r}")
        key, index, value = f"K{m.group(1)}", int(m.group(2) or 0), m.group(3) or ""
        if key == "K0100":
            out.characteristics_count = int(value)
        elif key.startswith("K1"):
            out.parts.setdefault(index, {})[key] = value
            part = index
        elif key.startswith("K2"):
            out.characteristics.setdefault(index, {})[key] = value
            part_of.setdefault(index, part)
        elif key.startswith("K0"):
            # A unit's values: K0001 of each characteristic once; a repeated one, or one of another part,
            # begins the next unit.
            if key == "K0001" and (record is None or index in record
                                   or part_of.get(index) != part_of.get(next(iter(record), index))):
                record = {}
                out.values.append(record)
            if record is None:
                raise DfqFormatError(f"line {n}: {key} before any K0001 value")
            record.setdefault(index, {})[key] = value
    return out
