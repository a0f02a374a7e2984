"""Imported curves (File > Open curves…) analysed off the GUI thread: the files read, fitted as
`linpar analyze --impedance Z --hx HX` (or `--uiv UIV`) fits them (both read them with
analysis.curves.imported.import_curves), with each channel's fitted curve of the exporting tool kept for the
overlay (analysis.curves.reference). A file that cannot be read fails the job with one line; a file given as the
other kind (U, I and laser spectra as the impedance, or the reverse) is named for what it is, in the dialog's words
(app.jobs.curve_kinds)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from app.jobs.book import Job


@dataclass(frozen=True, slots=True)
class CurvesRequest:
    impedance: Path | None = None
    hx: Path | None = None
    hx_mm_per_volt: bool = False      # a plain table's Hx in mm/V (a Klippel export's header says its unit)
    uiv: Path | None = None           # a CSV of complex U, I and laser spectra: Z and Hx in one file

    @property
    def path(self) -> Path:
        """The file the analysis is named after: the U/I/V file, else the impedance curve."""
        return self.uiv if self.uiv is not None else self.impedance

    @property
    def name(self) -> str:
        return self.path.name


def analyse_curves(job: Job, request: CurvesRequest):
    """`request`'s curves fitted: an analysis.curves.fitting.CurveAnalysis with its files and references."""
    from analysis.curves.fitting import fit_curves
    from analysis.curves.imported import import_curves
    from analysis.importers import ImportFormatError
    from app.jobs.curve_kinds import misfiled
    job.say(f"reading {request.name}")
    try:
        curves = import_curves(request.impedance, hx=request.hx, uiv=request.uiv,
                               hx_mm_per_volt=request.hx_mm_per_volt)
    except ImportFormatError as exc:
        raise misfiled(request, exc) or exc
    job.check()
    job.say(f"fitting {request.name}")
    result = fit_curves(curves.impedance, curves.displacement, f_range=curves.fit_range, notes=curves.notes)
    return dataclasses.replace(result, files=curves.files, references=curves.references)
