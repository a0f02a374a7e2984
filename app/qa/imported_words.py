"""What the QA page says of imported curves (File > Open curves…): the signal, noise and distortion checks have
not run and never will (they run on recordings: a file holds no channels to check), and what the verdict rests on
instead (analysis.validity.fit.qa_blocker: an imported impedance that cannot be a driver's, or numbers no driver
has (analysis.curves.plausible_numbers), make the result red, INVALID; a curve the model misses by more than the
fit-error tolerance is NOT JUDGED; else the limits judge).
A recording's words ("not checked yet", "check the wiring") would send the user after checks that do not apply."""
from __future__ import annotations

HEADLINE = "Imported curves: no validity checks"
JUDGED_BY = ("the signal, noise and distortion checks run on recordings, not on curves read from a file: these "
             "curves are judged by their fit (a curve the model misses by more than the fit-error tolerance is "
             "not judged) and by being a driver's at all (passive, with a resonance, with a moving mass and an "
             "efficiency a driver can have)")
NO_LIMITS = "no limits loaded: only the curves' fit is judged"
NO_CHANNELS = ("Imported curves have no voltage, current or displacement channel to check: Z (and Hx) were read "
               "from the file.")


def imported(validity) -> bool:
    """True for the validity (analysis.validity.result.ResultValidity) of imported curves, stored ones too."""
    return validity.imported is not None
