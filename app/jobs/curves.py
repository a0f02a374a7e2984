"""Imported curves (File > Open curves…) analysed off the GUI thread: the files read, fitted as
`linpar analyze --impedance Z --hx HX` fits them, with each channel's fitted curve of the exporting tool kept for
the overlay (analysis.curves.reference). A file that cannot be read fails the job with the CLI's one line."""
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
    from analysis.importers import read_curve
    job.say(f"reading {request.name}")
    z = read_curve(request.impedance, "impedance", None)
    hx = None if request.hx is None else read_curve(request.hx, "displacement", None,
                                                     "mm/V" if request.hx_mm_per_volt else None)
    job.check()
    job.say(f"fitting {request.name}")
    read = [c for c in (z, hx) if c is not None]
    result = fit_curves(z.transfer, None if hx is None else hx.transfer, notes=[c.describe() for c in read])
    references = {name: c.reference for name, c in zip(("impedance", "displacement"), read) if c.reference is not None}
    files = tuple(p for p in (request.impedance, request.hx) if p is not None)
    return dataclasses.replace(result, files=files, references=references)
