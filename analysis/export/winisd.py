"""The driver as a WinISD driver file (.wdr), for box design.

Why WinISD: it is the most widely used free box-design program, and its
driver file is plain INI-style text that a person can read and check.
WinISD publishes no description of the format. What is written here follows
real files and a public reverse-engineering of them, all in the public
repository github.com/Johnlon/openisd (OpenISD, a browser clone of WinISD):

- a file WinISD 0.7.0.950 itself wrote after every field was typed in it:
  drivers/sample/john-all-noncalc-fields-manually-entered.wdr, and a blank
  one, drivers/sample/driver-with-latin-text.wdr;
- driver-database files entered by hand in WinISD, e.g.
  "drivers/B&C 12PS100.wdr", "drivers/Eminence 2510.wdr" (same 56 keys, in
  the same order);
- docs/design/WINISD_SCHEMA.md (keys, units, the ParState string, WinISD's
  relations between fields, read from WinISD's binary and its help files),
  docs/research/UNIT_BOUNDARY_AUDIT.md (file unit against the unit WinISD
  shows, field by field), drivers/sample/README.md (ParState slot probes),
  packages/winisd/src/parstate.ts and packages/winisd/test/wdrBytes.test.ts.

The file, as written here:

- One section, [Driver], on the first line; one `Key=Value` per line, no
  spaces; all 56 keys WinISD writes, in WinISD's order (DRIVER_KEYS), the
  edit-state string `ParState` last. Keys are case-sensitive: `Fs`, `BL`.
- Values in SI, '.' as decimal point, numbers as WinISD's own writer spells
  them: plain decimals, an 'E' exponent below 1e-5 (8.81202645607949E-6).
- Text UTF-8 (WinISD's own file with a Euro sign and Kanji is UTF-8), CRLF.
  Names and the comment stay on one line (WinISD codes a line break inside a
  value as the byte 0xA4; we write none).
- `ParState`: 49 characters, one per WinISD parameter in WinISD's internal
  order (PARSTATE_SLOTS): E entered, C calculated by WinISD, N not set.
  A file without it would mark all 49 entered and pin zeros, so it is
  always written. A field this measurement cannot give is written the way
  WinISD writes a field nobody set: value 0, mark N. WinISD may then derive
  it (or wait for it) instead of taking 0 as a measured value.

  | key   | unit     | value written (mark)                                         |
  |-------|----------|--------------------------------------------------------------|
  | Brand | text     | first word of the driver name                                |
  | Model | text     | the rest of the name, and the serial number                  |
  | ProvidedBy | text | linpar, operator, station                                  |
  | Comment | text   | date, validity, model; where the full model is              |
  | DateAdded | text | YYYYMMDD of the measurement (empty if unknown)              |
  | DateModified | text | the same                                                 |
  | Qts   | 1        | Qts (C)                                                      |
  | Fs    | Hz       | fs (E)                                                       |
  | Re    | ohm      | RE (E)                                                       |
  | Le    | H        | LE; with a lossy coil Im(Ze - RE)/w at fLe (E)               |
  | fLe   | Hz       | 1 kHz (or the top of the band), lossy coil models only (E)   |
  | KLe   | H*Hz^0.5 | Le*sqrt(2 pi fLe), WinISD's semi-inductance (C)              |
  | BL    | T*m      | Bl (E), laser only                                           |
  | Cms   | m/N      | Cms (E), laser only                                          |
  | Qms   | 1        | Qms (E)                                                      |
  | Qes   | 1        | Qes (E)                                                      |
  | Rms   | kg/s     | Rms (E), laser only                                          |
  | Mms   | kg       | Mms (E), laser only                                          |
  | Sd    | m^2      | Sd (E), when given                                           |
  | Vas   | m^3      | Vas (E), laser and Sd                                        |
  | no    | 1        | eta0, a fraction (C), laser and Sd                           |
  | Dd    | m        | 2 sqrt(Sd/pi), the piston diameter (C)                       |
  | SPL   | dB       | SPL at 1 W, 1 m, half space (C), laser and Sd                |
  | USPL  | dB       | SPL at 2.83 V, 1 m (C), laser and Sd                         |
  | EBP   | Hz       | fs/Qes (C)                                                   |
  | numVC | 1        | 1 (E, as WinISD marks a new driver)                          |
  | VCCon | 1        | 1, parallel (no ParState mark: WinISD never sets one)        |
  | c     | m/s      | 343, the speed of sound linpar used (E)                      |
  | roo   | kg/m^3   | 1.18, the air density linpar used for Vas and eta0 (E)       |

  Every other key (Znom, Pe, Xmax, Vd, Dia, Hc, Hg, SPLmax, SPLmaxLF,
  alfaVC, Rt, Ct, gamma, Rme, Mpow, Mcost, Gloss and the dimensions) is 0, N:
  not measured here. E marks what the measurement states; C marks WinISD's
  own formulas of those values, so WinISD keeps them consistent when a user
  edits an input. c and roo are written so WinISD's Vas = roo c^2 Sd^2 Cms and
  its eta0 agree with ours (WinISD otherwise takes its own environment).

Semi-inductance. WinISD's lossy-coil model is the three fields Le, fLe, KLe
with KLe = Le*sqrt(2 pi fLe) (read from WinISD's calculation engine): a
semi-inductance KLe*sqrt(jw), n = 1/2, with the same |Z| as the inductance Le
at fLe; fLe = KLe = 0 keeps the plain Le (WINISD_SCHEMA.md section 3.2).
WinISD has no field for LR-2
(L2, R2), for Leach's free exponent n or for creep. So linpar writes Le as the
fitted coil's series inductance at fLe (the 'Le at 1 kHz' of data sheets),
and, when the fitted model has a lossy-inductance effect, fLe and KLe.
With the textbook model Le = LE and fLe = KLe = 0. The full model (LE, L2, R2,
K, n, lambda, with uncertainties) is in the JSON export, not here: WinISD's
files have no other section, and WinISD writes only its own keys when it
saves (WINISD_SCHEMA.md), so anything more would be lost on the first save.

Not confirmed by any public source: CRLF line ends (the copies we could read
are line-normalised); whether WinISD reads a non-ASCII UTF-8 name back as
written; that WinISD uses KLe*sqrt(jw) in place of jwLe when fLe, KLe are set
and the plain Le when they are 0 (its help is said to use the coil's
inductance for the impedance curve only, not for SPL); that WinISD reads
numbers written with 17 digits (its own writer uses 15); how WinISD treats a
file without Vas (no laser), which cannot be simulated, while OpenISD reports
WinISD crashing on some sparse drivers. Nobody has opened this exporter's
files in WinISD for this project. The test
(tests/analysis/export/test_export_driver.py) checks every field against the real
files' key list and units.
"""
from __future__ import annotations

