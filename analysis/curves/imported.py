"""Curves read from other tools' files, ready to fit: Z, optional Hx, how they were read, and the band to fit.

`import_curves` reads them (analysis.importers) and keeps the fit's frequency range with them. It is the one
way curves are read: the library (`analysis.analyze(curves)`, `analysis.diagnose(curves)`), the CLI
(`linpar analyze --impedance`, `linpar diagnose --impedance`) and the GUI (File > Open curves…) all call it, so
the three fit the same lines of the same files.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from analysis.curves.fitting import LINES_PER_DECADE, CurveFitError, FitRange
from analysis.spectra import TransferFunction

PHASE_UNITS = ("deg", "rad")


@dataclass(frozen=True, kw_only=True)
class ImportedCurves:
    impedance: TransferFunction                 # ohm
    displacement: TransferFunction | None       # Hx in m/V; None: Z alone (no Bl)
    notes: tuple[str, ...]                      # each file: what was read, and how
    fit_range: FitRange = FitRange()
    files: tuple[Path, ...] = ()                # the files read, the impedance's (or the uiv) first
    # Each channel's fitted curve of the exporting tool (a Klippel export's): an overlay, never fitted.
    references: Mapping[str, TransferFunction] = field(default_factory=dict)


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
    fit_range = FitRange(f_min=f_min, f_max=f_max, hx_f_max=hx_f_max,
                         per_decade=None if all_lines else LINES_PER_DECADE)
    if uiv is not None:
        read = read_uiv(uiv)
        return ImportedCurves(impedance=read.impedance, displacement=read.displacement, notes=(read.describe(),),
                              fit_range=fit_range, files=(read.path,))
    z = read_curve(impedance, "impedance", phase)
    x = None if hx is None else read_curve(hx, "displacement", phase, "mm/V" if hx_mm_per_volt else None)
    by_channel = {name: c for name, c in (("impedance", z), ("displacement", x)) if c is not None}
    return ImportedCurves(impedance=z.transfer, displacement=None if x is None else x.transfer,
                          notes=tuple(c.describe() for c in by_channel.values()), fit_range=fit_range,
                          files=tuple(c.path for c in by_channel.values()),
                          references={name: c.reference for name, c in by_channel.items()
                                      if c.reference is not None})
