"""A curve the model misses by more than the fit-error tolerance: a yellow finding on it, where the user reads
the result.

QA never judged such curves (analysis.validity.fit.qa_blocker: NOT JUDGED), but `linpar analyze`, the Results
page and the report said "validity: unknown" beside them: the real woofer's U/I/V spectra, fitted from 1 Hz where
the sweep started at 5 Hz, missed the displacement by 26 % rms and read like any other result. The tolerance is
QA's (analysis.fit.error.FIT_ERROR_DEFAULTS): what QA does not judge, the result calls doubtful.
"""
from __future__ import annotations

from analysis.curves.findings import with_curve_findings
from analysis.fit.error import FIT_ERROR_DEFAULTS
from analysis.validity.findings import MODEL_MISFIT, Finding, Severity
from analysis.validity.fit import CURVES_MISFIT_REMEDY
from analysis.validity.result import ResultValidity


def judged_misfit(validity: ResultValidity) -> ResultValidity:
    """`validity` with a yellow model-misfit finding on each curve whose fit error exceeds its tolerance."""
    found = []
    for name, error in (validity.fit_error_percent or {}).items():
        tolerance = FIT_ERROR_DEFAULTS.get(name)
        if tolerance is None or error <= tolerance:
            continue
        found.append(Finding(name, MODEL_MISFIT, Severity.YELLOW,
                             f"{name}: the model misses this curve by {error:.3g} % rms (tolerance {tolerance:g} %): "
                             "its parameters are doubtful, and QA does not judge them", CURVES_MISFIT_REMEDY, error))
    return with_curve_findings(validity, found)