import math
import re
from decimal import Decimal
from typing import TYPE_CHECKING, Mapping

import numpy as np

from analysis.derived import C_SOUND, RHO
from analysis.export.registry import Exporter

if TYPE_CHECKING:      # a type only: listing the formats (the CLI's parser) loads no archive
    from analysis.archive.results import StoredResult

ENCODING = "utf-8"
NEWLINE = "\r\n"
REFERENCE_LE_HZ = 1000.0

# The keys, in the order WinISD writes them, with their SI unit ("text" for strings).
DRIVER_KEYS: tuple[tuple[str, str], ...] = (
    ("Brand", "text"), ("Model", "text"), ("Manufacturer", "text"), ("ProvidedBy", "text"),
    ("Comment", "text"), ("DateAdded", "text"), ("DateModified", "text"),
    ("Qts", "1"), ("Znom", "ohm"), ("Fs", "Hz"), ("Pe", "W"), ("SPL", "dB"), ("Re", "ohm"), ("Le", "H"),
    ("fLe", "Hz"), ("KLe", "H*Hz^0.5"), ("BL", "T*m"), ("Xmax", "m"), ("Cms", "m/N"), ("Qms", "1"), ("Qes", "1"),
    ("Rms", "kg/s"), ("Mms", "kg"), ("Sd", "m^2"), ("Vas", "m^3"), ("Dia", "m"), ("Vd", "m^3"), ("no", "1"),
    ("Dd", "m"), ("EBP", "Hz"), ("numVC", "1"), ("Hc", "m"), ("Hg", "m"), ("SPLmax", "dB"), ("SPLmaxLF", "dB"),
    ("USPL", "dB"), ("alfaVC", "1/K"), ("Rt", "K/W"), ("Ct", "J/K"), ("gamma", "N/(A*kg)"), ("Rme", "N*s/m"),
    ("Mpow", "N/W^0.5"), ("Mcost", "N*s/m"), ("Gloss", "1"), ("VCCon", "1"), ("c", "m/s"), ("roo", "kg/m^3"),
    ("Thick", "m"), ("Depth", "m"), ("MagDepth", "m"), ("Magnet", "m"), ("Basket", "m"), ("Outer", "m"),
    ("Vcd", "m"), ("DVol", "m^3"), ("ParState", "text"),
)
# ParState's 49 slots in WinISD's internal order; slot 10 (Xlim) has no key in the file.
PARSTATE_SLOTS: tuple[str | None, ...] = (
    "Znom", "Fs", "Pe", "SPL", "Re", "Le", "fLe", "KLe", "BL", "Xmax", None, "Cms", "Qms", "Qes", "Qts",
    "Rms", "Mms", "Sd", "Vd", "Vas", "Dia", "Dd", "no", "numVC", "Hc", "Hg", "SPLmax", "SPLmaxLF", "USPL",
    "alfaVC", "Rt", "Ct", "gamma", "EBP", "Rme", "Mpow", "Mcost", "Gloss", "Thick", "Depth", "MagDepth",
    "Magnet", "Basket", "Outer", "Vcd", "DVol", "VCCon", "c", "roo",
)
# (WinISD key, linpar parameter, ParState mark), written when the parameter has a value.
PARAMETER_FIELDS: tuple[tuple[str, str, str], ...] = (
    ("Qts", "Qts", "C"), ("Fs", "fs", "E"), ("Re", "RE", "E"), ("BL", "Bl", "E"), ("Cms", "Cms", "E"),
    ("Qms", "Qms", "E"), ("Qes", "Qes", "E"), ("Rms", "Rms", "E"), ("Mms", "Mms", "E"), ("Vas", "Vas", "E"),
    ("no", "eta0", "C"), ("SPL", "SPL_1W_1m", "C"), ("USPL", "SPL_2.83V_1m", "C"),
)
# WinISD's own value for a key nobody set (drivers/sample/driver-with-latin-text.wdr): 0, except these.
DEFAULTS = {"numVC": "1", "VCCon": "1"}
TEXT_KEYS = frozenset(k for k, unit in DRIVER_KEYS if unit == "text")


