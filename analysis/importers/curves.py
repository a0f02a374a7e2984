"""Impedance and Hx curves from text files (.zma, .frd, REW exports, any delimited table).

An imported curve has no per-line uncertainty (std NaN, noise_known False):
the fit then weighs its lines relatively and takes the parameter
uncertainties from the scatter of the residual.
"""
from __future__ import annotations

import dataclasses

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.bounds import FREQUENCY, HX, IMPEDANCE, Bound
from analysis.importers.columns import HX_UNITS, assign_columns, hx_unit, impedance_scale, phase_unit
from analysis.importers import lpm
from analysis.importers.errors import ImportFormatError
from analysis.importers.table import Table, parse_table, read_text
from analysis.spectra import TransferFunction

KINDS = {"impedance": ("ohm", "|Z| in ohm"), "displacement": ("m/V", "|Hx| in m/V")}
# An impedance (passive) is within +-90 degrees; measured noise near +-90
# can cross it, so only a wrapped phase beyond +-180 is refused.
MAX_IMPEDANCE_PHASE_TURNS = 0.5
# Hx may be unwrapped (the phase keeps falling with a sensor delay); ten turns
# is far beyond any displacement response, and catches degrees read as radians.
MAX_HX_PHASE_TURNS = 10.0
# Tolerance on the range checks: exports round the last digit.
RANGE_TOLERANCE = 1e-4


@dataclass(frozen=True)
class ImportedCurve:
    """One imported curve and how it was read (so that the user can check it)."""

    transfer: TransferFunction
    path: Path
    notes: tuple[str, ...]          # each decision taken while reading: the phase unit and why, etc.
    # The exporting tool's own fitted curve, when the file has one (Klippel dB-Lab): an overlay, never fitted.
    reference: TransferFunction | None = None

    def describe(self) -> str:
        t = self.transfer
        head = (f"{self.path.name}: {t.name}, {len(t.freqs)} lines, {t.freqs[0]:g} to {t.freqs[-1]:g} Hz, "
                f"{'with phase' if t.has_phase else 'magnitude only'}")
        return "; ".join([head, *self.notes])


