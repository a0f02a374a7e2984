"""The analysis worker's model part: its refits run on worker processes, not in the job's thread of the GUI process."""
from __future__ import annotations

from pathlib import Path

import pytest

import app.jobs.workers
from analysis.fit.added_physics import extended_models
from analysis.fit.model_uncertainty import alternative_models
from analysis.parallel import worker_count
from analysis.pipeline import analyze_recording
from app.jobs.workers import AnalysisOutcome, AnalysisWorker
from tests.app.conftest import analysis_wait_ms
from tests.app.jobs.pool_spy import noting_background_pool
from tests.pace import wait_ms
from tests.realistic_drivers import realistic_recording


@pytest.mark.skipif(worker_count() < 2, reason="one core: the refits run in the job's thread, no pool is started")
def test_the_model_parts_refits_are_handed_to_the_pool(qtbot, monkeypatch):
    handed = []
    monkeypatch.setattr(app.jobs.workers, "background_pool", noting_background_pool(app.jobs.workers.background_pool, handed))
    result = analyze_recording(realistic_recording("midrange", 0))
    worker = AnalysisWorker()
    with qtbot.waitSignal(worker.finished, timeout=analysis_wait_ms(4)) as done:
        worker.start_model_part(AnalysisOutcome(0, Path("midrange"), result, None))
    model = result.fit.model        # the other forms, and the model with each effect a real driver has added
    assert handed == ["fit_with"] * (len(alternative_models(model)) + len(extended_models(model)))
    mms = done.args[1].result.parameters["Mms"]
    assert mms.value == result.parameters["Mms"].value and mms.std_model > 0
    assert worker.shutdown(wait_ms(10))
