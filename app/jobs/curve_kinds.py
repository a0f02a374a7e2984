"""A curves file given as the other kind in File > Open curves…: U, I and laser spectra given as the impedance (or
Hx) curve, or an impedance curve given as the U/I/V spectra. The importer's own message then says what the file
lacks for the kind it was read as ("columns U_re, I_re, V_re are all real: expected one"); the user needs to hear
what the file is, and where in the dialog it goes. Only asked after a read failed: a good file is read once."""
from __future__ import annotations

from pathlib import Path

from analysis.errors import LinparError

# The dialog's words for the two kinds (app.window.open_curves shows them).
CURVES_CHOICE = "Impedance (and Hx) curves"
UIV_CHOICE = "U, I and laser spectra"
UIV_COLUMNS = "f_Hz, U_re, U_im, I_re, I_im, V_re, V_im"


class CurvesKindError(LinparError, ValueError):
    """A curves file that reads as the other kind of file: one line naming what it is and where it goes."""


def _reads_as_uiv(path: Path) -> bool:
    from analysis.importers import ImportFormatError, read_uiv
    try:
        read_uiv(path)
    except (ImportFormatError, OSError):
        return False
    return True


def _reads_as_impedance(path: Path) -> bool:
    from analysis.importers import ImportFormatError, read_curve
    try:
        read_curve(path, "impedance")
    except (ImportFormatError, OSError):
        return False
    return True


def misfiled(request, failure) -> CurvesKindError | None:
    """What the file that `failure` (an ImportFormatError) names is, when it is the other kind than `request`
    (app.jobs.curves.CurvesRequest) gave it as; None when it is no other kind either (the importer's line stands)."""
    path = Path(failure.path)
    if request.uiv is None and path in (request.impedance, request.hx) and _reads_as_uiv(path):
        given = "an impedance curve" if path == request.impedance else "an Hx curve"
        return CurvesKindError(f"{path.name} holds complex U, I and laser spectra ({UIV_COLUMNS}), not "
                               f"{given}: in File ▸ Open curves… choose “{UIV_CHOICE}” and give it there")
    if request.uiv is not None and path == request.uiv and _reads_as_impedance(path):
        return CurvesKindError(f"{path.name} holds an impedance curve, not complex U, I and laser spectra "
                               f"({UIV_COLUMNS}): in File ▸ Open curves… choose “{CURVES_CHOICE}” and give it "
                               "as the impedance")
    return None
