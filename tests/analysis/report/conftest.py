"""Fixtures the report tests share: a recording's analysis as stored, and the same with a parameter the data do
not determine."""
import dataclasses

import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.pipeline import analyze_recording
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def stored():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    return StoredResult.from_json(results_document(analyze_recording(rec), rec))


@pytest.fixture(scope="module")
def undetermined_qms(stored):
    """`stored` with Qms known to ± 4 times its value, as the imported Dayton curve's (5.65 ± 25)."""
    qms = stored.parameters["Qms"]
    return dataclasses.replace(stored, parameters={**stored.parameters,
                                                   "Qms": dataclasses.replace(qms, std=4 * qms.value)})