def read_curve(path: str | Path, kind: str = "impedance", phase: str | None = None,
               unit: str | None = None) -> ImportedCurve:
    """Read an impedance (ohm) or Hx (kind 'displacement', m/V) curve. Raises ImportFormatError.

    phase: 'deg' or 'rad' to override what the file says; unit (Hx only):
    'm/V', 'mm/V' or 'um/V' for the magnitude (returned in m/V).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {sorted(KINDS)}, not {kind!r}")
    if phase not in (None, "deg", "rad"):
        raise ValueError(f"phase must be 'deg' or 'rad', not {phase!r}")
    if unit is not None and (kind != "displacement" or unit not in HX_UNITS):
        raise ValueError(f"unit applies to Hx only and must be one of {sorted(HX_UNITS)}, not {unit!r}")
    text = read_text(path)
    if lpm.recognises(text):
        return lpm_curve(lpm.read_lpm(path, text), kind, unit)
    return curve_from_table(parse_table(path, text), kind, phase, unit)


def lpm_curve(export: lpm.LpmExport, kind: str, unit: str | None = None) -> ImportedCurve:
    """The measured curve of a Klippel dB-Lab export (magnitude only), its fitted curve kept as the reference."""
    path = export.path
    if export.kind != kind:
        option = "--impedance" if export.kind == "impedance" else "--hx"
        raise ImportFormatError(path, None, f"a Klippel export of {'an impedance' if export.kind == 'impedance' else 'Hx'}"
                                f" ({export.title!r}, in {export.unit}) where {KINDS[kind][1]} was expected: give it "
                                f"as {option}")
    if unit is not None and unit.lower() != export.unit.lower().replace("µ", "u").replace("μ", "u"):
        raise ImportFormatError(path, None, f"the export's units line says {export.unit}, the option {unit}: "
                                "drop the option (the file's unit is used)")
    si_unit, value_name = KINDS[kind]
    curves = []
    for curve in (export.measured, export.fitted):
        if curve is None:
            curves.append(None)
            continue
        table = export.table(curve)
        check_frequencies(table, curve.freqs)
        _check_positive(table, curve.values, "magnitude")
        check_bound(table, curve.values, HX if kind == "displacement" else IMPEDANCE, value_name.split(" in ")[0])
        n = len(curve.freqs)
        curves.append(TransferFunction(kind, si_unit, curve.freqs.copy(), np.arange(n), curve.values.astype(complex),
                                       np.full(n, np.nan), has_phase=False, noise_known=False))
    measured, fitted = curves
    notes = [f"Klippel dB-Lab export {export.title!r}: the {export.measured.group!r} curve, magnitude only (the "
             f"export has no phase: |{'Z' if kind == 'impedance' else 'Hx'}| alone is fitted)",
             f"magnitude in {export.unit} (from the file's units line)"]
    if fitted is not None:
        notes.append(f"the {export.fitted.group!r} curve (the tool's own fit) kept for comparison, not fitted; it "
                     f"misses the measured curve by {100 * reference_misfit(measured, fitted):.2g} % rms (its fit error)")
    return ImportedCurve(measured, path, tuple(notes), fitted)


def curve_from_table(table: Table, kind: str, phase: str | None = None, unit: str | None = None) -> ImportedCurve:
    si_unit, value_name = KINDS[kind]
    columns = assign_columns(table, value_name)
    freqs = table.values[:, columns.frequency]
    notes: list[str] = []
    if freqs.size > 1 and np.all(np.diff(freqs) < 0):       # written from the top of the band down: read it turned
        table = dataclasses.replace(table, values=table.values[::-1], lines=table.lines[::-1])
        freqs = freqs[::-1]
        notes.append("frequencies descending in the file: read from its last line up")
    check_frequencies(table, freqs)
    if columns.is_complex:
        value = table.values[:, columns.real] + 1j * table.values[:, columns.imag]
        _check_positive(table, np.abs(value), f"|{value_name.split()[0].strip('|')}|")
        notes.append("real and imaginary parts")
    else:
        magnitude = table.values[:, columns.magnitude]
        _check_positive(table, magnitude, "magnitude")
        value = magnitude.astype(complex)
        if columns.phase is not None:
            pu = phase_unit(table, columns, phase)
            notes.append(pu.describe())
            raw_phase = table.values[:, columns.phase]
            _check_phase_range(table, raw_phase, pu, kind)
            radians = np.deg2rad(raw_phase) if pu.unit == "deg" else raw_phase
            value = magnitude * np.exp(1j * radians)
            if pu.unit == "deg" and len(raw_phase) >= 10 and 0 < np.max(np.abs(raw_phase)) <= np.pi:
                notes.append("all phases lie within +-pi degrees: if they are radians, give the unit explicitly")
        else:
            notes.append("no phase column: magnitude only")
    if kind == "displacement":
        chosen, why = hx_unit(table, columns, unit)
        value = value * HX_UNITS[chosen]
        notes.append(f"magnitude in {chosen} ({why})")
    else:
        factor, said = impedance_scale(table, columns)
        value = value * factor
        notes += [said] if said else []
    check_bound(table, np.abs(value), HX if kind == "displacement" else IMPEDANCE, value_name.split(" in ")[0])
    has_phase = columns.is_complex or columns.phase is not None
    n = len(freqs)
    tf = TransferFunction(kind, si_unit, freqs.copy(), np.arange(n), value, np.full(n, np.nan),
                          has_phase=has_phase, noise_known=False)
    return ImportedCurve(tf, table.path, tuple(notes))


def reference_misfit(measured: TransferFunction, reference: TransferFunction) -> float:
    """rms of |reference / measured| - 1 over the measured lines the reference spans (interpolated in log f)."""
    inside = (measured.freqs >= reference.freqs[0]) & (measured.freqs <= reference.freqs[-1])
    if not inside.any():
        return float("nan")
    at = np.interp(np.log(measured.freqs[inside]), np.log(reference.freqs), np.abs(reference.value))
    return float(np.sqrt(np.mean((at / np.abs(measured.value[inside]) - 1) ** 2)))


def check_bound(table: Table, values: np.ndarray, bound: Bound, what: str) -> None:
    """Every value inside the bound (analysis.bounds); else the first one outside, with its line."""
    bad = np.flatnonzero(~((values >= bound.low) & (values <= bound.high)))
    if bad.size:
        i = bad[0]
        raise table.error(int(table.lines[i]), f"{what} {values[i]:g}: expected {bound.expected()}")


def check_frequencies(table: Table, freqs: np.ndarray) -> None:
    bad = np.flatnonzero(freqs <= 0)
    if bad.size:
        i = bad[0]
        raise table.error(int(table.lines[i]), f"frequency {freqs[i]:g} Hz: expected a positive frequency")
    check_bound(table, freqs, FREQUENCY, "frequency")
    steps = np.flatnonzero(np.diff(freqs) <= 0)
    if steps.size:
        i = steps[0] + 1
        raise table.error(int(table.lines[i]), f"frequency {freqs[i]:g} Hz is not above the previous line's "
                          f"{freqs[i - 1]:g} Hz: expected strictly increasing frequencies (sort the file by "
                          "frequency and remove repeated lines)")


def _check_positive(table: Table, values: np.ndarray, what: str) -> None:
    bad = np.flatnonzero(~(values > 0))
    if bad.size:
        i = bad[0]
        raise table.error(int(table.lines[i]), f"{what} {values[i]:g}: expected a positive value")


def _check_phase_range(table: Table, raw: np.ndarray, pu, kind: str) -> None:
    turns = MAX_IMPEDANCE_PHASE_TURNS if kind == "impedance" else MAX_HX_PHASE_TURNS
    limit = turns * (360.0 if pu.unit == "deg" else 2 * np.pi) * (1 + RANGE_TOLERANCE)
    bad = np.flatnonzero(np.abs(raw) > limit)
    if bad.size:
        i = bad[0]
        unit = "degrees" if pu.unit == "deg" else "radians"
        hint = " (is it in degrees?)" if pu.unit == "rad" else ""
        raise table.error(int(table.lines[i]), f"phase {raw[i]:g} is out of range for {unit}: expected |phase| <= "
                          f"{limit / (1 + RANGE_TOLERANCE):.4g} for {'an impedance' if kind == 'impedance' else 'Hx'}"
                          f"{hint}; {pu.describe()}")


def read_impedance(path: str | Path, phase: str | None = None) -> TransferFunction:
    return read_curve(path, "impedance", phase).transfer


def read_hx(path: str | Path, phase: str | None = None, unit: str | None = None) -> TransferFunction:
    return read_curve(path, "displacement", phase, unit).transfer
