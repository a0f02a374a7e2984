"""What the columns of an imported curve mean: names, roles and the phase unit.

A header (the line just before the data) names the columns; without one the
order is the .zma/.frd convention: frequency, magnitude[, phase]. The phase
unit comes from the header ('Z_rad', 'Phase(degrees)', 'phase [rad]'), else
from the comments, else from the caller's option, else degrees (what .zma,
.frd and REW write). An explicit option wins over the file, and the choice is
always reported with its reason.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from analysis.importers.table import Table

_RAD = re.compile(r"(?<![a-z])rad(?:ians?)?(?![a-z])")
_DEG = re.compile(r"(?<![a-z])deg(?:rees?|s)?(?![a-z])|°")
_DB = re.compile(r"(?<![a-z])(?:db|spl)(?![a-z])")
_REAL = re.compile(r"(?<![a-z])re(?:al)?(?![a-z])")
_IMAG = re.compile(r"(?<![a-z])im(?:ag(?:inary)?)?(?![a-z])")
_FREQ = re.compile(r"freq|^f$|^f[\s_(\[]*hz[)\]]*$|^hz$")
_PHASE = re.compile(r"phase|^arg|^ang|(?<![a-z])(?:rad|deg)")
HX_UNITS = {"m/V": 1.0, "mm/V": 1e-3, "um/V": 1e-6}
_HX_UNIT = re.compile(r"(?<![a-z])(mm|um|µm|m)\s*/\s*v(?![a-z])")
# An impedance column's unit in its header: ohm with an SI prefix (case matters: m is milli, M mega).
_Z_UNIT = re.compile(r"(?<![A-Za-z])([mkKM]?)\s?(?:[oO][hH][mM][sS]?|Ω)(?![A-Za-z])")
_Z_PREFIX = {"": ("ohm", 1.0), "m": ("mOhm", 1e-3), "k": ("kOhm", 1e3), "K": ("kOhm", 1e3), "M": ("MOhm", 1e6)}


def column_role(name: str) -> str:
    """'frequency', 'phase', 'real', 'imag', 'decibel' or 'magnitude' (the default)."""
    n = name.strip().lower()
    if _FREQ.search(n):
        return "frequency"
    if _PHASE.search(n):
        return "phase"
    if _REAL.search(n):
        return "real"
    if _IMAG.search(n):
        return "imag"
    if _DB.search(n):
        return "decibel"
    return "magnitude"


@dataclass(frozen=True)
class Columns:
    """Indices of the columns of a curve file; `phase` or (`real`, `imag`) or neither."""

    frequency: int
    magnitude: int | None = None
    phase: int | None = None
    real: int | None = None
    imag: int | None = None

    @property
    def is_complex(self) -> bool:
        return self.real is not None


def assign_columns(table: Table, value_name: str) -> Columns:
    """Map the table's columns to roles, by header names when they say something, else by position."""
    n = table.n_columns
    roles = [column_role(h) for h in table.header] if table.header else None
    if roles and any(r != "magnitude" for r in roles):
        return _by_name(table, roles, value_name)
    if n in (2, 3):
        return Columns(0, 1, 2 if n == 3 else None)
    raise table.error(table.lines[0], f"{n} columns: expected 2 or 3 (frequency, {value_name}[, phase]) "
                      "or a header line naming the columns")


def _by_name(table: Table, roles: list[str], value_name: str) -> Columns:
    names = table.header
    line = table.header_line

    def only(role: str) -> int | None:
        found = [i for i, r in enumerate(roles) if r == role]
        if len(found) > 1:
            raise table.error(line, f"columns {', '.join(repr(names[i]) for i in found)} are all {role}: expected one"
                              + _uiv_hint(names))
        return found[0] if found else None

    frequency = only("frequency")
    frequency = 0 if frequency is None else frequency
    used = {frequency}
    real, imag = only("real"), only("imag")
    if (real is None) != (imag is None):
        raise table.error(line, "a real part without an imaginary part (or the reverse): expected both")
    if real is not None:
        used |= {real, imag}
        columns = Columns(frequency, real=real, imag=imag)
    else:
        phase = only("phase")
        magnitude = next((i for i, r in enumerate(roles) if i not in used and i != phase
                          and r in ("magnitude", "decibel")), None)
        if magnitude is None:
            raise table.error(line, f"no {value_name} column among {', '.join(repr(n) for n in names)}")
        if roles[magnitude] == "decibel":
            raise table.error(line, f"column {names[magnitude]!r} is in dB: expected {value_name} as a plain magnitude")
        used |= {magnitude} | ({phase} if phase is not None else set())
        columns = Columns(frequency, magnitude, phase)
    unused = [names[i] for i in range(len(names)) if i not in used]
    if unused:
        raise table.error(line, f"column {unused[0]!r} is not understood: expected frequency, {value_name}, "
                          "phase (or real and imaginary parts)")
    return columns


