"""Imported curves (File > Open curves…) analysed off the GUI thread: the files read, fitted as
`linpar analyze --impedance Z --hx HX` fits them (both read them with analysis.curves.imported.import_curves), with
each channel's fitted curve of the exporting tool kept for the overlay (analysis.curves.reference). A file that
cannot be read fails the job with the CLI's one line."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from app.jobs.book import Job


@dataclass(frozen=True, slots=True)
class CurvesRequest:
    impedance: Path
    hx: Path | None = None
    hx_mm_per_volt: bool = False      # a plain table's Hx in mm/V (a Klippel export's header says its unit)

    @property
    def name(self) -> str:
        return self.impedance.name


def analyse_curves(job: Job, request: CurvesRequest):
    """`request`'s curves fitted: an analysis.curves.fitting.CurveAnalysis with its files and references."""
    from analysis.curves.fitting import fit_curves
    from analysis.curves.imported import import_curves
    job.say(f"reading {request.name}")
    curves = import_curves(request.impedance, hx=request.hx, hx_mm_per_volt=request.hx_mm_per_volt)
    job.check()
    job.say(f"fitting {request.name}")
    result = fit_curves(curves.impedance, curves.displacement, f_range=curves.fit_range, notes=curves.notes)
    return dataclasses.replace(result, files=curves.files, references=curves.references)