def _clean(text: str) -> str:
    """One line: a line break in a name would start a new key in the file."""
    return " ".join(str(text).split())


def _number(value: float) -> str:
    """Shortest round trip, spelled as WinISD's writer does: 0.0000159790990485196, 8.81202645607949E-6."""
    text = repr(float(value))
    if "e" not in text:
        return text[:-2] if text.endswith(".0") else text
    mantissa, exponent = text.split("e")
    if int(exponent) < -5 or int(exponent) > 14:
        return f"{mantissa}E{int(exponent)}"
    return format(Decimal(text), "f")


def _value(result: StoredResult, name: str) -> float | None:
    p = result.parameters.get(name)
    if p is None or p.value is None or not math.isfinite(p.value):
        return None
    return float(p.value)


def _has_lossy_coil(result: StoredResult) -> bool:
    try:
        return any(e.category == "inductance" for e in result.model().effects)
    except KeyError:          # an effect this version no longer knows: its coil cannot be evaluated
        return False


def _le_frequency(result: StoredResult) -> float:
    """1 kHz, or the top of the measured band below it: the model is not extrapolated."""
    curve = result.curves.get("impedance")
    return REFERENCE_LE_HZ if curve is None else min(REFERENCE_LE_HZ, float(np.max(curve.freqs)))


