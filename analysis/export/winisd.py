"""The driver as a WinISD driver file (.wdr), for box design.

Why WinISD: it is the most widely used free box-design program, and its
driver file is plain INI-style text (Windows GetPrivateProfileString), which
any tool can write and a person can read and check.

The file, as written here:

- Windows text: CRLF line ends, Windows-1252 (characters it lacks become
  '?'), '.' as decimal point whatever the locale, one `key=value` per line.
- Section [Driver]: the identification (Brand, Model, Comment) and the
  Thiele-Small parameters in SI units, as WinISD keeps them internally (its
  driver editor shows customary units and converts):

  | key    | unit   | value written                                   |
  |--------|--------|-------------------------------------------------|
  | Brand  | text   | the driver name's first word (manufacturer)     |
  | Model  | text   | the driver name (and serial number)             |
  | Comment| text   | who measured, when, validity, the model         |
  | Re     | ohm    | RE                                              |
  | Le     | H      | LE                                              |
  | fs     | Hz     | fs                                              |
  | Qms    | -      | Qms                                             |
  | Qes    | -      | Qes                                             |
  | Qts    | -      | Qts                                             |
  | Bl     | T*m    | Bl                  (only with the laser)       |
  | Mms    | kg     | Mms                 (only with the laser)       |
  | Cms    | m/N    | Cms                 (only with the laser)       |
  | Rms    | kg/s   | Rms                 (only with the laser)       |
  | Vas    | m^3    | Vas                 (laser and Sd)              |
  | Sd     | m^2    | Sd                  (when known)                |
  | Dia    | m      | sqrt(4 Sd / pi), the piston diameter (when Sd is known) |
  | no     | -      | eta0, the reference efficiency as a fraction (laser and Sd) |
  | SPL    | dB     | SPL at 1 W, 1 m     (laser and Sd)              |
  | USPL   | dB     | SPL at 2.83 V, 1 m  (laser and Sd)              |
  | EBP    | Hz     | fs / Qes, the efficiency bandwidth product      |

  A parameter this measurement could not identify is left out, never
  written as 0: WinISD then asks for it or derives it (e.g. from fs, Qes
  and Vas). Xmax, Pe and Znom are not measured here and are not written.

- Section [linpar]: what the linear model has beyond Thiele-Small, in SI,
  for the programs (and people) that use it: `Effects` (the effect ids),
  the eddy-current inductance L2 [H] and R2 [ohm] (LR-2), the Leach
  semi-inductance `K` [ohm*s^n] and `n` [-] (Z_L = K (j w)^n), the creep
  factor `lambda`, and `Validity`. WinISD's model has a plain Le and no
  semi-inductance, so it ignores this section (INI readers skip sections
  they do not ask for); the Le in [Driver] is the fitted LE alone.

The format description above is from WinISD's driver files as distributed
and written by WinISD 0.7; the test (tests/analysis/test_export_driver.py)
checks every field against this table.
"""
from __future__ import annotations

import math
from typing import Mapping

from analysis.archive.results import StoredResult

ENCODING = "cp1252"
NEWLINE = "\r\n"

# (key, parameter name in the result, SI unit): written when the parameter has a value.
DRIVER_FIELDS: tuple[tuple[str, str, str], ...] = (
    ("Re", "RE", "ohm"), ("Le", "LE", "H"), ("fs", "fs", "Hz"), ("Qms", "Qms", "1"), ("Qes", "Qes", "1"),
    ("Qts", "Qts", "1"), ("Bl", "Bl", "T*m"), ("Mms", "Mms", "kg"), ("Cms", "Cms", "m/N"), ("Rms", "Rms", "kg/s"),
    ("Vas", "Vas", "m^3"), ("no", "eta0", "1"), ("SPL", "SPL_1W_1m", "dB"), ("USPL", "SPL_2.83V_1m", "dB"),
)
# Extra model parameters carried in [linpar]: (key, fitted parameter, SI unit).
LINPAR_FIELDS: tuple[tuple[str, str, str], ...] = (
    ("L2", "L2", "H"), ("R2", "R2", "ohm"), ("L3", "L3", "H"), ("R3", "R3", "ohm"),
    ("K", "K", "ohm*s^n"), ("n", "n", "1"), ("lambda", "lambda", "1"),
)


def _clean(text: str) -> str:
    """One line of Windows-1252 text: a line break in a name would start a new key in the file."""
    one_line = " ".join(str(text).split())
    return one_line.encode(ENCODING, errors="replace").decode(ENCODING)


def _number(value: float) -> str:
    return repr(float(value))


def _value(result: StoredResult, name: str) -> float | None:
    p = result.parameters.get(name)
    if p is None or p.value is None or not math.isfinite(p.value):
        return None
    return float(p.value)


def wdr_text(result: StoredResult, header: Mapping | None = None) -> str:
    header = dict(header or {})
    name = str(header.get("driver") or "linpar measurement")
    serial = str(header.get("serial") or "")
    comment = "; ".join(x for x in (
        f"measured by linpar {header.get('measured_at', '')}".strip(),
        f"operator {header['operator']}" if header.get("operator") else "",
        f"station {header['station']}" if header.get("station") else "",
        f"validity {result.overall}",
        "model " + (",".join(result.effects) or "textbook")) if x)
    lines = ["[Driver]", f"Brand={_clean(name.split()[0] if name.split() else name)}",
             f"Model={_clean(name + (' ' + serial if serial else ''))}", f"Comment={_clean(comment)}"]
    for key, param, _unit in DRIVER_FIELDS:
        value = _value(result, param)
        if value is not None:
            lines.append(f"{key}={_number(value)}")
    if result.sd_m2:
        lines.append(f"Sd={_number(result.sd_m2)}")
        lines.append(f"Dia={_number(math.sqrt(4 * result.sd_m2 / math.pi))}")
    fs, qes = _value(result, "fs"), _value(result, "Qes")
    if fs is not None and qes:
        lines.append(f"EBP={_number(fs / qes)}")
    lines += ["", "[linpar]", f"Effects={','.join(result.effects) or 'none'}", f"Validity={result.overall}"]
    for key, param, _unit in LINPAR_FIELDS:
        value = result.values.get(param)
        if value is not None and math.isfinite(value):
            lines.append(f"{key}={_number(value)}")
    return NEWLINE.join(lines) + NEWLINE


def wdr_bytes(result: StoredResult, header: Mapping | None = None) -> bytes:
    return wdr_text(result, header).encode(ENCODING, errors="replace")
