"""Importing measured curves from other tools: impedance, Hx, complex U/I/V spectra.

    read_curve(path, kind, phase, unit) -> ImportedCurve   (.transfer, .notes: how it was read)
    read_impedance(path, phase)         -> TransferFunction (ohm)
    read_hx(path, phase, unit)          -> TransferFunction (m/V)
    read_uiv(path)                      -> ImportedUIV (.impedance, .displacement)

Every reader returns complete curves or raises ImportFormatError, whose
one-line message names the file, the line and what was expected.
"""
from analysis.importers.curves import ImportedCurve, read_curve, read_hx, read_impedance
from analysis.importers.errors import ImportFormatError
from analysis.importers.uiv import ImportedUIV, read_uiv

__all__ = ["ImportFormatError", "ImportedCurve", "ImportedUIV", "read_curve", "read_hx", "read_impedance",
           "read_uiv"]
