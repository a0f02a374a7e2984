"""Klippel dB-Lab / LPM curve exports: |Z| or |Hx|, the measured curve beside Klippel's fitted one.

    "Magnitude of electric impedance Z(f)"                    title
    "Measured"		"Fitted"                                  column groups, one per curve
    "Frequency [Hz]"	"[Ohm]"	"Frequency [Hz]"	"[Ohm]"       units, a frequency/value pair per curve
    1.953125	6.1234	1.953125	6.1207                        numbers, tab separated

Each curve is its own frequency/value pair of columns, so the curves may
have different lines (a shorter fitted curve leaves its fields empty). The
measured curve is what linpar fits; the fitted one is kept as the tool's
reference (an overlay, and how far the tool's own model misses). The export
holds magnitudes only: the fit then uses |Z| and |Hx| alone, and says so.
Hx is in mm/V (also m/V or um/V, as the units line says).

Strict: a missing column, a unit it does not know, text where a number
belongs, or a file with a fitted curve only is refused with one line naming
the file and the line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.importers.errors import ImportFormatError
from analysis.importers.table import Dialect, Table, parse_number

_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_BRACKET = re.compile(r"\[([^\]]*)\]")
# The unit in a value column's brackets -> (curve kind, factor to SI).
VALUE_UNITS = {"ohm": ("impedance", 1.0), "ω": ("impedance", 1.0), "ohms": ("impedance", 1.0),
               "m/v": ("displacement", 1.0), "mm/v": ("displacement", 1e-3), "um/v": ("displacement", 1e-6),
               "µm/v": ("displacement", 1e-6), "μm/v": ("displacement", 1e-6)}
SI_NAMES = {"impedance": "Ohm", "displacement": "mm/V"}
MEASURED, FITTED = "measured", "fitted"


def recognises(text: str) -> bool:
    """True for a dB-Lab export: its first line a quoted title, a quoted 'Frequency [Hz]' before the numbers."""
    lines = [line.strip() for line in _LINE_BREAK.split(text[:4096]) if line.strip()]
    return (len(lines) >= 3 and lines[0].startswith('"') and lines[0].count('"') >= 2
            and any(line.startswith('"') and "frequency [hz]" in line.lower() for line in lines[1:6]))


@dataclass(frozen=True)
class LpmCurve:
    """One frequency/value pair of columns."""

    group: str                  # as the file names it ("Measured", "Fitted")
    freqs: np.ndarray
    values: np.ndarray          # SI
    lines: np.ndarray           # 1-based line of each value


@dataclass(frozen=True)
class LpmExport:
    path: Path
    title: str
    kind: str                   # "impedance" or "displacement"
    unit: str                   # the value unit as the file writes it
    measured: LpmCurve
    fitted: LpmCurve | None

    def table(self, curve: LpmCurve) -> Table:
        """The curve as a two-column table, so that the generic checks (bounds, increasing lines) apply."""
        return Table(self.path, np.column_stack([curve.freqs, curve.values]), curve.lines,
                     ("frequency", "magnitude"), None, (self.title,), Dialect("tab", False))


def _fields(line: str) -> list[str]:
    fields = [f.strip() for f in line.split("\t")]
    while fields and fields[-1] == "":
        fields.pop()
    return fields


def _unquoted(field: str) -> str:
    return field.strip().strip('"').strip()


def read_lpm(path: str | Path, text: str) -> LpmExport:
    """Parse a dB-Lab export (module doc). Raises ImportFormatError naming the file and the line."""
    path = Path(path)
    numbered = [(n, line) for n, line in enumerate(_LINE_BREAK.split(text), start=1) if line.strip()]
    data_start = next((i for i, (_, line) in enumerate(numbered) if not line.strip().startswith('"')), len(numbered))
    head = numbered[:data_start]
    title = _unquoted(head[0][1])
    units_at = next((i for i, (_, line) in enumerate(head) if "frequency [hz]" in line.lower()), None)
    if units_at is None or units_at == 0:
        raise ImportFormatError(path, head[0][0], "no units line (\"Frequency [Hz]\" \"[Ohm]\" ...): expected a "
                                "Klippel dB-Lab export's title, column groups and units")
    units_line, units_text = head[units_at]
    groups_line, groups_text = head[units_at - 1] if units_at >= 2 else (head[0][0], "")
    units = [_unquoted(f) for f in _fields(units_text)]
    if len(units) % 2 or not units:
        raise ImportFormatError(path, units_line, f"{len(units)} unit fields: expected a frequency and a value "
                                "column per curve (\"Frequency [Hz]\" \"[Ohm]\")")
    kind, unit, to_si = _value_unit(path, units_line, units)
    n_pairs = len(units) // 2
    groups = [_unquoted(f) for f in _fields(groups_text) if _unquoted(f)]
    if len(groups) != n_pairs:
        raise ImportFormatError(path, groups_line, f"{len(groups)} column groups ({', '.join(map(repr, groups))}) "
                                f"for {n_pairs} frequency/value pairs: expected one group name per curve "
                                "(\"Measured\", \"Fitted\")")
    roles = [MEASURED if g.lower().startswith("meas") else FITTED if g.lower().startswith("fit") else None
             for g in groups]
    if MEASURED not in roles:
        what = "only a fitted curve" if FITTED in roles else f"no measured curve among {', '.join(map(repr, groups))}"
        raise ImportFormatError(path, groups_line, f"{what}: expected a \"Measured\" column group (export the "
                                "measured curve with the fitted one)")
    columns = _columns(path, numbered[data_start:], 2 * n_pairs)
    curves = [_curve(path, groups[i], columns[2 * i], columns[2 * i + 1], to_si) for i in range(n_pairs)]
    measured = curves[roles.index(MEASURED)]
    fitted = curves[roles.index(FITTED)] if FITTED in roles else None
    return LpmExport(path, title, kind, unit, measured, fitted)


def _value_unit(path: Path, line: int, units: list[str]) -> tuple[str, str, float]:
    found = set()
    for i in range(0, len(units), 2):
        if units[i].lower() != "frequency [hz]":
            raise ImportFormatError(path, line, f"column {i + 1}: {units[i]!r}: expected \"Frequency [Hz]\" "
                                    "(a frequency column before each value column)")
        bracket = _BRACKET.search(units[i + 1])
        unit = bracket.group(1).strip() if bracket else units[i + 1]
        if unit.lower().replace(" ", "") not in VALUE_UNITS:
            raise ImportFormatError(path, line, f"column {i + 2}: unknown unit {unit!r}: expected [Ohm] for an "
                                    "impedance, or [mm/V], [m/V], [um/V] for Hx")
        found.add(unit)
    if len({VALUE_UNITS[u.lower().replace(' ', '')] for u in found}) > 1:
        raise ImportFormatError(path, line, f"mixed units {', '.join(sorted(found))}: expected one curve kind "
                                "per file")
    unit = found.pop()
    kind, to_si = VALUE_UNITS[unit.lower().replace(" ", "")]
    return kind, unit, to_si


def _columns(path: Path, rows: list[tuple[int, str]], n: int) -> list[list[tuple[int, float]]]:
    """Each column's (line, value) pairs; a curve that ends leaves its fields empty from then on."""
    if not rows:
        raise ImportFormatError(path, None, "no data rows: expected lines of numbers after the units line")
    columns: list[list[tuple[int, float]]] = [[] for _ in range(n)]
    ended = [False] * (n // 2)
    for line, text in rows:
        fields = _fields(text)
        if len(fields) > n:
            raise ImportFormatError(path, line, f"{len(fields)} columns where the units line names {n}")
        fields += [""] * (n - len(fields))
        for pair in range(n // 2):
            f, v = fields[2 * pair], fields[2 * pair + 1]
            if f == "" and v == "":
                ended[pair] = True
                continue
            if ended[pair]:
                raise ImportFormatError(path, line, f"columns {2 * pair + 1}-{2 * pair + 2}: a value after the "
                                        "curve's empty lines: expected each curve's lines together")
            if f == "" or v == "":
                raise ImportFormatError(path, line, f"column {2 * pair + (1 if f == '' else 2)} is missing: expected "
                                        "a frequency and a value for each curve")
            columns[2 * pair].append((line, parse_number(path, line, 2 * pair + 1, f, False)))
            columns[2 * pair + 1].append((line, parse_number(path, line, 2 * pair + 2, v, False)))
    return columns


def _curve(path: Path, group: str, freqs: list[tuple[int, float]], values: list[tuple[int, float]],
           to_si: float) -> LpmCurve:
    if len(freqs) < 2:
        raise ImportFormatError(path, None, f"the {group!r} curve has {len(freqs)} lines: expected a curve")
    lines = np.array([line for line, _ in freqs])
    return LpmCurve(group, np.array([v for _, v in freqs]), np.array([v for _, v in values]) * to_si, lines)
