"""Analysis of an opened recording off the GUI thread: a JobRunner (app.jobs.book) whose jobs read a recording
and analyse it. What crosses over is frozen (AnalysisOutcome) or a string."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from analysis.fit.least_squares import FitCancelled
from analysis.fit.model_uncertainty import model_uncertainty
from analysis.pipeline import AnalysisResult, analyze_recording
from analysis.recording.format import read_recording
from app.jobs.background_pool import PoolCancelled, background_pool
from app.jobs.book import Job, JobRunner
from app.results.curves import ResultCurves, result_curves


@dataclass(frozen=True, slots=True)
class AnalysisOutcome:
    job: int
    path: Path
    result: AnalysisResult
    curves: ResultCurves | None         # None: nothing was fitted (result.not_fitted says why)
    nominal_ohm: float | None = None    # the nominal impedance the sidecar's driver entry gives, for a remark


class AnalysisWorker(JobRunner):
    cancel_errors = (*JobRunner.cancel_errors, FitCancelled, PoolCancelled)

    def start(self, path: str | Path, sd_m2: float | None = None) -> Job:
        path = Path(path)

        def work(job: Job) -> AnalysisOutcome:
            job.say(f"reading {path.name}")
            recording = read_recording(path)
            job.check()
            job.say(f"estimating spectra and fitting {path.name}")
            result = analyze_recording(recording, sd_m2, cancel=job.cancel_event)
            nominal = (recording.driver or {}).get("nominal_impedance_ohm")
            nominal = float(nominal) if isinstance(nominal, (int, float)) and not isinstance(nominal, bool) else None
            return AnalysisOutcome(job.id, path, result, result_curves(result), nominal)
        return self.run("analysis", work, f"analysing {path.name}")

    def start_model_part(self, outcome: AnalysisOutcome) -> Job:
        """The model part of each parameter's uncertainty (analysis.fit.model_uncertainty), after the statistical
        result is shown: a few seconds of refits when the model misses the data, none when it does not. It
        finishes with the outcome again, its parameters' std now the total (std_noise and std_model beside).
        The refits run on worker processes below the window (app.jobs.background_pool): in this thread they held
        the GIL against the GUI thread for seconds, while the user turns to the Model lab."""
        def work(job: Job) -> AnalysisOutcome:
            job.say(f"the model part of the uncertainties of {outcome.path.name}")
            with background_pool(job.cancel_event) as executor:
                result = model_uncertainty(outcome.result, cancel=job.cancel_event, executor=executor)
            return AnalysisOutcome(job.id, outcome.path, result, outcome.curves, outcome.nominal_ohm)
        return self.run("model part", work, f"estimating the model part of {outcome.path.name}'s uncertainties")

    def start_curves(self, request) -> Job:
        """Imported curves (app.jobs.curves.CurvesRequest) read and fitted; the outcome's result a CurveAnalysis."""
        from app.jobs.curves import analyse_curves

        def work(job: Job) -> AnalysisOutcome:
            result = analyse_curves(job, request)
            return AnalysisOutcome(job.id, request.path, result, result_curves(result))
        return self.run("analysis", work, f"analysing {request.name}")
