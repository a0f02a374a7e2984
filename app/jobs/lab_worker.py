"""The model lab's fits off the GUI thread: refits of one model, and diagnoses.

A LabWorker is a JobRunner (app.jobs.book). What crosses to the GUI thread is
frozen (LabFit, DiagnosisOutcome) and already holds everything the page
draws: the parameter table, the dense model curves and the residual in words.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from analysis.derived import parameter_table
from analysis.diagnosis import residuals
from analysis.diagnosis.acceptance import Flag
from analysis.diagnosis.candidates import MAX_STEPS, Candidate, Diagnosis, Step, diagnose, explain
from analysis.diagnosis.sites import SiteResult
from analysis.diagnosis.words import drift_from_validity, verdict_headline, verdict_text
from analysis.effects import Effect
from analysis.fit.error import band_text
from analysis.fit.least_squares import FitCancelled, FitData, FitResult, fit_model
from analysis.model.composed import Model
from analysis.pipeline import AnalysisResult
from analysis.validity.fit import rejudged
from app.jobs.background_pool import PoolCancelled, background_pool
from app.jobs.book import Job, JobRunner
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


def _refit(job: Job, base: AnalysisResult, data: FitData, model: Model, start: dict[str, float]) -> LabFit:
    job.say(f"fitting {model.describe()}")
    fit = fit_model(data, model, start=start, cancel=job.cancel_event)
    job.check()
    return lab_fit(base, fit)


def _diagnose(job: Job, base: AnalysisResult, data: FitData, start: FitResult, follow: bool,
              taken: CandidateRow | None) -> DiagnosisOutcome:
    """Rank the candidates from `start` (follow=False) or follow the greedy path from it (follow=True).

    `taken`, when known, is the candidate a previous ranking of `start` chose:
    the greedy path then goes on from it instead of ranking `start` again
    (it still counts as the path's first step, for the verdict).
    """
    begin = taken.fitted.fit if taken is not None else start
    with background_pool(job.cancel_event) as executor:       # the window keeps the cores (and the GIL) it needs
        result = diagnose(data, begin.model, executor=executor, cancel=job.cancel_event, start_fit=begin,
                          progress=job.say, max_steps=MAX_STEPS, follow=follow)
    job.check()
    if taken is not None:
        t = taken
        first = Step(fit=start, candidates=(), residual=residuals.describe(start),
                     chosen=Candidate(action=t.action, effect=t.effect, replaces=t.replaces, fit=t.fitted.fit,
                                      delta_bic=t.delta_bic, error=t.error, flags=t.flags))
        result = dataclasses.replace(result, steps=(first,) + result.steps)
    return diagnosis_outcome(base, result, follow)


class LabWorker(JobRunner):
    cancel_errors = (*JobRunner.cancel_errors, FitCancelled, PoolCancelled)

    def refit(self, base: AnalysisResult, data: FitData, model: Model, start: dict[str, float]) -> Job:
        start = dict(start)
        return self.run("refit", lambda job: _refit(job, base, data, model, start), "the model lab's refit")

    def diagnose(self, base: AnalysisResult, data: FitData, start: FitResult, follow: bool = False,
                 taken: CandidateRow | None = None) -> Job:
        return self.run("diagnosis", lambda job: _diagnose(job, base, data, start, follow, taken),
                        "the model lab's diagnosis")
