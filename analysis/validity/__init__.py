"""Whether a measurement can be trusted, channel by channel: the checks of the spectra, the wiring, the drift, the capture and the fit, and their findings.

The public names of analysis.validity.assessment (assess, Validity, ...) and of
analysis.validity.result (ResultValidity: a result's validity, with its JSON) are importable
from the package itself; each is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "ABSENT": "assessment",
    "CaptureInfo": "capture",
    "CaptureInfoError": "capture",
    "ChannelValidity": "assessment",
    "Finding": "assessment",
    "ImportedCurves": "imported_curves",
    "ResultValidity": "result",
    "ResultValidityError": "result",
    "Severity": "assessment",
    "Validity": "assessment",
    "assess": "assessment",
    "capture_of": "assessment",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