def inductance_at(result: StoredResult, f_hz: float) -> float | None:
    """Im(Ze - RE) / w of the fitted blocked impedance: the coil's series inductance at f_hz [H]."""
    w = 2 * np.pi * f_hz
    try:
        ze = result.model().blocked_impedance(np.array([1j * w]), result.values)[0]
    except KeyError:
        return None
    le = float(ze.imag) / w
    return le if math.isfinite(le) and le > 0 else None


def _date(header: Mapping) -> str:
    m = re.match(r"(\d{4})-(\d{2})-(\d{2})", str(header.get("measured_at") or ""))
    return "".join(m.groups()) if m else ""


def _header_fields(result: StoredResult, header: Mapping) -> dict[str, str]:
    words = str(header.get("driver") or "").split()
    brand, model = (words[0], words[1:]) if len(words) > 1 else ("", words)
    serial = str(header.get("serial") or "")
    model_text = " ".join(model + ([serial] if serial else [])) or "linpar measurement"
    who = ", ".join(str(header[k]) for k in ("operator", "station") if header.get(k))
    comment = "; ".join(x for x in (
        f"measured by linpar {header.get('measured_at') or ''}".strip(),
        f"validity {result.overall}",
        "model " + (",".join(result.effects) or "textbook"),
        "Le is the coil's inductance at fLe; the full model is in the linpar JSON export") if x)
    date = _date(header)
    return {"Brand": _clean(brand), "Model": _clean(model_text), "Manufacturer": "",
            "ProvidedBy": _clean("linpar" + (f" ({who})" if who else "")), "Comment": _clean(comment),
            "DateAdded": date, "DateModified": date}


def wdr_fields(result: StoredResult, header: Mapping | None = None) -> dict[str, str]:
    """Key -> text as written, for every key WinISD writes (ParState included)."""
    values: dict[str, float] = {}
    marks: dict[str, str] = {"numVC": "E"}     # WinISD marks numVC entered on every new driver
    for key, param, mark in PARAMETER_FIELDS:
        v = _value(result, param)
        if v is not None:
            values[key], marks[key] = v, mark
    f_le = _le_frequency(result)
    le = inductance_at(result, f_le) if _has_lossy_coil(result) else None
    if le is not None:
        values["Le"], values["fLe"], values["KLe"] = le, f_le, le * math.sqrt(2 * math.pi * f_le)
        marks.update(Le="E", fLe="E", KLe="C")
    elif (le := _value(result, "LE")) is not None:
        values["Le"], marks["Le"] = le, "E"
    if result.sd_m2:
        values["Sd"], marks["Sd"] = result.sd_m2, "E"
        values["Dd"], marks["Dd"] = 2 * math.sqrt(result.sd_m2 / math.pi), "C"
    if values.get("Fs") and values.get("Qes"):
        values["EBP"], marks["EBP"] = values["Fs"] / values["Qes"], "C"
    values["c"], marks["c"] = C_SOUND, "E"
    values["roo"], marks["roo"] = RHO, "E"

    text = _header_fields(result, dict(header or {}))
    for key, _unit in DRIVER_KEYS:
        if key not in TEXT_KEYS:
            text[key] = _number(values[key]) if key in values else DEFAULTS.get(key, "0")
    text["ParState"] = "".join(marks.get(slot, "N") if slot else "N" for slot in PARSTATE_SLOTS)
    return text


def wdr_text(result: StoredResult, header: Mapping | None = None) -> str:
    text = wdr_fields(result, header)
    lines = ["[Driver]"] + [f"{key}={text[key]}" for key, _unit in DRIVER_KEYS]
    return NEWLINE.join(lines) + NEWLINE


def wdr_bytes(result: StoredResult, header: Mapping | None = None) -> bytes:
    return wdr_text(result, header).encode(ENCODING)


EXPORTERS = (Exporter("driver", "WinISD driver file", ".wdr", wdr_bytes, rank=30),)