def _uiv_hint(names: list[str]) -> str:
    """What to do with a file of voltage, current and laser spectra given as one curve ('' for any other header):
    its U_re, I_re and V_re are three real parts, and "expected one" alone does not say which reader it needs."""
    signals = {name.strip().lower()[:1] for name in names}
    if {"u", "i"} <= signals and signals & {"v", "x"}:
        return ("; the header names voltage, current and laser spectra: read it as U/I/V spectra "
                "(linpar analyze --uiv FILE; in the window, File > Open curves…, 'U, I and laser spectra')")
    return ""


@dataclass(frozen=True)
class PhaseUnit:
    unit: str        # "deg" or "rad"
    source: str      # why this unit, for the user

    def describe(self) -> str:
        return f"phase in {'degrees' if self.unit == 'deg' else 'radians'} ({self.source})"


def _units_named(text: str) -> set[str]:
    t = text.lower()
    return ({"rad"} if _RAD.search(t) else set()) | ({"deg"} if _DEG.search(t) else set())


def phase_unit(table: Table, columns: Columns, option: str | None) -> PhaseUnit:
    """The phase unit of `table`'s phase column and why it was chosen."""
    found, where = None, ""
    if table.header and columns.phase is not None:
        named = _units_named(table.header[columns.phase])
        if len(named) == 1:
            found, where = named.pop(), f"the header {table.header[columns.phase]!r}"
    if found is None:
        named = set().union(*(_units_named(t) for t in table.preamble)) if table.preamble else set()
        if len(named) == 1:
            found = named.pop()
            where = "the file's comments (" + next(repr(t) for t in table.preamble if _units_named(t)) + ")"
    if option is not None:
        if found is not None and found != option:
            said = "degrees" if found == "deg" else "radians"
            return PhaseUnit(option, f"given as option; it overrides {where}, which says {said}")
        return PhaseUnit(option, "given as option")
    if found is not None:
        return PhaseUnit(found, f"from {where}")
    return PhaseUnit("deg", "assumed: the file does not say, and degrees are what .zma, .frd and REW write; "
                            "give the phase unit explicitly if they are radians")


def hx_unit(table: Table, columns: Columns, option: str | None) -> tuple[str, str]:
    """The unit of an Hx magnitude (m/V, mm/V or um/V) and why it was chosen."""
    if option is not None:
        return option, "given as option"
    texts = ([table.header[columns.magnitude if columns.magnitude is not None else columns.real]]
             if table.header else []) + list(table.preamble)
    for text in texts:
        m = _HX_UNIT.search(text.lower())
        if m:
            unit = {"mm": "mm/V", "um": "um/V", "µm": "um/V", "m": "m/V"}[m.group(1)]
            return unit, f"from the file: {text!r}"
    return "m/V", "assumed: the file does not say (SI); give mm/V explicitly if it is in mm/V"


def impedance_scale(table: Table, columns: Columns) -> tuple[float, str | None]:
    """The factor to ohm of an impedance magnitude whose column header names another unit (Z[mOhm]), and the note
    that says so; (1, None) for ohm or a header that names none. Only the column's own header is read: a comment
    line may quote another value in milliohm."""
    column = columns.magnitude if columns.magnitude is not None else columns.real
    if not table.header or column is None:
        return 1.0, None
    text = table.header[column]
    m = _Z_UNIT.search(text)
    if not m or not m.group(1):
        return 1.0, None
    unit, factor = _Z_PREFIX[m.group(1)]
    return factor, f"magnitude in {unit} (from the file: {text!r}), converted to ohm"
