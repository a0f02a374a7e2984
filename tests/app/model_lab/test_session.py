"""The model lab's session (app.model_lab.session): its versions, Sd and diagnosis, without a window or Qt."""
from __future__ import annotations

import dataclasses

import pytest

from analysis.diagnosis import residuals
from analysis.effects import parse_effects
from analysis.fit.least_squares import fit_model
from analysis.model.composed import Model
from analysis.pipeline import AnalysisResult, analyze_recording
from app.jobs.lab_outcome import LabFit, lab_fit
from app.model_lab.session import LabSession
from app.results.curves import result_curves
from tests.builders import TYPICAL_NOISE, recording
from tests.fresh_import import loaded_by_import


def test_the_session_imports_no_qt():
    assert loaded_by_import("app.model_lab.session", "PySide6") == []


@pytest.fixture(scope="module")
def base() -> AnalysisResult:
    return analyze_recording(recording(noise=TYPICAL_NOISE, n_periods=2, seed=5))


def first_version(result: AnalysisResult) -> LabFit:
    return LabFit(result, result_curves(result), residuals.describe(result.fit))


def test_versions_are_numbered_and_the_last_is_current(base):
    session = LabSession()
    assert session.current is None and not session.diagnosis_is_current
    session.restart(base)
    assert session.base is base and session.data is not None and session.versions == []
    first = session.add(first_version(base), "as fitted")
    textbook = fit_model(session.data, Model(parse_effects("none")))
    second = session.add(lab_fit(base, textbook), "removed both effects")
    assert (first.number, second.number) == (1, 2) and session.current is second
    assert second.effects == "textbook" and second.how == "removed both effects"


def test_a_version_fitted_in_a_worker_process_is_of_the_same_recording(base):
    """A diagnosis's candidate comes back pickled, its spectra a copy: adopted, the Results page echoed it as a
    new recording, and the lab restarted, dropping the version and the diagnosis (Apply, Follow the greedy path)."""
    import pickle
    session = LabSession()
    session.restart(base)
    session.add(first_version(base), "as fitted")
    textbook = fit_model(session.data, Model(parse_effects("none")))
    from_worker = pickle.loads(pickle.dumps(lab_fit(base, textbook)))
    assert from_worker.result.spectra is not base.spectra
    version = session.add(from_worker, "applied")
    assert session.is_same_recording(version.fitted.result) and session.current is version


def test_sd_follows_the_results_page_on_the_current_version(base):
    session = LabSession()
    session.restart(base)
    session.add(first_version(base), "as fitted")
    vas = session.current.fitted.result.parameters["Vas"].value
    assert session.set_sd(base.sd_m2) is False                     # unchanged: nothing to redo
    assert session.is_same_recording(dataclasses.replace(base, sd_m2=0.02))
    assert session.set_sd(0.02) is True
    assert session.base.sd_m2 == 0.02 and session.current.fitted.result.sd_m2 == 0.02
    # Vas grows with Sd squared (Vas = rho c^2 Cms Sd^2).
    new_vas = session.current.fitted.result.parameters["Vas"].value
    assert new_vas == pytest.approx(vas * (0.02 / base.sd_m2) ** 2, rel=1e-9)
    assert session.add(first_version(base), "again").fitted.result.sd_m2 == 0.02     # new versions take it too


def test_a_diagnosis_is_current_until_the_next_version(base):
    session = LabSession()
    session.restart(base)
    session.add(first_version(base), "as fitted")
    session.diagnosed(object())         # what the worker's DiagnosisOutcome is does not matter to the session
    assert session.diagnosis_is_current and session.diagnosis_version == 1
    session.add(first_version(base), "refitted")
    assert session.diagnosis is not None and not session.diagnosis_is_current


def test_a_new_recording_restarts_and_a_broken_one_leaves_nothing(base):
    session = LabSession()
    session.restart(base)
    session.add(first_version(base), "as fitted")
    session.diagnosed(object())
    other = analyze_recording(recording(noise=TYPICAL_NOISE, n_periods=2, seed=6))
    assert not session.is_same_recording(other)
    session.restart(other)
    assert session.base is other and session.versions == [] and session.diagnosis is None
    broken = dataclasses.replace(other, fit=None, not_fitted="the current is silent")
    session.restart(broken)
    assert session.base is None and session.data is None and session.current is None


@pytest.fixture(scope="module")
def band_fitted() -> AnalysisResult:
    """A realistic woofer (a cone mode the laser's spot sees): its parameters come from the piston band."""
    from tests.realistic_drivers import realistic_recording
    result = analyze_recording(realistic_recording("woofer", 0))
    assert result.whole_band_fit is not None, "the woofer's parameters should come from its piston band"
    return result


def test_a_band_fitted_result_is_modelled_over_every_line_where_the_cone_mode_shows(band_fitted):
    from app.jobs.lab_outcome import first_version as lab_first_version
    session = LabSession()
    session.restart(band_fitted)
    band_lines = len(band_fitted.data.displacement.freqs)
    assert len(session.data.displacement.freqs) > band_lines            # the lab sees above the band
    first, how = lab_first_version(band_fitted)
    assert "piston band" in how
    fitted_lines = first.fit.channels["displacement"].freqs
    assert len(fitted_lines) == len(session.data.displacement.freqs)
    # Over every line the model misses the cone mode: the lab's starting point shows it (the band hides it).
    assert first.result.validity.fit_error_percent["displacement"] > 10.0
    assert band_fitted.validity.fit_error_percent["displacement"] < 10.0
    assert first.result.validity.fit_band_hz["displacement"][1] == pytest.approx(float(fitted_lines[-1]))
    assert first.result.data is None and first.result.whole_band_fit is None


def test_a_result_fitted_over_every_line_starts_the_lab_as_it_is(base):
    from app.jobs.lab_outcome import first_version as lab_first_version
    assert base.whole_band_fit is None
    first, how = lab_first_version(base)
    assert first.result is base and how == "as fitted on the Results page"
