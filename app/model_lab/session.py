"""The model lab's state without its widgets: the recording it models, its versions and the last diagnosis.

ModelLab (app.model_lab.page) shows a LabSession and forwards the user's moves to it; the session decides what
a new recording, an edited Sd, a new version and a diagnosis do to the lab's history. No Qt is imported here
(the fits it keeps are made by app.jobs.lab_worker, named here as types only): tests/app/model_lab/test_session.py
drives it without a window.
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from analysis.derived import parameter_table
from analysis.fit.least_squares import FitData
from app.model_lab.versions import LabVersion

if TYPE_CHECKING:
    from analysis.pipeline import AnalysisResult
    from app.jobs.lab_outcome import DiagnosisOutcome, LabFit


class LabSession:
    def __init__(self) -> None:
        self.base: AnalysisResult | None = None     # the recording as the Results page analysed it
        self.data: FitData | None = None            # its lines: what every refit and diagnosis fits
        self.versions: list[LabVersion] = []
        self.diagnosis: DiagnosisOutcome | None = None
        self.diagnosis_version = 0                  # the version the diagnosis's candidates are one move from

    @property
    def current(self) -> LabVersion | None:
        return self.versions[-1] if self.versions else None

    def is_same_recording(self, result: AnalysisResult) -> bool:
        """True for a result of the recording the lab models (one of its versions shown, or Sd edited)."""
        return self.base is not None and result.spectra is self.base.spectra

    def restart(self, result: AnalysisResult) -> None:
        """A new recording: its result is the base, with no version and no diagnosis yet; a result with nothing
        fitted (a broken measurement) leaves the lab nothing to model."""
        fitted = result.fit is not None
        self.base = result if fitted else None
        # Every usable line, also when the result's parameters come from its piston band: the lab is where the
        # user sees where the model fails (a cone mode above the band) and which physics would explain it, as
        # `linpar diagnose` does. Its first version is then the model fitted over every line (first_version).
        self.data = FitData.from_spectra(result.spectra) if fitted else None
        self.versions = []
        self.diagnosis, self.diagnosis_version = None, 0

    def set_sd(self, sd_m2: float | None) -> bool:
        """Sd edited: the base and the current version's derived parameters follow it. True when it changed."""
        if self.base is None or sd_m2 == self.base.sd_m2:
            return False
        self.base = dataclasses.replace(self.base, sd_m2=sd_m2)
        if self.versions:
            version = self.versions[-1]
            self.versions[-1] = dataclasses.replace(version, fitted=self.with_sd(version.fitted))
        return True

    def with_sd(self, fitted: LabFit) -> LabFit:
        """`fitted` with the lab's current Sd (it feeds derived parameters only; milliseconds)."""
        if fitted.result.sd_m2 == self.base.sd_m2:
            return fitted
        result = dataclasses.replace(fitted.result, sd_m2=self.base.sd_m2,
                                     parameters=parameter_table(fitted.fit, self.base.sd_m2))
        return dataclasses.replace(fitted, result=result)

    def add(self, fitted: LabFit, how: str) -> LabVersion:
        """The next version, numbered from 1, with the lab's Sd; `how` says how it came about.

        A fit made in a worker process (a diagnosis's candidates, the greedy path's steps) comes back with a copy
        of the recording's spectra: the version takes the base's own, so that the Results page's echo of it
        (is_same_recording) is this recording's and not a new one's that would restart the lab and drop it."""
        if self.base is not None and fitted.result.spectra is not self.base.spectra \
                and same_lines(fitted.result.spectra, self.base.spectra):
            fitted = dataclasses.replace(fitted, result=dataclasses.replace(fitted.result, spectra=self.base.spectra))
        version = LabVersion(len(self.versions) + 1, self.with_sd(fitted), how)
        self.versions.append(version)
        return version

    def diagnosed(self, outcome: DiagnosisOutcome) -> None:
        """A diagnosis of the current version (its candidates are one move from it)."""
        self.diagnosis, self.diagnosis_version = outcome, self.current.number

    @property
    def diagnosis_is_current(self) -> bool:
        """True when the diagnosis's candidates are one move from the current version."""
        return (self.diagnosis is not None and self.current is not None
                and self.diagnosis_version == self.current.number)


def same_lines(a, b) -> bool:
    """True when two analysis.spectra.Spectra hold the same recording's lines (a copy that crossed a process)."""
    return (a.sample_rate == b.sample_rate and a.period_samples == b.period_samples and a.n_periods == b.n_periods
            and np.array_equal(a.excited_bins, b.excited_bins) and np.array_equal(a.impedance.value, b.impedance.value))
