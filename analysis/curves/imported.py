"""Curves read from other tools' files, ready to fit: Z, optional Hx, how they were read, and the band to fit.

`import_curves` reads them (analysis.importers) and keeps the fit's frequency range with them, so that
`analysis.analyze(curves)` and `analysis.diagnose(curves)` fit the same lines `linpar analyze --impedance`
and `linpar diagnose --impedance` fit.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from analysis.curves.fitting import LINES_PER_DECADE, CurveFitError, FitRange
from analysis.spectra import TransferFunction

PHASE_UNITS = ("deg", "rad")


@dataclass(frozen=True, kw_only=True)
class ImportedCurves:
    impedance: TransferFunction                 # ohm
    displacement: TransferFunction | None       # Hx in m/V; None: Z alone (no Bl)
    notes: tuple[str, ...]                      # each file: what was read, and how
    fit_range: FitRange = FitRange()


def import_curves(impedance: str | Path | None = None, *, hx: str | Path | None = None,
                  uiv: str | Path | None = None, phase: str | None = None, hx_mm_per_volt: bool = False,
                  f_min: float | None = None, f_max: float | None = None, hx_f_max: float | None = None,
                  all_lines: bool = False) -> ImportedCurves:
    """An impedance curve (and an Hx curve), or a CSV of complex U, I and laser spectra (uiv), read for a fit.

    phase: 'deg' or 'rad' to override what the files say; f_min, f_max bound both curves and hx_f_max Hx
    alone (default 4 x fs); all_lines keeps every line of a linearly spaced file (default: 100 per decade).
    Raises ImportFormatError (a file that cannot be read) or CurveFitError (curves given the wrong way).
    """
    from analysis.importers import read_curve, read_uiv
    if phase is not None and phase not in PHASE_UNITS:
        raise CurveFitError(f"phase: '{phase}' is not a phase unit; expected one of {', '.join(PHASE_UNITS)}")
    if uiv is not None and (impedance is not None or hx is not None):
        raise CurveFitError("uiv carries both Z and Hx: do not add an impedance or an Hx curve")
    if uiv is None and impedance is None:
        raise CurveFitError("Hx alone cannot be fitted: give the impedance curve too" if hx is not None else
                            "no curves: give an impedance curve (and an Hx curve), or uiv")
    fit_range = FitRange(f_min, f_max, hx_f_max, None if all_lines else LINES_PER_DECADE)
    if uiv is not None:
        read = read_uiv(uiv)
        return ImportedCurves(impedance=read.impedance, displacement=read.displacement, notes=(read.describe(),),
                              fit_range=fit_range)
    z = read_curve(impedance, "impedance", phase)
    x = None if hx is None else read_curve(hx, "displacement", phase, "mm/V" if hx_mm_per_volt else None)
    return ImportedCurves(impedance=z.transfer, displacement=None if x is None else x.transfer,
                          notes=tuple(c.describe() for c in (z, x) if c is not None), fit_range=fit_range)
