"""A broken measurement is judged, not refused: what the findings leave to fit, the fit's own finding, and QA.

The mechanism every way of analysing a recording shares (analysis.pipeline,
the measurement's analysis step, the GUI), in three steps:

1. `unusable_channels(validity)`: the channels are judged before anything is
   fitted. A channel with no signal, or that copies another (a wiring
   fault), carries nothing to fit. The impedance needs the voltage and the
   current; without it nothing is fitted, and the result keeps its judged
   channels with every parameter "not measured" and the reason. Without a
   usable displacement the impedance alone is fitted, as for a recording
   made without the laser: the electrical parameters are still reported.
2. `misfit_findings(fit)`: a fitted channel whose reduced chi^2 is far above 1
   (`misfit_yellow_chi2_red`, analysis.thresholds) gets a yellow "model-misfit"
   finding: the model does not describe this measurement. Its findings go on
   the signal the fitted channel answers with: the impedance's on the current
   (Z = U / I, the current's response to the voltage), Hx's on the displacement.
3. `qa_blocker(validity, tolerance)`: a red measurement is INVALID: not a
   PASS, not a FAIL (the unit was not judged; production yield leaves it
   out), with the honest reason and what to do: measure again. One whose
   fit error (analysis.fit.error, the rms misfit in % of a curve) exceeds
   the limits file's tolerance is NOT JUDGED, with that reason (imported curves': what to check in the file,
   CURVES_MISFIT_REMEDY, as they have no wiring nor channels' findings). A model-misfit
   finding (reduced chi^2 far above 1) alone does not block QA: a real driver
   measured with little noise always has one, at a fit error of a few %.
   Neither blocked case is judged against the limits parameter by parameter.
   Every place that shows a QA verdict (the QA page, reports, `linpar analyze
   --limits`) takes its headline from VERDICT_HEADLINES.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from analysis.fit.bands import curves_band_hz
from analysis.fit.error import FIT_ERROR_DEFAULTS, fit_error_percent
from analysis.fit.least_squares import FitResult
from analysis.qa_interval import FAIL, PASS, UNCERTAIN
from analysis.thresholds import DEFAULT_THRESHOLDS, ValidityThresholds
from analysis.validity.assessment import ABSENT, ChannelValidity, Validity
from analysis.validity.findings import CHANNEL_COPY, MODEL_MISFIT, NO_SIGNAL, Finding, Severity, worst
from analysis.validity.result import ResultValidity

# Findings after which a channel carries nothing a fit could use.
UNUSABLE = (NO_SIGNAL, CHANNEL_COPY)
# The signal channel whose light a fitted channel's findings go on.
FIT_SIGNAL = {"impedance": "current", "displacement": "displacement"}
# The QA verdicts' codes (as written in JSON) and what a user reads for each. A broken measurement is INVALID in
# its own word (never a FAIL: the unit was not judged, and an operator reads the big word); UNCERTAIN: a
# parameter's interval straddles a limit. The archive stores each under analysis.archive.record.QA_VERDICTS
# (STORED_VERDICT): production statistics leave out all but pass and fail.
INVALID, NOT_JUDGED = "invalid", "not judged"
VERDICT_HEADLINES = {PASS: "PASS", FAIL: "FAIL", UNCERTAIN: "UNCERTAIN: measure again",
                     INVALID: "INVALID: measure again", NOT_JUDGED: "NOT JUDGED"}
# The archive's CHECK constraint knows pass, fail, invalid and not judged: an uncertain unit is stored as not
# judged (it must be measured again, and counts in no yield).
STORED_VERDICT = {UNCERTAIN: NOT_JUDGED}
MISFIT_REMEDY = ("find the effect the model lacks (the Model lab, or 'linpar diagnose') and fit again; if no effect "
                 "helps, check the wiring and the channels' findings")
# Imported curves (validity.imported) have no wiring and no channels' findings, and the Model lab works on recordings
# only: what is left to look at is the file.
CURVES_MISFIT_REMEDY = ("find the effect the model lacks ('linpar diagnose' on the same files) and fit again with it; "
                        "or fit the band the model holds in (--fmax, e.g. 10 x fs: a voice coil far above fs needs "
                        "more than the catalogue's inductance); if neither helps, check what the file holds: a band "
                        "from well below fs, the phase in the unit it was read in, the measured (not a fitted) curve")


@dataclass(frozen=True, slots=True)
class UnusableChannels:
    """Which channels cannot be fitted, and why: None where a channel can be used, else the reason (a finding
    and its remedy). `unusable.impedance is not None` reads as it means: the impedance is unusable."""

    impedance: str | None
    displacement: str | None       # None also when the recording has no displacement at all


def _unusable(validity: Validity, name: str) -> str | None:
    channel = validity.channels.get(name)
    if channel is None or channel.status == ABSENT:
        return None
    for finding in channel.findings:
        if finding.code in UNUSABLE:
            return f"{finding.message}; {finding.remedy}"
    return None


def unusable_channels(validity: Validity) -> UnusableChannels:
    impedance = _unusable(validity, "voltage") or _unusable(validity, "current")
    displacement = _unusable(validity, "displacement")
    if impedance is None and displacement is None:
        return UnusableChannels(None, None)
    return UnusableChannels(impedance and f"the impedance cannot be fitted: {impedance}",
                            displacement and f"the displacement cannot be used: {displacement}")


def misfit_findings(fit: FitResult, th: ValidityThresholds = DEFAULT_THRESHOLDS) -> dict[str, list[Finding]]:
    """A yellow model-misfit finding per fitted channel whose reduced chi^2 reaches the limit."""
    found: dict[str, list[Finding]] = {}
    for name, chi2_red in fit.chi2_red_by_channel().items():
        if not (chi2_red >= th.misfit_yellow_chi2_red) and math.isfinite(chi2_red):
            continue
        shown = "not finite" if not math.isfinite(chi2_red) else f"{chi2_red:.3g}"
        times = "" if not math.isfinite(chi2_red) else f", a misfit {math.sqrt(chi2_red):.3g} times the noise"
        signal = FIT_SIGNAL.get(name, "current")
        found.setdefault(signal, []).append(Finding(
            signal, MODEL_MISFIT, Severity.YELLOW,
            f"{name}: the model does not describe this measurement (reduced chi^2 {shown}{times}; "
            f"limit: yellow from {th.misfit_yellow_chi2_red:g})", MISFIT_REMEDY,
            chi2_red if math.isfinite(chi2_red) else float("inf")))
    return found


def rejudged(validity: ResultValidity, fit: FitResult, th: ValidityThresholds = DEFAULT_THRESHOLDS
             ) -> ResultValidity:
    """A result's validity for another fit of the same recording: the old fit's misfit findings replaced by the
    new one's, the lights redone, the fit error and its band the new fit's (the Model lab's versions, fitted
    over every line where the result may have come from the piston band)."""
    misfits = misfit_findings(fit, th)
    channels = {}
    for name, channel in validity.channels.items():
        if channel.status == ABSENT:
            channels[name] = channel
            continue
        findings = tuple(f for f in channel.findings if f.code != MODEL_MISFIT) + tuple(misfits.get(name, ()))
        channels[name] = ChannelValidity(name, str(worst(f.severity for f in findings)), findings, channel.measures)
    lights = [Severity(ch.status) for ch in channels.values() if ch.status in set(Severity)]
    return validity.replace(channels=channels, overall=worst(lights) if channels else validity.overall,
                            fit_error_percent=fit_error_percent(fit),
                            fit_band_hz=curves_band_hz(fit.channels.values()))


def red_findings_text(validity: ResultValidity) -> str:
    """The first red finding of a validity in words, with its code and remedy, and how many more."""
    red = [f for f in validity.findings if f.severity == Severity.RED]
    if not red:
        return "a channel is red: read its light"
    first = red[0]
    more = f" (and {len(red) - 1} more red finding{'s' if len(red) > 2 else ''})" if len(red) > 1 else ""
    return f"{first.message} [{first.code}]{more}: {first.remedy}"


def qa_blocker(validity: ResultValidity, tolerance: Mapping[str, float] | None = None) -> tuple[str, str] | None:
    """(INVALID or NOT_JUDGED, why) when QA limits must not judge this result; else None.

    tolerance: channel -> the largest fit error in % at which the model is taken to describe the measurement
    (analysis.fit.error.FIT_ERROR_DEFAULTS when None). A result stored before the fit error was computed (no
    "fit_error_percent") is judged by its model-misfit finding, as it was then."""
    if validity.overall == Severity.RED and validity.imported is not None:       # a file: mend how it was read
        return INVALID, (f"the curves as read are no driver's: {red_findings_text(validity)}; the unit itself "
                         "was not judged")
    if validity.overall == Severity.RED:
        return INVALID, (f"measurement invalid: {red_findings_text(validity)}, and measure again; the unit "
                         "itself was not judged")
    errors = validity.fit_error_percent
    if errors is not None:
        tolerance = FIT_ERROR_DEFAULTS if tolerance is None else tolerance
        over = [(name, err, tolerance[name]) for name, err in errors.items()
                if name in tolerance and not err <= tolerance[name]]
        if not over:
            return None
        said = "; ".join(f"the {name} by {err:.3g} % rms (tolerance {limit:g} %)" for name, err, limit in over)
        if validity.imported is not None:
            return NOT_JUDGED, (f"the model does not describe these curves: it misses {said}; its parameters "
                                f"judge nothing; {CURVES_MISFIT_REMEDY}")
        return NOT_JUDGED, (f"the model does not describe this measurement: it misses {said}; its parameters "
                            f"judge nothing; {MISFIT_REMEDY}")
    for finding in validity.findings:
        if finding.code == MODEL_MISFIT:
            return NOT_JUDGED, (f"the model does not describe this measurement ({finding.message}): its "
                                f"parameters judge nothing; {finding.remedy}")
    return None
