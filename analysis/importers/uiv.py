"""Complex voltage, current and velocity (or displacement) spectra: the whole laser method from a CSV.

Columns (header names, any order; '#' comments): f_Hz, U_re, U_im, I_re,
I_im and either V_re, V_im (cone velocity, m/s) or X_re, X_im (displacement,
m). Without a header the order is f, U, I, V (7 columns). Then

    Z = U / I        Hx = X / U = V / (j*2*pi*f*U)
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.bounds import HX, IMPEDANCE
from analysis.importers.curves import check_bound, check_frequencies
from analysis.importers.table import Table, read_table
from analysis.spectra import TransferFunction

# Column names: a signal letter and re/im, e.g. 'U_re', 'I im', 'V.imag', 'Re(U)'.
_PART = r"(re|real|im|imag)"
_NAME = re.compile(rf"^(?P<sig>[uivx])[\s_.\-]*(?P<part>{_PART})$|^(?P<part2>{_PART})\s*\(\s*(?P<sig2>[uivx])\s*\)$")
POSITIONAL = ("f", "U_re", "U_im", "I_re", "I_im", "V_re", "V_im")


@dataclass(frozen=True)
class ImportedUIV:
    impedance: TransferFunction
    displacement: TransferFunction
    path: Path
    notes: tuple[str, ...]

    def describe(self) -> str:
        f = self.impedance.freqs
        return "; ".join([f"{self.path.name}: complex U, I and laser spectra, {len(f)} lines, "
                          f"{f[0]:g} to {f[-1]:g} Hz", *self.notes])


def _columns(table: Table) -> dict[str, int]:
    """Column index of 'f' and of each (signal, part), e.g. ('u', 're')."""
    if table.header is None:
        if table.n_columns != len(POSITIONAL):
            raise table.error(int(table.lines[0]), f"{table.n_columns} columns and no header: expected "
                              f"{len(POSITIONAL)} ({', '.join(POSITIONAL)}) or a header naming them")
        names = POSITIONAL
    else:
        names = table.header
    found: dict[str, int] = {}
    for i, name in enumerate(names):
        n = name.strip().lower()
        if n.startswith("f") and ("hz" in n or "freq" in n or n == "f"):
            key = "f"
        else:
            m = _NAME.match(n)
            if not m:
                raise table.error(table.header_line, f"column {name!r} is not understood: expected f_Hz, U_re, "
                                  "U_im, I_re, I_im and V_re, V_im (velocity) or X_re, X_im (displacement)")
            sig = m.group("sig") or m.group("sig2")
            part = "re" if (m.group("part") or m.group("part2")).startswith("re") else "im"
            key = sig + part
        if key in found:
            raise table.error(table.header_line, f"column {name!r} appears twice")
        found[key] = i
    needed = ["f", "ure", "uim", "ire", "iim"]
    missing = [k for k in needed if k not in found]
    motion = [s for s in "vx" if s + "re" in found and s + "im" in found]
    if missing or len(motion) != 1:
        what = ", ".join(missing) if missing else "exactly one of V (velocity) or X (displacement), real and imaginary"
        raise table.error(table.header_line, f"missing column(s): {what}")
    return found


def read_uiv(path: str | Path) -> ImportedUIV:
    """Z and Hx from complex U, I and V (or X) spectra. Raises ImportFormatError."""
    table = read_table(path)
    col = _columns(table)
    v = table.values
    f = v[:, col["f"]]
    check_frequencies(table, f)
    U = v[:, col["ure"]] + 1j * v[:, col["uim"]]
    I = v[:, col["ire"]] + 1j * v[:, col["iim"]]
    for name, signal in (("voltage", U), ("current", I)):
        zero = np.flatnonzero(signal == 0)
        if zero.size:
            raise table.error(int(table.lines[zero[0]]), f"the {name} is zero: Z = U / I needs both non-zero")
    if "vre" in col:
        V = v[:, col["vre"]] + 1j * v[:, col["vim"]]
        X = V / (2j * np.pi * f)
        notes = ("motion given as velocity (m/s): Hx = V / (j*2*pi*f*U)",)
    else:
        X = v[:, col["xre"]] + 1j * v[:, col["xim"]]
        notes = ("motion given as displacement (m): Hx = X / U",)
    with np.errstate(over="ignore", invalid="ignore"):
        Z, Hx = U / I, X / U
    for name, value in (("impedance", Z), ("Hx", Hx)):
        bad = np.flatnonzero(~np.isfinite(value))
        if bad.size:
            raise table.error(int(table.lines[bad[0]]), f"the {name} overflows: expected finite spectra")
    check_bound(table, np.abs(Z), IMPEDANCE, "|Z| = |U / I|")
    check_bound(table, np.abs(Hx), HX, "|Hx| = |X / U|")
    n = len(f)
    nan = np.full(n, np.nan)
    z_tf = TransferFunction("impedance", "ohm", f.copy(), np.arange(n), Z, nan, has_phase=True, noise_known=False)
    x_tf = TransferFunction("displacement", "m/V", f.copy(), np.arange(n), Hx, nan.copy(), has_phase=True,
                            noise_known=False)
    return ImportedUIV(z_tf, x_tf, table.path, notes)
