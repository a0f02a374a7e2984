"""The model lab's fits off the GUI thread: refits of one model, and diagnoses.

A LabWorker is a JobRunner (app.jobs.book). What crosses to the GUI thread is
frozen (LabFit, DiagnosisOutcome: app.jobs.lab_outcome) and already holds
everything the page draws: the parameter table, the dense model curves and the
residual in words. A refit fits on the lab's worker process
(app.jobs.refit_process), a diagnosis on a pool of its own.
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QObject

from analysis.diagnosis import residuals
from analysis.diagnosis.candidates import MAX_STEPS, Candidate, Step, diagnose
from analysis.fit.least_squares import FitCancelled, FitData, FitResult
from analysis.model.composed import Model
from analysis.pipeline import AnalysisResult
from app.jobs.background_pool import PoolCancelled, background_pool
from app.jobs.book import Job, JobRunner
from app.jobs.lab_outcome import CandidateRow, DiagnosisOutcome, LabFit, diagnosis_outcome, lab_fit
from app.jobs.refit_process import RefitProcess


def _refit(job: Job, refits: RefitProcess, ticket: int, base: AnalysisResult, data: FitData, model: Model,
           current: FitResult) -> LabFit:
    job.say(f"fitting {model.describe()}")
    fit = refits.fit(ticket, data, model, current, job.cancel_event)
    job.check()
    return lab_fit(base, fit)       # 2-5 ms here: sending the base (its spectra, 2.6 MB) to the worker costs more


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
        if executor is None:
            return diagnosis_outcome(base, result, follow)
        # Built on a worker too: 0.1-0.2 s of CPU (a parameter table and curves per candidate) that in this
        # thread held the GIL against the GUI thread's paint just before the table is shown; the round trip
        # of its pickles costs the GUI process ~25 ms of CPU.
        return executor.submit(diagnosis_outcome, base, result, follow).result()


class LabWorker(JobRunner):
    cancel_errors = (*JobRunner.cancel_errors, FitCancelled, PoolCancelled)

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self.refits = RefitProcess()

    def refit(self, base: AnalysisResult, data: FitData, model: Model, current: FitResult) -> Job:
        """`model` refitted from `current`, the version it changes (analysis.diagnosis.refit)."""
        ticket = self.refits.ticket()      # in the GUI thread: app.jobs.refit_process
        return self.run("refit", lambda job: _refit(job, self.refits, ticket, base, data, model, current),
                        "the model lab's refit")

    def shutdown(self, wait_ms: int) -> bool:
        stopped = super().shutdown(wait_ms)
        self.refits.shutdown()
        return stopped

    def diagnose(self, base: AnalysisResult, data: FitData, start: FitResult, follow: bool = False,
                 taken: CandidateRow | None = None) -> Job:
        return self.run("diagnosis", lambda job: _diagnose(job, base, data, start, follow, taken),
                        "the model lab's diagnosis")
