"""What the Model lab shows of a fit or a diagnosis, built off the GUI thread; no Qt.

LabFit and DiagnosisOutcome are frozen and already hold everything the page draws: the parameter table,
the dense model curves and the residual in words. A diagnosis's outcome is built on a worker process of
its pool (app.jobs.lab_worker), which imports this module and nothing of Qt.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from analysis.derived import parameter_table
from analysis.diagnosis import residuals
from analysis.diagnosis.acceptance import Flag
from analysis.diagnosis.candidates import Candidate, Diagnosis, explain
from analysis.diagnosis.sites import SiteResult
from analysis.diagnosis.words import drift_from_validity, verdict_headline, verdict_text
from analysis.effects import Effect
from analysis.fit.error import band_text
from analysis.fit.least_squares import FitResult
from analysis.pipeline import AnalysisResult
from analysis.validity.fit import rejudged
from app.results.curves import ResultCurves, result_curves


@dataclass(frozen=True, slots=True)
class LabFit:
    """One fitted model, ready to show: its AnalysisResult, curves and residual description."""

    result: AnalysisResult      # the lab's recording with this fit and its parameter table
    curves: ResultCurves
    residual: str               # analysis.diagnosis.residuals.describe(fit)

    @property
    def fit(self) -> FitResult:
        return self.result.fit


def lab_fit(base: AnalysisResult, fit: FitResult) -> LabFit:
    """`fit` dressed for display; milliseconds, but run in the worker with the fit it follows."""
    # The validity goes with the fit: the base's misfit finding is the base model's, not this one's. The lab
    # fits every line (app.model_lab.session), whatever band the base's parameters came from.
    result = dataclasses.replace(base, fit=fit, parameters=parameter_table(fit, base.sd_m2),
                                 validity=rejudged(base.validity, fit), data=None, whole_band_fit=None)
    return LabFit(result, result_curves(result), residuals.describe(fit))


def first_version(result: AnalysisResult) -> tuple[LabFit, str]:
    """The lab's first version and how it came about: the result's fit, or, when its parameters come from the
    piston band, the same model over every line the lab works on (its curves and the residual in words take
    milliseconds: no worker needed)."""
    if result.whole_band_fit is None:
        return LabFit(result, result_curves(result), residuals.describe(result.fit)), "as fitted on the Results page"
    band = band_text(result.validity, "displacement").strip(" ()")         # "14.6-144 Hz"; the page adds ()
    return (lab_fit(result, result.whole_band_fit),
            f"over every line; the Results page's parameters come from the piston band, {band} on Hx")


@dataclass(frozen=True, slots=True)
class CandidateRow:
    """One ranked candidate of a diagnosis: the move, its numbers and its explanation."""

    action: str                     # "add" or "replace"
    effect: Effect
    replaces: Effect | None
    delta_bic: float                # inf when the refit failed
    explanation: str                # analysis.diagnosis.candidates.explain
    fitted: LabFit | None           # None when the refit failed
    error: str | None = None
    flags: tuple[Flag, ...] = ()
    accepted: bool = False          # the acceptance rule would take it (analysis.diagnosis.acceptance)
    judgement: str = ""             # why (not): the assessment's reason code
    partner: Effect | None = None   # a second effect taken with this one (a pair)

    @property
    def chi2_red(self) -> dict[str, float]:
        return self.fitted.fit.chi2_red_by_channel() if self.fitted else {}

    @property
    def move(self) -> str:
        if self.replaces is not None:
            return f"replace {self.replaces.id} by {self.effect.id}"
        return f"add {self.effect.id}" + (f" with {self.partner.id}" if self.partner is not None else "")


@dataclass(frozen=True, slots=True)
class DiagnosisOutcome:
    ranked_from: FitResult                  # the model the candidates are one move away from
    candidates: tuple[CandidateRow, ...]    # best first
    path: tuple[LabFit, ...]                # greedy path: the models taken, in order (empty: ranking only)
    residual: str                           # where the residual of ranked_from sits
    verdict: str = ""                       # analysis.diagnosis.acceptance's four verdicts
    verdict_text: str = ""                  # the verdict in plain words, with the site and what to do next
    sites: tuple[SiteResult, ...] = ()      # where the misfit left belongs, best first
    step_cap_reached: bool = False
    verdict_headline: str = ""              # the verdict in one short sentence

    @property
    def chosen(self) -> CandidateRow | None:
        """The candidate the acceptance rule takes (None: none would be taken)."""
        return next((c for c in self.candidates if c.accepted), None)


def _row(base: AnalysisResult, ranked_from: FitResult, c: Candidate) -> CandidateRow:
    return CandidateRow(c.action, c.effect, c.replaces, c.delta_bic, explain(ranked_from, c),
                        lab_fit(base, c.fit) if c.fit is not None else None, c.error, c.flags, c.accepted,
                        c.assessment.reason if c.assessment else "", c.partner)


def diagnosis_outcome(base: AnalysisResult, result: Diagnosis, follow: bool) -> DiagnosisOutcome:
    """What the lab shows of a diagnosis: the last ranking, the path taken, the verdict and the sites."""
    if follow:
        last = result.steps[-1]
        path = tuple(lab_fit(base, step.fit) for step in result.steps[1:])
    else:
        last, path = result.steps[0], ()
    rows = tuple(_row(base, last.fit, c) for c in last.candidates)
    drift = drift_from_validity(base.validity)
    return DiagnosisOutcome(last.fit, rows, path, last.residual, result.verdict, verdict_text(result, drift),
                            result.sites, result.step_cap_reached, verdict_headline(result))
